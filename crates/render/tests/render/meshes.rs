//! Built-in meshes, the teapot, and loading files.

use glam::{Mat4, Vec3};
use mirrorball_core::Fault;
use mirrorball_render::{load_mesh, mesh, Builtin};
use std::path::Path;

#[test]
fn builtins_are_valid_with_unit_normals() {
    for b in Builtin::ALL {
        for level in [1, 2, 5, b.default_tessellation()] {
            let m = b.mesh(level);
            m.validate().unwrap();
            assert!(!m.triangles.is_empty(), "{}", b.name());
            for n in &m.normals {
                assert!((n.length() - 1.0).abs() < 1e-4, "{} normal {n}", b.name());
            }
        }
    }
}

#[test]
fn sphere_normals_are_positions_and_tessellation_is_a_parameter() {
    let a = mesh::sphere(8);
    let b = mesh::sphere(64);
    assert!(b.triangles.len() > 30 * a.triangles.len());
    for (p, n) in b.positions.iter().zip(&b.normals) {
        assert!((p.length() - 1.0).abs() < 1e-5 && (*p - *n).length() < 1e-5);
    }
}

#[test]
fn teapot_has_32_patches_and_outward_body_normals() {
    let level = 6;
    let t = mesh::teapot(level);
    // (level+1)² vertices per patch.
    assert_eq!(t.positions.len(), 32 * (level as usize + 1).pow(2));
    let (lo, hi) = t.bounds().unwrap();
    assert!(((hi - lo) * 0.5).max_element() - 1.0 < 1e-5);
    // Body patches 4..12: the normal points away from the vertical axis.
    let per = (level as usize + 1).pow(2);
    let c = (lo + hi) * 0.5;
    let mut outward = 0;
    let mut total = 0;
    for k in 4..12 {
        for i in 0..per {
            let p = t.positions[k * per + i] - c;
            let n = t.normals[k * per + i];
            let radial = Vec3::new(p.x, 0.0, p.z);
            if radial.length() > 0.1 {
                total += 1;
                if n.dot(radial) > 0.0 {
                    outward += 1;
                }
            }
        }
    }
    assert_eq!(outward, total);
    // Finer levels have more triangles.
    assert!(mesh::teapot(12).triangles.len() > 3 * mesh::teapot(6).triangles.len());
}

#[test]
fn transformed_mesh_keeps_unit_normals() {
    let m = mesh::sphere(16).transformed(Mat4::from_scale(Vec3::new(2.0, 1.0, 0.5)));
    for n in &m.normals {
        assert!((n.length() - 1.0).abs() < 1e-5);
    }
}

fn asset(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/meshes")
        .join(name)
}

#[test]
fn reads_the_bundled_bunny_obj() {
    let m = load_mesh(&asset("bunny.obj")).unwrap();
    assert_eq!(m.positions.len(), 2826);
    assert_eq!(m.triangles.len(), 5648);
    m.validate().unwrap();
}

#[test]
fn reads_gltf_with_node_transforms_and_obj_without_normals() {
    let dir = tempfile::tempdir().unwrap();
    // A minimal glTF: one triangle, positions only, a node translating by +2 in x.
    let positions: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let bytes: Vec<u8> = positions.iter().flat_map(|f| f.to_le_bytes()).collect();
    std::fs::write(dir.path().join("tri.bin"), &bytes).unwrap();
    let json = r#"{
      "asset": {"version": "2.0"},
      "scene": 0,
      "scenes": [{"nodes": [0]}],
      "nodes": [{"mesh": 0, "translation": [2, 0, 0]}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
      "buffers": [{"uri": "tri.bin", "byteLength": 36}],
      "bufferViews": [{"buffer": 0, "byteLength": 36}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                     "min": [0, 0, 0], "max": [1, 1, 0]}]
    }"#;
    let p = dir.path().join("tri.gltf");
    std::fs::write(&p, json).unwrap();
    let m = load_mesh(&p).unwrap();
    assert_eq!(m.triangles.len(), 1);
    assert!((m.positions[1] - Vec3::new(3.0, 0.0, 0.0)).length() < 1e-6);
    assert!((m.normals[0] - Vec3::Z).length() < 1e-6);

    let o = dir.path().join("t.obj");
    std::fs::write(&o, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n").unwrap();
    let m = load_mesh(&o).unwrap();
    assert_eq!(m.triangles.len(), 2);
    assert!((m.normals[0] - Vec3::Z).length() < 1e-6);
}

