//! Specular prefiltering: Phong and GGX lobes by filtered importance sampling, and the
//! roughness-to-mip-level mappings engines use.
//!
//! # Filtered importance sampling
//!
//! Křivánek & Colbert (2008, GPU Gems 3 ch. 20) and Karis (2013): for each output direction
//! `n`, `N` directions `l_i` are drawn from the lobe's own distribution (a fixed Hammersley
//! set, rotated into a frame about `n`), and each is looked up not in the full-resolution
//! map but in the mip level whose texels are about as large as the solid angle the sample
//! stands for, `Ω_s = 1/(N p(l_i))`:
//!
//! ```text
//! lod_i = ½ log₂(Ω_s / Ω_texel(l_i)) + bias,      P(n) ≈ Σ w_i L_lod(l_i) / Σ w_i.
//! ```
//!
//! `Ω_texel` is the level-0 texel's solid angle *where the sample lands*
//! (`(2/size)²·|ma|³` on a cube: corner texels are five times smaller than centre texels),
//! not the face-centre average most implementations use. The lookups are trilinear in a
//! seamless, solid-angle-weighted box pyramid, so the pre-averaged texels carry exactly the
//! energy of the region they cover. Weights: GGX samples the half vector from
//! `D(h)(n·h)` and reflects (`p(l) = D/4` when `n = v`), weight `w = n·l`; Phong and
//! Lambert sample their own kernels exactly, `w = 1`. `Σ w_i` is the same for every
//! texel, so a constant environment comes out constant to rounding (the furnace test).
//!
//! The frame about `n` is `t = normalize(ŷ × n)`, `b = n × t`, continuous everywhere but at
//! the poles: no seam can come from the frame.
//!
//! A floor on the level keeps each sample of a lobe narrower than the output texel at least
//! as blurred as the difference between the texel's solid angle and the lobe's (a mirror:
//! the whole texel), so sharp lobes on coarse outputs are antialiased rather than aliased;
//! lobes wider than their texels are evaluated at the texel centre as they are.
//!
//! # Roughness per mip level
//!
//! [`RoughnessMapping`] gives the roughness stored at each level of an `L`-level chain, and
//! the level a shader should read for a roughness:
//!
//! | mapping | roughness of level `m` | level for roughness `r` |
//! | --- | --- | --- |
//! | `Linear` | `m/(L−1)` | `r (L−1)` |
//! | `Ue4` (Unreal Engine 4, `ComputeReflectionCaptureMipFromRoughness`) | `min(1, 2^((m + 2 − L)/1.2))` | `L − 2 + 1.2 log₂ r` |
//! | `Filament` (cmgen / `perceptualRoughnessToLod`) | `1 − √(1 − m/(L−1))` | `(L−1)·r(2 − r)` |

use crate::cube::SeamlessCube;
use crate::lobe::Lobe;
use glam::{Vec3, Vec4};
use mirrorball_core::simd::F32x4;
use mirrorball_core::CubeMap;
use std::f64::consts::PI;

/// Which roughness each mip level of a prefiltered chain holds.
#[derive(Clone, Debug, PartialEq)]
pub enum RoughnessMapping {
    /// `r = m/(L − 1)`: level 0 is a mirror, the last level roughness 1.
    Linear,
    /// Unreal Engine 4: `r = min(1, 2^((m + 2 − L)/1.2))` (the 1×1 level and the one
    /// before it are roughness 1).
    Ue4,
    /// Filament's cmgen: `r = 1 − √(1 − m/(L − 1))` (its shaders read level
    /// `(L − 1)·r(2 − r)`).
    Filament,
    /// One roughness per level, given.
    Custom(Vec<f64>),
}

