//! Unity's and Unreal's DDS cubes, parsed by `ddsfile`, their BC6H blocks decoded by
//! `texture2ddecoder` (neither is mirrorball's code): the header, every level against the
//! float chain within BC6H's error, and level 0 showing the direction-coded world as each
//! engine's axes say.

use crate::common::{bake, coded, texel_dir};
use ddsfile::{Caps2, Dds, DxgiFormat};
use mirrorball_bake::Engine;
use mirrorball_core::glam::DVec3;
use mirrorball_core::{metrics, EnvMap, Image, ProjectionKind};

/// Level `m` of face `f` decoded to RGB in [0, 1] (texture2ddecoder gives 8-bit BGRA,
/// `(v·255).clamp(0, 255) as u8`): faces in order, each with its whole chain (DDS's layout).
fn decode(dds: &Dds, size: u32) -> Vec<Vec<Vec<[f64; 3]>>> {
    decode_with(dds, size, false)
}

/// [`decode`], or with mirrorball's own decoder (`bcdec_rs`, through `Encoding::decode`),
/// its floats truncated to 8 bits the same way.
fn decode_with(dds: &Dds, size: u32, ours: bool) -> Vec<Vec<Vec<[f64; 3]>>> {
    let levels = dds.get_num_mipmap_levels();
    let mut at = 0usize;
    (0..6)
        .map(|_| {
            (0..levels)
                .map(|m| {
                    let s = (size >> m).max(1) as usize;
                    let bytes = s.div_ceil(4) * s.div_ceil(4) * 16;
                    let blocks = &dds.data[at..at + bytes];
                    at += bytes;
                    let bw = s.div_ceil(4);
                    let mut px = vec![[0f64; 3]; bw * 4 * bw * 4];
                    for (i, block) in blocks.chunks_exact(16).enumerate() {
                        let rgb = if ours {
                            let img = mirrorball_io::Encoding::Bc6hUnsigned.decode(block, 4, 4);
                            std::array::from_fn(|t| {
                                let px = img.get(t as u32 % 4, t as u32 / 4);
                                std::array::from_fn(|c| {
                                    ((px[c] * 255.0).clamp(0.0, 255.0) as u8) as f64 / 255.0
                                })
                            })
                        } else if block[0] & 31 == 0x0f {
                            decode_mode14(block)
                        } else {
                            let mut texels = [0u32; 16];
                            texture2ddecoder::decode_bc6_block(block, &mut texels, false);
                            texels.map(|bgra| {
                                let [b, g, r, _] = bgra.to_le_bytes();
                                [r, g, b].map(|v| v as f64 / 255.0)
                            })
                        };
                        for (t, v) in rgb.iter().enumerate() {
                            let (x, y) = ((i % bw) * 4 + t % 4, (i / bw) * 4 + t / 4);
                            px[y * bw * 4 + x] = *v;
                        }
                    }
                    let mut out = Vec::new();
                    for y in 0..s {
                        for x in 0..s {
                            out.push(px[y * bw * 4 + x]);
                        }
                    }
                    out
                })
                .collect()
        })
        .collect()
}

/// BC6H mode 14 (mode bits 01111: one region, 16-bit endpoints, 4-bit deltas), decoded
/// from the specification (D3D11.3 §19.5.9; Khronos Data Format 1.3 §20.2), which
/// texture2ddecoder 0.1.2 cannot: its mask for 16-bit endpoints, `(1 << 16) − 1` in `u16`
/// (bc6.rs:678), overflows. Texels as texture2ddecoder gives them: 8-bit, truncated.
fn decode_mode14(block: &[u8]) -> [[f64; 3]; 16] {
    let bits = u128::from_le_bytes(block.try_into().unwrap());
    let field = |at: u32, n: u32| ((bits >> at) & ((1 << n) - 1)) as u32;
    // Six bits read first-to-last as the high bits 15 down to 10.
    let reversed = |at: u32| (0..6).fold(0, |v, k| v << 1 | field(at + k, 1));
    let w = [
        field(5, 10) | reversed(39) << 10,
        field(15, 10) | reversed(49) << 10,
        field(25, 10) | reversed(59) << 10,
    ];
    let delta = [field(35, 4), field(45, 4), field(55, 4)];
    // The second endpoint: the first plus the sign-extended delta, modulo 2¹⁶.
    let e1: [u32; 3] =
        std::array::from_fn(|c| (w[c] as i32 + ((delta[c] as i32) << 28 >> 28)) as u32 & 0xffff);
    const WEIGHTS: [u32; 16] = [0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64];
    std::array::from_fn(|t| {
        let index = if t == 0 {
            field(65, 3)
        } else {
            field(68 + 4 * (t as u32 - 1), 4)
        };
        let wt = WEIGHTS[index as usize];
        std::array::from_fn(|c| {
            // 16-bit endpoints are unquantized as they are; the result ×31/64 is half's bits.
            let v = ((64 - wt) * w[c] + wt * e1[c] + 32) >> 6;
            let h = half::f16::from_bits(((v * 31) >> 6) as u16).to_f32();
            ((h * 255.0).clamp(0.0, 255.0) as u8) as f64 / 255.0
        })
    })
}

