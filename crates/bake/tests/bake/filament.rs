//! Filament's files read back by the `ktx` crate (a KTX 1.1 reader that is not mirrorball's):
//! header fields, mip and face counts, texels against the float chain; the SH in `sh.txt`
//! and under the `sh` key against a port of cmgen's own pre-scaled SH
//! (`CubemapSH::computeIrradianceSH3Bands`, libs/ibl/src/CubemapSH.cpp).

use crate::common::{bake, texel_dir};
use ktx::KtxInfo;
use mirrorball_bake::Engine;
use mirrorball_core::glam::DVec3;
use mirrorball_io::Encoding;
use std::f64::consts::PI;

const GL_HALF_FLOAT: u32 = 0x140B;
const GL_RGB: u32 = 0x1907;
const GL_RGBA: u32 = 0x1908;
const GL_RGBA16F: u32 = 0x881A;
const GL_R11F_G11F_B10F: u32 = 0x8C3A;

/// cmgen's `CubemapUtils::solidAngle` (libs/ibl/src/CubemapUtils.cpp), ported.
fn cmgen_solid_angle(dim: u32, u: u32, v: u32) -> f64 {
    let quadrant = |x: f64, y: f64| (x * y).atan2((x * x + y * y + 1.0).sqrt());
    let i = 1.0 / dim as f64;
    let s = (u as f64 + 0.5) * 2.0 * i - 1.0;
    let t = (v as f64 + 0.5) * 2.0 * i - 1.0;
    let (x0, y0, x1, y1) = (s - i, t - i, s + i, t + i);
    quadrant(x0, y0) - quadrant(x0, y1) - quadrant(x1, y0) + quadrant(x1, y1)
}

/// cmgen's `computeIrradianceSH3Bands` of the function `radiance`, sampled on a cube of
/// `dim`² faces, ported with its constants.
fn cmgen_irradiance_sh(radiance: impl Fn(DVec3) -> [f64; 3], dim: u32) -> [[f64; 3]; 9] {
    let (c0, c1, c2) = (PI, 2.0 * PI / 3.0, PI / 4.0); // computeTruncatedCosSh(0, 1, 2)
    let k = 1.0 / (PI * PI);
    let a = [
        k / 4.0 * c0,
        k / 4.0 * 3.0 * c1,
        k / 4.0 * 3.0 * c1,
        k / 4.0 * 3.0 * c1,
        k / 4.0 * 15.0 * c2,
        k / 4.0 * 15.0 * c2,
        k / 16.0 * 5.0 * c2,
        k / 4.0 * 15.0 * c2,
        k / 16.0 * 15.0 * c2,
    ];
    let mut sh = [[0.0; 3]; 9];
    for face in 0..6 {
        for y in 0..dim {
            for x in 0..dim {
                let s = texel_dir(face, x, y, dim);
                let w = cmgen_solid_angle(dim, x, y);
                let p = [
                    1.0,
                    s.y,
                    s.z,
                    s.x,
                    s.y * s.x,
                    s.y * s.z,
                    3.0 * s.z * s.z - 1.0,
                    s.z * s.x,
                    s.x * s.x - s.y * s.y,
                ];
                let l = radiance(s);
                for i in 0..9 {
                    for c in 0..3 {
                        sh[i][c] += l[c] * w * a[i] * p[i];
                    }
                }
            }
        }
    }
    sh
}