impl RoughnessMapping {
    /// Parses `linear`, `ue4` (`unreal`), `filament` (`cmgen`), or a comma-separated list.
    pub fn parse(s: &str) -> Option<RoughnessMapping> {
        match s.trim().to_ascii_lowercase().as_str() {
            "linear" => Some(RoughnessMapping::Linear),
            "ue4" | "unreal" | "ue" => Some(RoughnessMapping::Ue4),
            "filament" | "cmgen" => Some(RoughnessMapping::Filament),
            other => {
                let v: Option<Vec<f64>> = other
                    .split(',')
                    .map(|t| {
                        t.trim()
                            .parse::<f64>()
                            .ok()
                            .filter(|x| (0.0..=1.0).contains(x))
                    })
                    .collect();
                v.filter(|v| !v.is_empty()).map(RoughnessMapping::Custom)
            }
        }
    }

    /// The roughness of level `level` of a `levels`-level chain.
    pub fn roughness(&self, level: usize, levels: usize) -> f64 {
        let last = levels.saturating_sub(1).max(1) as f64;
        let m = level as f64;
        match self {
            RoughnessMapping::Linear => (m / last).min(1.0),
            RoughnessMapping::Ue4 => 2f64.powf((m + 2.0 - levels as f64) / 1.2).min(1.0),
            RoughnessMapping::Filament => 1.0 - (1.0 - (m / last).min(1.0)).sqrt(),
            RoughnessMapping::Custom(v) => v
                .get(level)
                .or(v.last())
                .copied()
                .unwrap_or(0.0)
                .clamp(0.0, 1.0),
        }
    }

    /// The (fractional) level a shader should sample for roughness `r` (the inverse).
    pub fn level(&self, r: f64, levels: usize) -> f64 {
        let last = levels.saturating_sub(1).max(1) as f64;
        let r = r.clamp(0.0, 1.0);
        let m = match self {
            RoughnessMapping::Linear => r * last,
            RoughnessMapping::Ue4 => levels as f64 - 2.0 + 1.2 * r.max(1e-3).log2(),
            RoughnessMapping::Filament => last * r * (2.0 - r),
            RoughnessMapping::Custom(v) => {
                // Piecewise-linear inverse of a non-decreasing list.
                let mut m = 0.0;
                for i in 1..v.len() {
                    if r <= v[i] {
                        let span = (v[i] - v[i - 1]).max(1e-12);
                        m = (i - 1) as f64 + ((r - v[i - 1]) / span).clamp(0.0, 1.0);
                        return m;
                    }
                    m = i as f64;
                }
                m
            }
        };
        m.clamp(0.0, last)
    }

    /// A short name for reports.
    pub fn name(&self) -> String {
        match self {
            RoughnessMapping::Linear => "linear".into(),
            RoughnessMapping::Ue4 => "ue4".into(),
            RoughnessMapping::Filament => "filament".into(),
            RoughnessMapping::Custom(_) => "custom".into(),
        }
    }

    /// [`RoughnessMapping::level`] as a formula for people (before clamping to the chain).
    pub fn level_formula(&self) -> &'static str {
        match self {
            RoughnessMapping::Linear => "level = roughness * (levels - 1)",
            RoughnessMapping::Ue4 => "level = levels - 2 + 1.2 * log2(roughness)",
            RoughnessMapping::Filament => "level = (levels - 1) * roughness * (2 - roughness)",
            RoughnessMapping::Custom(_) => {
                "piecewise-linear inverse of the listed roughness values"
            }
        }
    }
}

/// Point `i` of the `n`-point Fibonacci lattice on the unit square,
/// `((i + ½)/n, frac(i/φ))`: like the Hammersley set (`i/n` and the radical inverse of `i`)
/// a low-discrepancy set stratified in the first coordinate, and measurably a little more
/// accurate here (the lobe's cumulative distribution in θ is sampled by the first
/// coordinate, the azimuth by the second).
#[inline]
pub(crate) fn lattice(i: u32, n: u32) -> (f64, f64) {
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    ((i as f64 + 0.5) / n as f64, (i as f64 * INV_PHI).fract())
}

/// A lobe's sample set in the frame of its axis (`+z`), in groups of four for SIMD: per
/// group `[x, y, z, weight, ½ log₂ Ω_s + bias]` (padding has weight 0).
pub(crate) struct SampleSet {
    pub groups: Vec<[Vec4; 5]>,
    pub weight_sum: f32,
}

