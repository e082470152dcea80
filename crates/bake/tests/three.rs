//! `bake three`: three.js r187's PMREM levels and roughnesses, the refusals, and the files
//! read back the way three's DDSLoader and HDRCubeTextureLoader read them, looked up the way
//! three looks cubes up, at (−x, y, z).

use mirrorball_bake::{Bake, BakeOptions, Engine, Lighting};
use mirrorball_core::glam::DVec3;
use mirrorball_core::{EnvMap, Image, ProjectionKind};
use mirrorball_io::Encoding;

/// Directions spread over the sphere (a Fibonacci lattice).
fn directions(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - y * y).sqrt();
            let a = golden * i as f64;
            DVec3::new(r * a.cos(), y, r * a.sin())
        })
        .collect()
}

fn cube(faces: Vec<Image>) -> EnvMap {
    EnvMap::new(ProjectionKind::Cube.default_projection(), faces).unwrap()
}

#[test]
fn levels_are_three_pmrem_levels_at_the_roughness_its_shaders_read_them() {
    let spec = Engine::Three.chain_spec(&BakeOptions {
        size: 256,
        ..Default::default()
    });
    // PMREMGenerator.js: faces size >> lod down to 2^LOD_MIN = 8, no diffuse cube.
    let faces: Vec<u32> = spec.levels.iter().map(|l| l.0).collect();
    assert_eq!(faces, [256, 128, 64, 32, 16, 8]);
    assert_eq!(spec.diffuse_face, None);
    // envmap_common_pars_fragment.glsl.js: three reads roughness r at mip maxLod·r(2 − r),
    // with clamp(r, 0, 1); each level must sit exactly where three reads its roughness.
    let max_lod = (spec.levels.len() - 1) as f64;
    for (lod, &(_, r)) in spec.levels.iter().enumerate() {
        assert!((0.0..=1.0).contains(&r));
        let mip = max_lod * r * (2.0 - r);
        assert!(
            (mip - lod as f64).abs() < 1e-12,
            "level {lod} at roughness {r} is read at mip {mip}"
        );
    }
    assert_eq!(spec.levels[0].1, 0.0);
    assert_eq!(spec.levels.last().unwrap().1, 1.0);
}

#[test]
fn bad_requests_are_refused_with_the_reason() {
    let ask = |size, encoding, zstd| {
        Bake::new(
            Engine::Three,
            BakeOptions {
                size,
                encoding,
                zstd,
                ..Default::default()
            },
        )
        .map(|_| ())
        .map_err(|e| e.to_string())
    };
    assert!(ask(16, None, None).is_ok());
    assert!(ask(64, Some(Encoding::Bc6hSigned), None).is_ok());
    // three's own rule: its PMREM goes down to 8×8 faces.
    let e = ask(8, None, None).unwrap_err();
    assert!(
        e.contains("power-of-two size of at least 16") && e.contains('8'),
        "{e}"
    );
    for size in [100, 0] {
        let e = ask(size, None, None).unwrap_err();
        assert!(
            e.contains("power of two") && e.contains(&size.to_string()),
            "{e}"
        );
    }
    let e = ask(64, Some(Encoding::Rgba16F), None).unwrap_err();
    assert!(e.contains("rgba16f") && e.contains("bc6h"), "{e}");
    let e = ask(64, None, Some(3)).unwrap_err();
    assert!(e.contains("Zstandard"), "{e}");
}

/// The i-th little-endian u32 of `bytes`.
fn u32_at(bytes: &[u8], i: usize) -> u32 {
    u32::from_le_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap())
}

