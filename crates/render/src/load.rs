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
use std::path::Path;

/// Reads a mesh from a `.glb`, `.gltf` or `.obj` file.
pub fn load_mesh(path: &Path) -> Result<Mesh, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    // The parsers are other crates': a panic on malformed data (gltf-json 1.4 indexes the
    // accessors with a POSITION attribute's index before checking it) becomes an error.
    let parse = || match ext.as_str() {
        "glb" | "gltf" => load_gltf(path),
        "obj" => load_obj(path),
        _ => Err(format!(
            "{}: unknown mesh format (known: .glb .gltf .obj)",
            path.display()
        )),
    };
    let mesh =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse)).unwrap_or_else(|_| {
            Err(format!(
                "{}: the {} reader failed on malformed data",
                path.display(),
                if ext == "obj" { "OBJ" } else { "glTF" }
            ))
        })?;
    if mesh.triangles.is_empty() {
        return Err(format!("{}: no triangles", path.display()));
    }
    mesh.validate()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    check_extent(&mesh).map_err(|e| format!("{}: {e}", path.display()))?;
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

fn load_gltf(path: &Path) -> Result<Mesh, String> {
    let name = path.display();
    let (doc, buffers, _images) = gltf::import(path).map_err(|e| {
        let msg = e.to_string();
        if msg.contains("draco") || msg.contains("KHR_draco") {
            format!("{name}: Draco-compressed glTF (KHR_draco_mesh_compression) is not supported; decompress it first (e.g. gltf-transform, or the OBJ in assets/meshes)")
        } else {
            format!("{name}: {msg}")
        }
    })?;
    if doc
        .extensions_required()
        .any(|e| e == "KHR_draco_mesh_compression")
    {
        return Err(format!("{name}: Draco-compressed glTF (KHR_draco_mesh_compression) is not supported; decompress it first"));
    }
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| format!("{name}: no scene"))?;
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
                        return Err(format!(
                            "{name}: mesh {}: the indices are {:?}, not unsigned integers",
                            mesh.index(),
                            a.data_type()
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
                part.validate().map_err(|e| format!("{name}: {e}"))?;
                out.append(&part.transformed(m));
            }
        }
        stack.extend(node.children().map(|c| (c, m)));
    }
    Ok(out)
}

fn load_obj(path: &Path) -> Result<Mesh, String> {
    let name = path.display();
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _mtl) = tobj::load_obj(path, &opts).map_err(|e| format!("{name}: {e}"))?;
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
        part.validate().map_err(|e| format!("{name}: {e}"))?;
        out.append(&part);
    }
    Ok(out)
}