impl SampleSet {
    /// `n` samples of `lobe` (not a mirror).
    pub fn new(lobe: &Lobe, n: u32, lod_bias: f32) -> SampleSet {
        let n = n.max(1);
        let mut samples: Vec<[f32; 5]> = Vec::with_capacity(n as usize);
        for i in 0..n {
            let (u1, u2) = lattice(i, n);
            let phi = 2.0 * PI * u2;
            let (l, w, pdf) = lobe.sample(u1, phi);
            if w <= 0.0 {
                // A GGX reflection below the horizon: weight 0, costs without counting.
                continue;
            }
            let omega = 1.0 / (n as f64 * pdf.max(1e-30));
            samples.push([
                l.x as f32,
                l.y as f32,
                l.z as f32,
                w as f32,
                (0.5 * omega.log2()) as f32 + lod_bias,
            ]);
        }
        let weight_sum = samples.iter().map(|s| s[3]).sum();
        let groups = samples
            .chunks(4)
            .map(|c| {
                let get = |k: usize, pad: f32| {
                    Vec4::from_array(std::array::from_fn(|i| c.get(i).map_or(pad, |s| s[k])))
                };
                [
                    get(0, 0.0),
                    get(1, 0.0),
                    get(2, 1.0),
                    get(3, 0.0),
                    get(4, 0.0),
                ]
            })
            .collect();
        SampleSet { groups, weight_sum }
    }
}

/// A continuous tangent frame about `n`: `t = normalize(ŷ × n)`, `b = n × t` (the poles
/// fall back to `x̂`).
#[inline(always)]
pub(crate) fn frame(n: Vec3) -> (Vec3, Vec3) {
    let t = Vec3::new(n.z, 0.0, -n.x); // ŷ × n
    let len2 = t.length_squared();
    let t = if len2 > 1e-12 {
        t * len2.sqrt().recip()
    } else {
        Vec3::X
    };
    (t, n.cross(t))
}

/// `log₂ x` for `x ∈ [½, 1]` (a cube direction's largest component), to 1.4e-3: a cubic
/// least-squares fit, four lanes at once.
#[inline(always)]
fn log2_major(x: Vec4) -> Vec4 {
    Vec4::splat(-3.133_847_7)
        + x * (Vec4::splat(6.021_568) + x * (Vec4::splat(-4.118_088) + x * 1.231_347_8))
}

/// `2²³`: adding it to a non-negative integer-valued `f32` below `2²³` leaves the integer
/// in the low 23 bits of the sum, so lanes convert to indices without the saturating
/// float-to-integer conversions (several instructions each) that `as` costs.
const MAGIC: f32 = 8_388_608.0;

/// The integer in a lane that had [`MAGIC`] added.
#[inline(always)]
fn lane_index(x: f32) -> usize {
    (x.to_bits() & 0x007f_ffff) as usize
}

/// Four bilinear lookups (one per lane) on the levels described by `p` (per lane: face
/// size as `f32`, where the face starts, its bordered stride), weighted by `w`: coordinates
/// and bilinear weights in SIMD lanes, then four texel quads.
#[inline(always)]
fn gather4(
    cube: &SeamlessCube,
    p: &([f32; 4], [usize; 4], [usize; 4]),
    u: Vec4,
    v: Vec4,
    w: Vec4,
) -> Vec4 {
    let size = Vec4::from_array(p.0);
    let half = Vec4::splat(0.5);
    let max = size + 0.499_9;
    let x = (u * size + half).max(half).min(max);
    let y = (v * size + half).max(half).min(max);
    let (x0, y0) = (x.trunc(), y.trunc());
    let (fx, fy) = (x - x0, y - y0);
    // Column and row each below 2²³ (faces up to 4096²), so exact as integers; the address
    // within the face is made in integer arithmetic (a 4096² face's bordered texels number
    // more than 2²⁴, past what f32 holds exactly).
    let xi = (x0 + MAGIC).to_array();
    let yi = (y0 + MAGIC).to_array();
    let (gx, gy) = (Vec4::ONE - fx, Vec4::ONE - fy);
    let w00 = (w * gx * gy).to_array();
    let w10 = (w * fx * gy).to_array();
    let w01 = (w * gx * fy).to_array();
    let w11 = (w * fx * fy).to_array();
    let mut acc = Vec4::ZERO;
    for k in 0..4 {
        let i = p.1[k] + lane_index(yi[k]) * p.2[k] + lane_index(xi[k]);
        let [a, b, c, d] = cube.quad(i, p.2[k]);
        acc += a * w00[k] + b * w10[k] + c * w01[k] + d * w11[k];
    }
    acc
}