#[test]
fn files_read_as_three_reads_them_show_the_world_at_minus_x() {
    let env = mirrorball_bake::direction_coded(256);
    let opts = BakeOptions {
        size: 32,
        ..Default::default()
    };
    let spec = Engine::Three.chain_spec(&opts);
    let lighting = Lighting::from_env(&env, &spec, Default::default());
    let dir = tempfile::tempdir().unwrap();
    let bake = Bake::new(Engine::Three, opts.clone()).unwrap();
    let turned = lighting.clone().oriented(&Engine::Three.orientation());
    let files = bake.write(&turned, dir.path()).unwrap();
    assert_eq!(files.len(), 8, "{files:?}");

    // The DDS as DDSLoader.js parses it (lines 176–335): 'DX10' FourCC (header int 21),
    // DXGI_FORMAT_BC6H_UF16 = 95 (int 32), the mip count (int 7, with DDSD_MIPMAPCOUNT in the
    // flags), all six cube-face bits in caps2 (int 28), then face-major data.
    let bytes = std::fs::read(dir.path().join("pmrem.dds")).unwrap();
    assert_eq!(&bytes[..4], b"DDS ");
    assert_eq!(&bytes[84..88], b"DX10");
    assert_eq!(u32_at(&bytes, 32), 95);
    assert_ne!(u32_at(&bytes, 2) & 0x20000, 0);
    assert_eq!(u32_at(&bytes, 7) as usize, spec.levels.len());
    assert_eq!(u32_at(&bytes, 28) & 0xFE00, 0xFE00);
    let mut at = 4 + 124 + 20;
    let mut levels: Vec<Vec<Image>> = vec![Vec::new(); spec.levels.len()];
    for _face in 0..6 {
        for (lod, &(size, _)) in spec.levels.iter().enumerate() {
            let len = Encoding::Bc6hUnsigned.image_bytes(size, size);
            levels[lod].push(Encoding::Bc6hUnsigned.decode(&bytes[at..at + len], size, size));
            at += len;
        }
    }
    assert_eq!(at, bytes.len());

    // three looks the cube up at (−x, y, z): that must give mirrorball's level at (x, y, z),
    // within BC6H's error on this smooth map, and mirrored would be far off.
    let dirs = directions(400);
    for (lod, faces) in levels.into_iter().enumerate() {
        let three = cube(faces);
        let ours = &lighting.specular[lod];
        let (mut worst, mut sum, mut worst_mirrored) = (0f32, 0f32, 0f32);
        for d in &dirs {
            let got = three.sample(DVec3::new(-d.x, d.y, d.z));
            let plain = three.sample(*d);
            let want = ours.sample(*d);
            for c in 0..3 {
                worst = worst.max((got[c] - want[c]).abs());
                sum += (got[c] - want[c]).abs();
                worst_mirrored = worst_mirrored.max((plain[c] - want[c]).abs());
            }
        }
        let mean = sum / (3 * dirs.len()) as f32;
        println!("level {lod}: through three's lookup, mean {mean:.4}, worst {worst:.4}");
        // BC6H holds one colour line per subset of a 4×4 block; this map's colour turns in
        // all three channels across a block, its worst case: its own round trip is off by
        // up to 0.075 on these levels (mean ≈ 0.01). Mirrored, the world is off by ≥ 0.2.
        assert!(
            worst < 0.08 && mean < 0.015,
            "level {lod}: off by {worst} (mean {mean})"
        );
        assert!(
            worst_mirrored > 0.2,
            "level {lod}: mirrored too close ({worst_mirrored})"
        );
    }

    // The plain cube as HDRCubeTextureLoader reads it: six RGBE faces, row 0 to t = 0.
    let names = ["px", "nx", "py", "ny", "pz", "nz"];
    let faces: Vec<Image> = names
        .iter()
        .map(|n| {
            let path = dir.path().join("cube").join(format!("{n}.hdr"));
            mirrorball_io::read(&path, &Default::default())
                .unwrap()
                .layers
                .remove(0)
        })
        .collect();
    let three = cube(faces);
    for d in &dirs {
        let got = three.sample(DVec3::new(-d.x, d.y, d.z));
        let want = [0.5 + 0.5 * d.x, 0.5 + 0.5 * d.y, 0.5 + 0.5 * d.z];
        for c in 0..3 {
            // RGBE's 8-bit mantissa (≤ 1/256 of the largest channel) and a 32² face's bilinear
            // lookup of the non-linear ½ + ½·d.
            assert!(
                (got[c] as f64 - want[c]).abs() < 0.01,
                "{d}: {got:?} vs {want:?}"
            );
        }
    }

    let note = std::fs::read_to_string(dir.path().join("README.md")).unwrap();
    for line in [
        "new THREE.CompressedCubeTexture(dds.image, dds.format)",
        "pmrem.isPMREMTexture = true",
        "scene.environment = pmrem",
        "new HDRCubeTextureLoader()",
    ] {
        assert!(note.contains(line), "the note lacks {line}");
    }
}
