//! Mesh files: glTF 2.0 (`.glb`, `.gltf`) and Wavefront OBJ. The only file I/O of the crate;
//! the rasteriser and the shading never touch files.
//!
//! glTF: every triangle primitive of every mesh instanced in the default scene (or the first
//! scene) is read with its node's world transform applied (normals by the inverse transpose).
//! Primitives without normals get area-weighted vertex normals. Draco-compressed files
//! (`KHR_draco_mesh_compression`) are refused with a message saying so. OBJ: all models,
//! triangulated, one index per vertex; missing normals are computed the same way.

use crate::mesh::Mesh;
use glam::{Mat4, Vec2, Vec3};
use mirrorball_core::Fault;
use std::path::{Path, PathBuf};

/// Why a mesh file cannot be loaded, naming the file, and whose fault it is: the file's
/// (missing, malformed, no triangles, Draco-compressed), the request's (not a mesh
/// format) or the system's (it cannot be read).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct MeshError {
    path: PathBuf,
    fault: Fault,
    problem: String,
}

impl MeshError {
    fn new(path: &Path, fault: Fault, problem: impl Into<String>) -> MeshError {
        MeshError {
            path: path.to_path_buf(),
            fault,
            problem: problem.into(),
        }
    }
    fn input(path: &Path, problem: impl Into<String>) -> MeshError {
        MeshError::new(path, Fault::Input, problem)
    }
    /// Whose fault it is.
    pub fn fault(&self) -> Fault {
        self.fault
    }
    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }
    /// What went wrong, without the file's name.
    pub fn problem(&self) -> &str {
        &self.problem
    }
}

/// Whose fault it is that a parser could not open `path` or a file it refers to (glTF
/// buffers): the main file's own failure to open ([`Fault::of_io`]: missing is the
/// input's fault, unreadable the system's), with the system's reason; when it opens, the
/// fault is in what it refers to, the input's (and no reason).
fn open_failure(path: &Path) -> (Fault, Option<String>) {
    match std::fs::File::open(path) {
        Err(e) => (Fault::of_io(e.kind()), Some(e.to_string())),
        Ok(_) => (Fault::Input, None),
    }
}

/// Reads a mesh from a `.glb`, `.gltf` or `.obj` file.
///
/// ```
/// use mirrorball_core::Fault;
/// use mirrorball_render::load_mesh;
/// let path = std::env::temp_dir().join(format!("mirrorball-doc-{}.obj", std::process::id()));
/// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
/// let mesh = load_mesh(&path);
/// std::fs::remove_file(&path).unwrap();
/// let mesh = mesh.unwrap();
/// assert_eq!(mesh.triangles.len(), 1);
/// // The file has no normals: they are made, facing the side the triangle winds
/// // counter-clockwise around (+Z).
/// assert!((mesh.normals[0] - glam::Vec3::Z).length() < 1e-6);
/// // A file that is not there is the input's fault, and the message says so with its path.
/// let err = load_mesh(std::path::Path::new("no/such/mesh.obj")).unwrap_err();
/// assert_eq!(err.fault(), Fault::Input);
/// assert_eq!(err.to_string(), "no/such/mesh.obj: no such file");
/// ```
pub fn load_mesh(path: &Path) -> Result<Mesh, MeshError> {
    let ext = mesh_ext(path)?;
    if let Some((fault, problem)) = mirrorball_core::input_file_problem(&std::fs::metadata(path)) {
        return Err(MeshError::new(path, fault, problem));
    }
    parsed(path, &ext, || match ext.as_str() {
        "glb" | "gltf" => load_gltf(path),
        _ => load_obj(path),
    })
}

/// Reads a mesh from the bytes of a `.glb`, `.gltf` or `.obj` file called `name` (its
/// extension says which; messages name it), as [`load_mesh`] reads the file: an uploaded
/// mesh, with no file written. A `.gltf` must carry its buffers inside (data URIs): a file
/// it names beside it is refused, naming the file.
///
/// ```
/// use mirrorball_render::load_mesh_bytes;
/// let mesh = load_mesh_bytes("tri.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
/// assert_eq!(mesh.triangles.len(), 1);
/// let err = load_mesh_bytes("empty.glb", b"").unwrap_err();
/// assert_eq!(err.to_string(), "empty.glb: the file is empty");
/// ```
pub fn load_mesh_bytes(name: &str, bytes: &[u8]) -> Result<Mesh, MeshError> {
    let path = Path::new(name);
    let ext = mesh_ext(path)?;
    if bytes.is_empty() {
        return Err(MeshError::input(path, "the file is empty"));
    }
    parsed(path, &ext, || match ext.as_str() {
        "glb" | "gltf" => gltf_slice(path, bytes),
        _ => obj_bytes(path, bytes),
    })
}