/// The filtered-importance-sampling estimate of the lobe about `n`, with `floor` the
/// `½ log₂` of the least solid angle a sample may stand for (the output texel's).
///
/// Four samples at a time: rotation into the frame, OpenGL face selection and face
/// coordinates ([`CubeMap::uv4`]) and mip level are computed in SIMD lanes; the four
/// trilinear fetches follow.
#[inline]
pub(crate) fn fis(cube: &SeamlessCube, set: &SampleSet, n: Vec3, floor: f32) -> Vec4 {
    let (t, b) = frame(n);
    let (tx, ty, tz) = (Vec4::splat(t.x), Vec4::splat(t.y), Vec4::splat(t.z));
    let (bx, by, bz) = (Vec4::splat(b.x), Vec4::splat(b.y), Vec4::splat(b.z));
    let (nx, ny, nz) = (Vec4::splat(n.x), Vec4::splat(n.y), Vec4::splat(n.z));
    let floor4 = Vec4::splat(floor);
    let c0 = Vec4::splat(cube.half_log2_texel0());
    let zero = Vec4::ZERO;
    let last = Vec4::splat(cube.last_lod());
    let top = cube.last_lod() as usize;
    let mut acc = Vec4::ZERO;
    for g in &set.groups {
        let [sx, sy, sz, w, hl] = *g;
        let lx = tx * sx + bx * sy + nx * sz;
        let ly = ty * sx + by * sy + ny * sz;
        let lz = tz * sx + bz * sy + nz * sz;
        // OpenGL's face and (u, v) of the four directions: core's table, four lanes.
        let lanes = |v: Vec4| F32x4::from_array(v.to_array());
        let at = CubeMap::uv4(lanes(lx), lanes(ly), lanes(lz));
        let (u, v) = (
            Vec4::from_array(at.sc.to_array()),
            Vec4::from_array(at.tc.to_array()),
        );
        let ma = Vec4::from_array(at.ma.to_array());
        let lod = (hl.max(floor4) - c0 - log2_major(ma) * 1.5)
            .max(zero)
            .min(last);
        let l0 = lod.trunc();
        let f = lod - l0;
        let l0 = (l0 + MAGIC).to_array();
        // Level parameters per lane (size, where the lane's face starts, the stride), for
        // the level below the sample's lod, and above it only when some lane blends in.
        let lanes_l0 = l0.map(lane_index);
        let lanes_face = at.layer.to_array().map(|l| l as usize);
        let params = |level: [usize; 4]| {
            let mut p = ([0.0f32; 4], [0usize; 4], [0usize; 4]);
            for k in 0..4 {
                let lv = cube.level(level[k]);
                p.0[k] = lv.size;
                p.1[k] = lv.face[lanes_face[k]];
                p.2[k] = lv.stride;
            }
            p
        };
        let wb = w * f;
        let wa = w - wb;
        acc += gather4(cube, &params(lanes_l0), u, v, wa);
        if f.cmpgt(zero).any() {
            let up = lanes_l0.map(|l| (l + 1).min(top));
            acc += gather4(cube, &params(up), u, v, wb);
        }
    }
    acc / set.weight_sum
}