/// Each engine's direction `e` in mirrorball's world, written out from the engines' axes
/// (not from the bake crate's table): Unity x right, y up, z forward; Unreal x forward,
/// y right, z up; mirrorball x right, y up, −z forward.
fn world_of(engine: Engine, e: DVec3) -> DVec3 {
    match engine {
        Engine::Unity => DVec3::new(e.x, e.y, -e.z),
        _ => DVec3::new(e.y, e.z, -e.x),
    }
}

#[test]
fn unity_and_unreal_cubes_read_back_by_independent_readers() {
    for engine in [Engine::Unity, Engine::Unreal] {
        let dir = tempfile::tempdir().unwrap();
        let size = 64;
        let (baked, lighting, files) = bake(engine, size, None, dir.path());
        assert_eq!(files.len(), 3, "{engine}: specular, diffuse, README");
        let dds = Dds::read(std::fs::File::open(&files[0]).unwrap()).unwrap();
        assert_eq!(dds.get_dxgi_format(), Some(DxgiFormat::BC6H_UF16));
        assert_eq!(dds.get_width(), size);
        assert_eq!(dds.get_num_mipmap_levels(), size.trailing_zeros() + 1);
        assert!(dds.header.caps2.contains(Caps2::CUBEMAP_ALLFACES));
        assert_eq!(baked.spec.levels.len(), size.trailing_zeros() as usize + 1);
        let decoded = decode(&dds, size);

        // Every level against the float chain, by the measure and floors the encoding
        // states (crates/io/tests/io/quality.rs: log-PSNR at least 49.5 dB at level 0 and
        // 31.5 dB at any level), the decoder's truncated 8-bit values taken at the middle
        // of their step.
        let cube = ProjectionKind::Cube.default_projection();
        let as_map = |d: &[Vec<Vec<[f64; 3]>>], m: usize| {
            let s = (size >> m).max(1);
            let faces: Vec<Image> = (0..6)
                .map(|f| {
                    let data = d[f][m]
                        .iter()
                        .flat_map(|px| px.map(|v| (v + 0.5 / 255.0) as f32))
                        .collect();
                    Image::from_vec(s, s, 3, data).unwrap()
                })
                .collect();
            EnvMap::new(cube, faces).unwrap()
        };
        let ours = decode_with(&dds, size, true);
        for m in 0..decoded[0].len() {
            let reference = EnvMap::new(
                cube,
                lighting.specular[m]
                    .layers()
                    .iter()
                    .map(|l| l.with_channels(3))
                    .collect(),
            )
            .unwrap();
            let p = metrics::log_psnr(&reference, &as_map(&decoded, m)).unwrap();
            let p_ours = metrics::log_psnr(&reference, &as_map(&ours, m)).unwrap();
            // Measured on this map at 64²: 46.3 dB at level 0, 25 dB at the 4×4 level
            // (one block a face holding three gradients); 1 dB under.
            let floor = if m == 0 { 45.0 } else { 24.0 };
            assert!(p >= floor, "{engine} level {m}: {p:.1} dB, below {floor}");
            assert!(
                (p - p_ours).abs() < 0.3,
                "{engine} level {m}: {p:.2} vs our decoder's {p_ours:.2} dB"
            );
        }

        // Level 0 (roughness 0, a mirror) shows, at the engine's direction e, the colour of
        // the world's direction e names in the engine's axes.
        let mut worst = 0f64;
        for (face, levels) in decoded.iter().enumerate() {
            for (i, got) in levels[0].iter().enumerate() {
                let e = texel_dir(face, i as u32 % size, i as u32 / size, size);
                let want = coded(world_of(engine, e));
                for c in 0..3 {
                    worst = worst.max((got[c] - want[c]).abs());
                }
            }
        }
        assert!(
            worst < 0.06,
            "{engine}: level 0 is not the world in its axes ({worst})"
        );
    }
}