/// `(r, g, b); // …` lines, read as Filament's samples read sh.txt (`sscanf("(%f,%f,%f)")`).
fn parse_sh_txt(text: &str) -> Vec<[f64; 3]> {
    text.lines()
        .map(|l| {
            let inner = l.split_once('(').unwrap().1.split_once(')').unwrap().0;
            let v: Vec<f64> = inner
                .split(',')
                .map(|t| t.trim().parse().unwrap())
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// KTX1's key/value pairs (KTX 1.1 §2.15: size, key NUL value NUL, padded to 4).
fn key_values(bytes: &[u8]) -> Vec<(String, String)> {
    let len = u32::from_le_bytes(bytes[60..64].try_into().unwrap()) as usize;
    let mut kv = &bytes[64..64 + len];
    let mut out = Vec::new();
    while kv.len() >= 4 {
        let n = u32::from_le_bytes(kv[..4].try_into().unwrap()) as usize;
        let pair = &kv[4..4 + n];
        let nul = pair.iter().position(|&b| b == 0).unwrap();
        let value = &pair[nul + 1..];
        let value = value.strip_suffix(&[0]).unwrap_or(value);
        out.push((
            String::from_utf8(pair[..nul].to_vec()).unwrap(),
            String::from_utf8(value.to_vec()).unwrap(),
        ));
        kv = &kv[(4 + n).next_multiple_of(4)..];
    }
    out
}

#[test]
fn filament_files_read_back_by_an_independent_reader() {
    let dir = tempfile::tempdir().unwrap();
    let size = 16;
    let (baked, lighting, files) = bake(Engine::Filament, size, None, dir.path());
    let names = crate::common::names(&files);
    assert_eq!(names, ["ibl.ktx", "skybox.ktx", "sh.txt", "README.md"]);

    // The default encoding, as cmgen writes it and Filament's Ktx1Reader reads it.
    let bytes = std::fs::read(&files[0]).unwrap();
    let ktx = ktx::Ktx::new(&bytes[..]);
    assert!(!ktx.big_endian());
    assert_eq!(ktx.gl_type(), GL_R11F_G11F_B10F);
    assert_eq!(ktx.gl_internal_format(), GL_R11F_G11F_B10F);
    assert_eq!(ktx.gl_format(), GL_RGB);
    assert_eq!(ktx.gl_base_internal_format(), GL_RGB);
    assert_eq!((ktx.pixel_width(), ktx.pixel_height()), (size, size));
    assert_eq!(
        (ktx.faces(), ktx.array_elements(), ktx.pixel_depth()),
        (6, 0, 0)
    );
    assert_eq!(ktx.mipmap_levels(), 5);
    for (m, level) in ktx.textures().enumerate() {
        let s = (size >> m).max(1) as usize;
        assert_eq!(
            level.len(),
            6 * s * s * 4,
            "level {m}: six faces of packed texels"
        );
    }
    // The packed texels, decoded here (unsigned 11/11/10-bit floats: 5-bit exponent, bias
    // 15, 6/6/5-bit mantissa; R in the low bits), against the float chain within the
    // encoding's stated error (2⁻⁷ relative for R and G, 2⁻⁶ for B: half an ulp).
    let unpack = |bits: u32, mbits: u32| {
        let (m, e) = (bits & ((1 << mbits) - 1), bits >> mbits);
        let frac = m as f64 / (1u32 << mbits) as f64;
        if e == 0 {
            frac * 2f64.powi(-14)
        } else {
            (1.0 + frac) * 2f64.powi(e as i32 - 15)
        }
    };
    for (m, level) in ktx.textures().enumerate() {
        let s = (size >> m).max(1);
        for face in 0..6 {
            let want = &lighting.specular[m].layers()[face];
            let texels = &level[face * (s * s * 4) as usize..][..(s * s * 4) as usize];
            for (i, px) in texels.chunks_exact(4).enumerate() {
                let v = u32::from_le_bytes(px.try_into().unwrap());
                let got = [
                    unpack(v & 0x7ff, 6),
                    unpack(v >> 11 & 0x7ff, 6),
                    unpack(v >> 22, 5),
                ];
                let w = want.get(i as u32 % s, i as u32 / s);
                for c in 0..3 {
                    let tol = if c == 2 { 2f64.powi(-6) } else { 2f64.powi(-7) };
                    let w = w[c] as f64;
                    assert!(
                        (got[c] - w).abs() <= w * tol + 1e-6,
                        "level {m} face {face}: {} vs {w}",
                        got[c]
                    );
                }
            }
        }
    }
    assert_eq!(baked.spec.levels.len(), 5);
    // Filament's rule: level m of L holds r = 1 − √(1 − m/(L − 1)).
    for (m, &(_, r)) in baked.spec.levels.iter().enumerate() {
        let lod = 4.0 * r * (2.0 - r); // perceptualRoughnessToLod, iblRoughnessOneLevel = 4
        assert!((lod - m as f64).abs() < 1e-12, "level {m}: r = {r}");
    }
    // The sky: the source itself at its own resolution (a 256-wide lat-long: 64²), not
    // the chain's level 0.
    let skybox = std::fs::read(&files[1]).unwrap();
    let sky = ktx::Ktx::new(&skybox[..]);
    assert_eq!(baked.spec.background_face, Some(64));
    assert_eq!(
        (sky.mipmap_levels(), sky.pixel_width(), sky.faces()),
        (1, 64, 6)
    );

    // sh.txt and the ibl file's `sh` key: cmgen's pre-scaled irradiance SH of the map.
    let txt = parse_sh_txt(&std::fs::read_to_string(&files[2]).unwrap());
    assert_eq!(txt.len(), 9);
    let cmgen = cmgen_irradiance_sh(crate::common::coded, 64);
    for (i, (a, b)) in txt.iter().zip(&cmgen).enumerate() {
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() < 2e-4,
                "L{i}[{c}]: {} vs cmgen's {}",
                a[c],
                b[c]
            );
        }
    }
    let kv = key_values(&bytes);
    let sh = &kv.iter().find(|(k, _)| k == "sh").expect("an sh key").1;
    let values: Vec<f64> = sh.split_whitespace().map(|v| v.parse().unwrap()).collect();
    assert_eq!(values.len(), 27);
    for (v, t) in values.iter().zip(txt.iter().flatten()) {
        assert!((v - t).abs() < 1e-6 * t.abs().max(1.0), "{v} vs {t}");
    }

    // Texel values: RGBA16F, decoded here, against the float chain.
    let dir16 = tempfile::tempdir().unwrap();
    let (_, lighting16, files16) = bake(
        Engine::Filament,
        size,
        Some(Encoding::Rgba16F),
        dir16.path(),
    );
    let bytes = std::fs::read(&files16[0]).unwrap();
    let ktx = ktx::Ktx::new(&bytes[..]);
    assert_eq!(
        (ktx.gl_type(), ktx.gl_internal_format(), ktx.gl_format()),
        (GL_HALF_FLOAT, GL_RGBA16F, GL_RGBA)
    );
    for (m, level) in ktx.textures().enumerate() {
        let s = (size >> m).max(1);
        let face_bytes = (s * s * 8) as usize;
        for face in 0..6 {
            let want = &lighting16.specular[m].layers()[face];
            let texels = &level[face * face_bytes..(face + 1) * face_bytes];
            for (i, px) in texels.chunks_exact(8).enumerate() {
                let w = want.get(i as u32 % s, i as u32 / s);
                for c in 0..3 {
                    let h = half::f16::from_le_bytes([px[2 * c], px[2 * c + 1]]).to_f32();
                    assert!(
                        (h - w[c]).abs() <= w[c].abs() * 1e-3 + 1e-6,
                        "level {m} face {face}"
                    );
                }
            }
        }
    }
    // Filament's axes are ours: the same chain whatever the encoding.
    assert_eq!(lighting.specular[0], lighting16.specular[0]);
}