/// The number of importance samples for `lobe` when the caller asks for `base`: wide lobes
/// gather many more distinct features of the environment, each seen through a wider (and
/// so blurrier) mip footprint, so their count doubles for every doubling of the lobe's
/// angular scale beyond 0.05 rad, up to 16 × `base` (a cosine-wide lobe). Wide lobes live
/// on the small levels of a chain, so this costs little.
pub(crate) fn sample_count(base: u32, lobe: &Lobe) -> u32 {
    let j = (lobe.angular_scale() / 0.05).log2().clamp(0.0, 4.0);
    ((base.max(1) as f64) * 2f64.powf(j)).round() as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookups_address_every_texel_of_a_4096_face() {
        // Each texel holds (x, y, face): every lookup at a texel centre must return its own
        // texel, and halfway between two texels their mean, on the largest working cube,
        // whose bordered texels past the first 2²⁴ of a face f32 could not address.
        use mirrorball_core::{EnvMap, Image, ProjectionKind};
        use rayon::prelude::*;
        let n = 4096u32;
        let faces: Vec<Image> = (0..6)
            .map(|f| {
                let mut data = vec![0.0f32; (n * n * 3) as usize];
                data.par_chunks_mut(3 * n as usize)
                    .enumerate()
                    .for_each(|(y, row)| {
                        for (x, t) in row.chunks_exact_mut(3).enumerate() {
                            t.copy_from_slice(&[x as f32, y as f32, f as f32]);
                        }
                    });
                Image::from_vec(n, n, 3, data).unwrap()
            })
            .collect();
        let env = EnvMap::new(ProjectionKind::Cube.default_projection(), faces).unwrap();
        let cube = SeamlessCube::new(&env);
        drop(env);
        let at = |x: f32| (x + 0.5) / n as f32;
        let lanes = [
            (4095.0f32, 4095.0f32),
            (4000.0, 4090.0),
            (0.0, 4095.0),
            (4095.0, 0.0),
        ];
        for face in [0usize, 5] {
            let p = (
                [n as f32; 4],
                [cube.level(0).face[face]; 4],
                [cube.level(0).stride; 4],
            );
            let u = Vec4::from_array(lanes.map(|l| at(l.0)));
            let v = Vec4::from_array(lanes.map(|l| at(l.1)));
            for (k, &(x, y)) in lanes.iter().enumerate() {
                let mut w = [0.0f32; 4];
                w[k] = 1.0;
                let got = gather4(&cube, &p, u, v, Vec4::from_array(w));
                assert_eq!(
                    got.truncate(),
                    Vec3::new(x, y, face as f32),
                    "{face} {x} {y}"
                );
                let one = cube.bilinear(0, face, at(x), at(y));
                assert_eq!(one, got, "{face} {x} {y}");
            }
            // Halfway between columns 4093 and 4094 of row 4094.
            let mid = cube.bilinear(0, face, 4094.0 / n as f32, at(4094.0));
            assert_eq!(mid.truncate(), Vec3::new(4093.5, 4094.0, face as f32));
        }
    }

    #[test]
    fn mappings_invert() {
        for m in [
            RoughnessMapping::Linear,
            RoughnessMapping::Ue4,
            RoughnessMapping::Filament,
            RoughnessMapping::Custom(vec![0.0, 0.2, 0.5, 1.0]),
        ] {
            for level in 1..9 {
                let r = m.roughness(level, 10);
                if r < 1.0 {
                    let back = m.level(r, 10);
                    assert!(
                        (back - level as f64).abs() < 1e-9
                            || matches!(m, RoughnessMapping::Custom(_)),
                        "{m:?} {level} {r} {back}"
                    );
                }
            }
        }
        assert_eq!(RoughnessMapping::Linear.roughness(0, 10), 0.0);
        assert_eq!(RoughnessMapping::Filament.roughness(9, 10), 1.0);
        assert_eq!(RoughnessMapping::Ue4.roughness(8, 10), 1.0);
    }

    #[test]
    fn frame_is_orthonormal() {
        for d in [
            Vec3::X,
            Vec3::Y,
            -Vec3::Y,
            Vec3::new(0.3, -0.5, 0.8).normalize(),
        ] {
            let (t, b) = frame(d);
            assert!(t.dot(d).abs() < 1e-6 && b.dot(d).abs() < 1e-6 && t.dot(b).abs() < 1e-6);
            assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
        }
    }
}