/// The lower-case extension of a mesh file's name, or the request's error when no reader
/// takes it (whatever the file holds).
fn mesh_ext(path: &Path) -> Result<String, MeshError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    if !matches!(ext.as_str(), "glb" | "gltf" | "obj") {
        return Err(MeshError::new(
            path,
            Fault::Request,
            "unknown mesh format (known: .glb .gltf .obj)",
        ));
    }
    Ok(ext)
}

/// The mesh `parse` reads from `path` (of extension `ext`), checked: a parser's panic on
/// malformed data (the parsers are other crates': gltf-json 1.4 indexes the accessors with
/// a POSITION attribute's index before checking it) becomes an error, and a mesh with no
/// triangles, invalid indices or an extent too large to frame is refused.
fn parsed(
    path: &Path,
    ext: &str,
    parse: impl FnOnce() -> Result<Mesh, MeshError>,
) -> Result<Mesh, MeshError> {
    let mesh =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse)).unwrap_or_else(|_| {
            Err(MeshError::input(
                path,
                format!(
                    "the {} reader failed on malformed data",
                    if ext == "obj" { "OBJ" } else { "glTF" }
                ),
            ))
        })?;
    if mesh.triangles.is_empty() {
        return Err(MeshError::input(path, "no triangles"));
    }
    mesh.validate()
        .map_err(|e| MeshError::input(path, e.to_string()))?;
    check_extent(&mesh).map_err(|e| MeshError::input(path, e))?;
    Ok(mesh)
}

/// The largest extent of a loaded mesh, in its own units, that can be framed: scaled to
/// unit size (`Mesh::normalizing_transform`), a larger mesh's transform has a determinant
/// (the scale cubed) too small for `f32`, and the renderer would take it for singular.
pub const MAX_EXTENT: f32 = 1e12;

/// Refuses a mesh whose vertices spread over more than [`MAX_EXTENT`] (finite vertices
/// can still be 3·10³⁸ apart).
fn check_extent(mesh: &Mesh) -> Result<(), String> {
    let Some((lo, hi)) = mesh.bounds() else {
        return Ok(());
    };
    let extent = (hi - lo).max_element();
    if extent.is_nan() || extent > MAX_EXTENT {
        let far = mesh
            .positions
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.abs().max_element().total_cmp(&b.1.abs().max_element()))
            .map(|(i, p)| format!("; vertex {i} is at ({}, {}, {})", p.x, p.y, p.z))
            .unwrap_or_default();
        return Err(format!(
            "the vertices span {extent:e} units, more than the {MAX_EXTENT:e} mirrorball can \
             frame{far}"
        ));
    }
    Ok(())
}

const DRACO: &str =
    "Draco-compressed glTF (KHR_draco_mesh_compression) is not supported; decompress it first";

/// glTF's import error as the mesh's: Draco named, an I/O failure the file's own or what
/// it refers to ([`open_failure`], `fault_of_io`), else the content's.
fn gltf_error(path: &Path, e: gltf::Error, fault_of_io: impl FnOnce() -> Fault) -> MeshError {
    let msg = e.to_string();
    if msg.contains("draco") || msg.contains("KHR_draco") {
        MeshError::input(
            path,
            format!("{DRACO} (e.g. gltf-transform, or the OBJ in assets/meshes)"),
        )
    } else {
        let fault = match e {
            gltf::Error::Io(_) => fault_of_io(),
            _ => Fault::Input,
        };
        MeshError::new(path, fault, msg)
    }
}

fn load_gltf(path: &Path) -> Result<Mesh, MeshError> {
    let (doc, buffers, _images) =
        gltf::import(path).map_err(|e| gltf_error(path, e, || open_failure(path).0))?;
    gltf_mesh(path, &doc, &buffers)
}