#[test]
fn refuses_draco_and_unknown_files_with_a_reason() {
    let draco = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/assets/bunny.glb");
    if draco.exists() {
        let e = load_mesh(&draco).unwrap_err();
        assert_eq!(e.fault(), Fault::Input, "{e}");
        let e = e.to_string();
        assert!(e.to_lowercase().contains("draco"), "{e}");
    }
    let e = load_mesh(Path::new("x.stl")).unwrap_err();
    assert_eq!(e.fault(), Fault::Request, "{e}");
    let e = e.to_string();
    assert!(e.contains("unknown mesh format"), "{e}");
    for missing in ["/nonexistent/x.obj", "/nonexistent/x.glb"] {
        let e = load_mesh(Path::new(missing)).unwrap_err();
        assert_eq!(e.fault(), Fault::Input, "{e}");
        assert_eq!(e.path(), Path::new(missing));
        let e = e.to_string();
        assert!(e.contains(&missing[12..]), "{e}");
    }
    // A file that is there but malformed is the input's fault.
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in [("bad.obj", "v 0 0\nf 1 2 3\n"), ("bad.gltf", "{ not json")] {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        let e = load_mesh(&p).unwrap_err();
        assert_eq!(e.fault(), Fault::Input, "{e}");
    }
}

#[test]
fn closed_outward_meshes_are_recognised_and_open_or_inverted_ones_are_not() {
    // Closed solids facing out (seams and poles welded by position).
    assert!(mesh::sphere(16).is_closed_outward());
    assert!(mesh::torus(1.0, 0.3, 12).is_closed_outward());
    assert!(mesh::cube(3).is_closed_outward());
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let bunny = load_mesh(&root.join("assets/meshes/bunny.obj")).unwrap();
    assert!(bunny.is_closed_outward(), "the bundled bunny is watertight");
    // Open: a sheet; a sphere with one triangle taken out.
    assert!(!mesh::quad(2).is_closed_outward());
    let mut holed = mesh::sphere(16);
    holed.triangles.remove(40);
    assert!(!holed.is_closed_outward());
    // Inconsistent: one triangle turned over.
    let mut flipped = mesh::sphere(16);
    flipped.triangles[40].swap(1, 2);
    assert!(!flipped.is_closed_outward());
    // Inside out: every triangle turned over, or the mesh mirrored.
    let mut inverted = mesh::sphere(16);
    for t in &mut inverted.triangles {
        t.swap(1, 2);
    }
    assert!(!inverted.is_closed_outward());
    assert!(!mesh::sphere(16)
        .transformed(Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)))
        .is_closed_outward());
    // Two pieces, one inside out: not culled.
    let mut two = mesh::sphere(8);
    let other = inverted.transformed(Mat4::from_translation(Vec3::X * 3.0));
    two.append(&other);
    assert!(!two.is_closed_outward());
    let mut two_out = mesh::sphere(8);
    two_out.append(&mesh::sphere(8).transformed(Mat4::from_translation(Vec3::X * 3.0)));
    assert!(two_out.is_closed_outward());
    // Non-manifold: an edge shared by four triangles (the same closed surface twice).
    let mut doubled = mesh::sphere(8);
    doubled.append(&mesh::sphere(8));
    assert!(!doubled.is_closed_outward());
    // The answer follows changes to the (public) fields.
    let mut m = mesh::sphere(8);
    assert!(m.is_closed_outward());
    m.triangles.pop();
    assert!(!m.is_closed_outward());
    // Empty, and out-of-range indices: not closed, no panic.
    assert!(!mirrorball_render::Mesh::default().is_closed_outward());
    let mut bad = mesh::sphere(4);
    bad.triangles[0][0] = 1_000_000;
    assert!(!bad.is_closed_outward());
}