/// A `.glb` or self-contained `.gltf` from its bytes (`path` names it in messages); a
/// buffer in another file is the input's fault, named.
fn gltf_slice(path: &Path, bytes: &[u8]) -> Result<Mesh, MeshError> {
    let (doc, buffers, _images) = gltf::import_slice(bytes).map_err(|e| match e {
        gltf::Error::ExternalReferenceInSliceImport => MeshError::input(
            path,
            "names a buffer or image in another file: give a .glb, or a .gltf with its buffers inside",
        ),
        e => gltf_error(path, e, || Fault::Input),
    })?;
    gltf_mesh(path, &doc, &buffers)
}

/// Every triangle primitive of every mesh instanced in the default (or first) scene of
/// `doc`, with its node's world transform.
fn gltf_mesh(
    path: &Path,
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
) -> Result<Mesh, MeshError> {
    if doc
        .extensions_required()
        .any(|e| e == "KHR_draco_mesh_compression")
    {
        return Err(MeshError::input(path, DRACO));
    }
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| MeshError::input(path, "no scene"))?;
    let mut out = Mesh::default();
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let m = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    continue;
                }
                let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
                let Some(pos) = reader.read_positions() else {
                    continue;
                };
                let mut part = Mesh {
                    positions: pos.map(Vec3::from_array).collect(),
                    ..Mesh::default()
                };
                let n = part.positions.len() as u32;
                // The reader panics on indices of any other type.
                if let Some(a) = prim.indices() {
                    use gltf::accessor::DataType;
                    if !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32) {
                        return Err(MeshError::input(
                            path,
                            format!(
                                "mesh {}: the indices are {:?}, not unsigned integers",
                                mesh.index(),
                                a.data_type()
                            ),
                        ));
                    }
                }
                let idx: Vec<u32> = match reader.read_indices() {
                    Some(i) => i.into_u32().collect(),
                    None => (0..n).collect(),
                };
                part.triangles = idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
                match reader.read_normals() {
                    Some(ns) => part.normals = ns.map(Vec3::from_array).collect(),
                    None => part.compute_normals(),
                }
                if let Some(tc) = reader.read_tex_coords(0) {
                    part.uvs = tc.into_f32().map(Vec2::from_array).collect();
                }
                part.validate()
                    .map_err(|e| MeshError::input(path, e.to_string()))?;
                out.append(&part.transformed(m));
            }
        }
        stack.extend(node.children().map(|c| (c, m)));
    }
    Ok(out)
}

/// How OBJ files are read: triangulated, one index per vertex.
fn obj_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    }
}

fn load_obj(path: &Path) -> Result<Mesh, MeshError> {
    let (models, _mtl) = tobj::load_obj(path, &obj_options()).map_err(|e| {
        // tobj keeps no I/O error kind. Its read error is, on a file that opened, a line
        // that is not UTF-8: the content, as is every other error.
        match (&e, open_failure(path)) {
            (tobj::LoadError::OpenFileFailed, (fault, Some(why))) => {
                MeshError::new(path, fault, format!("cannot open the file: {why}"))
            }
            _ => MeshError::input(path, e.to_string()),
        }
    })?;
    obj_mesh(path, models)
}

/// An OBJ from its bytes (`path` names it in messages); the materials it names are not
/// read (the renderer takes none from them).
fn obj_bytes(path: &Path, bytes: &[u8]) -> Result<Mesh, MeshError> {
    let (models, _mtl) =
        tobj::load_obj_buf(&mut std::io::Cursor::new(bytes), &obj_options(), |_| {
            Ok(Default::default())
        })
        .map_err(|e| MeshError::input(path, e.to_string()))?;
    obj_mesh(path, models)
}

/// OBJ's models as one mesh: normals made where the file has none.
fn obj_mesh(path: &Path, models: Vec<tobj::Model>) -> Result<Mesh, MeshError> {
    let mut out = Mesh::default();
    for m in models {
        let mm = m.mesh;
        let mut part = Mesh {
            positions: mm
                .positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect(),
            triangles: mm
                .indices
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
            ..Mesh::default()
        };
        if mm.normals.len() == mm.positions.len() {
            part.normals = mm
                .normals
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2]).normalize_or_zero())
                .collect();
        } else {
            part.compute_normals();
        }
        if mm.texcoords.len() / 2 == part.positions.len() {
            part.uvs = mm
                .texcoords
                .chunks_exact(2)
                .map(|p| Vec2::new(p[0], 1.0 - p[1]))
                .collect();
        }
        part.validate()
            .map_err(|e| MeshError::input(path, e.to_string()))?;
        out.append(&part);
    }
    Ok(out)
}
