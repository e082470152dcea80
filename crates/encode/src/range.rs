//! What each storage can hold, the one table every writer reads: the largest finite value of
//! each colour channel, whether negative values and NaN or infinities are held, and whether
//! the codes are display-referred.
//!
//! | [`Storage`] | largest | negative | NaN, ∞ |
//! | --- | --- | --- | --- |
//! | half (`Rgba16F`: EXR half, KTX2/DDS/KTX1) | 65504 | yes | yes |
//! | float (`Rgba32F`: EXR float, KTX2/DDS/KTX1) | 3.4·10³⁸ | yes | yes |
//! | `Rgb9E5` | 65408 | 0 | 0 |
//! | `B10G11R11` | 65024 (R, G), 64512 (B) | 0 | 0 |
//! | `Rgbd` | 255 | 0 | 0 |
//! | `Rgbm` | 6 | 0 | 0 |
//! | `Bc6hUnsigned` | 65504 | 0 | 0 |
//! | `Bc6hSigned` | ±65504 | yes | 0 |
//! | Radiance RGBE | 255·2¹¹⁹ ≈ 1.7·10³⁸ | 0 | 0 |
//! | 8- and 16-bit display codes (PNG, JPEG) | 1 (white) | 0 | 0 |
//!
//! [`Range::fit`] is the one rule by which a value becomes one the storage holds: a finite
//! value beyond the range is written as the range's end (a sun brighter than 65504 is 65504
//! in half, never infinity), NaN as 0 and infinities as the ends, except where the storage
//! holds NaN and infinities (binary16 and binary32), which keep them: the caller decides
//! whether they reach a writer (`mirrorball` replaces them by 0 unless `--keep-invalid`).
//!
//! [`Range::measure_map`] says, before a map is written, what [`Range::fit`] will change:
//! the texels past the range, the largest value, and the energy lost, weighted by each
//! texel's exact solid angle ([`Clipped`]).

use crate::{ldr8, packed_float, shared_exp, Encoding};
use mirrorball_core::{Choice, EnvMap, Image, WorldProjection};
use rayon::prelude::*;

/// The largest finite binary16 value (also BC6H's largest, `0x7BFF`).
pub const HALF_MAX: f32 = 65504.0;

/// The largest value Radiance RGBE holds: mantissa 255 with the largest exponent (byte 255).
pub const RGBE_MAX: f32 = 255.0 * (1u128 << 119) as f32;

/// How a file stores a colour value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    /// A texel encoding: KTX2, DDS and KTX1 cubes; OpenEXR's half is [`Encoding::Rgba16F`]'s
    /// range, its float [`Encoding::Rgba32F`]'s.
    Texels(Encoding),
    /// Radiance RGBE: three 8-bit mantissas sharing an 8-bit exponent.
    Rgbe,
    /// 8-bit display codes (sRGB PNG and JPEG): linear light in [0, 1].
    Display8,
    /// 16-bit display codes (sRGB PNG).
    Display16,
}

/// What a [`Storage`] holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// The largest finite value of R, G and B.
    pub max: [f32; 3],
    /// Whether negative values are held (to minus `max`); else they are written as 0.
    pub signed: bool,
    /// Whether NaN and infinities are held (binary16, binary32); else NaN is written as 0
    /// and infinities as the range's ends.
    pub special: bool,
    /// Display-referred codes: values past 1 are white by nature (after exposure and tone
    /// curve), not a loss to report.
    pub display: bool,
}

impl Storage {
    /// Every storage: each [`Encoding`], then RGBE and the display codes.
    pub fn all() -> Vec<Storage> {
        Encoding::NAMES
            .iter()
            .map(|&(e, _)| Storage::Texels(e))
            .chain([Storage::Rgbe, Storage::Display8, Storage::Display16])
            .collect()
    }

    /// What the storage holds (see the module's table).
    pub const fn range(self) -> Range {
        let (max, signed, special, display) = match self {
            Storage::Texels(Encoding::Rgba16F) => ([HALF_MAX; 3], true, true, false),
            Storage::Texels(Encoding::Rgba32F) => ([f32::MAX; 3], true, true, false),
            Storage::Texels(Encoding::Rgb9E5) => ([shared_exp::MAX; 3], false, false, false),
            Storage::Texels(Encoding::B10G11R11) => (
                [
                    packed_float::MAX_11,
                    packed_float::MAX_11,
                    packed_float::MAX_10,
                ],
                false,
                false,
                false,
            ),
            Storage::Texels(Encoding::Rgbd) => ([ldr8::RGBD_RANGE; 3], false, false, false),
            Storage::Texels(Encoding::Rgbm) => ([ldr8::RGBM_RANGE; 3], false, false, false),
            Storage::Texels(Encoding::Bc6hUnsigned) => ([HALF_MAX; 3], false, false, false),
            Storage::Texels(Encoding::Bc6hSigned) => ([HALF_MAX; 3], true, false, false),
            Storage::Rgbe => ([RGBE_MAX; 3], false, false, false),
            Storage::Display8 | Storage::Display16 => ([1.0; 3], false, false, true),
        };
        Range {
            max,
            signed,
            special,
            display,
        }
    }

    /// Its name for people: "half", "float", "RGB9E5", "Radiance RGBE", "8-bit PNG/JPEG".
    pub fn name(self) -> &'static str {
        match self {
            Storage::Texels(Encoding::Rgba16F) => "half",
            Storage::Texels(Encoding::Rgba32F) => "float",
            Storage::Texels(e) => e.label(),
            Storage::Rgbe => "Radiance RGBE",
            Storage::Display8 => "8-bit PNG/JPEG",
            Storage::Display16 => "16-bit PNG",
        }
    }
}

impl Range {
    /// Channel `c`'s value `v` as the storage holds it: finite values clamped to
    /// `[−max, max]` (signed) or `[0, max]`; NaN and infinities kept where the storage
    /// holds them, else NaN as 0 and infinities as the range's ends. Alpha (`c = 3`) has
    /// the colours' range. Values inside the range are returned unchanged.
    #[inline(always)]
    pub fn fit(&self, c: usize, v: f32) -> f32 {
        let hi = self.max[if c < 3 { c } else { 0 }];
        let lo = if self.signed { -hi } else { 0.0 };
        if v.is_finite() || !self.special {
            // `clamp` keeps NaN: it becomes 0 here.
            let f = v.clamp(lo, hi);
            if f.is_nan() {
                0.0
            } else {
                f
            }
        } else {
            v
        }
    }

    /// The smallest largest value of the three channels.
    pub fn least_max(&self) -> f32 {
        self.max[0].min(self.max[1]).min(self.max[2])
    }

    /// What writing `image` changes (colour channels only). With `weight` (the solid angle
    /// of texel `(x, y)`, or any weight a texel carries), [`Clipped::lost`] and
    /// [`Clipped::total`] are the weighted energies; without, only the counts.
    pub fn measure(&self, image: &Image, weight: Option<&Weight>) -> Clipped {
        let (w, c) = (image.width() as usize, image.channels());
        if w == 0 {
            return Clipped::default();
        }
        image
            .data()
            .par_chunks(w * c)
            .enumerate()
            .map(|(y, row)| self.measure_row(row, c, y as u32, weight))
            .reduce(Clipped::default, std::ops::Add::add)
    }

    /// [`Range::measure`] of one row `y`.
    fn measure_row(&self, row: &[f32], c: usize, y: u32, weight: Option<&Weight>) -> Clipped {
        let mut m = Clipped {
            weighted: weight.is_some(),
            ..Clipped::default()
        };
        let lo = self.max.map(|hi| if self.signed { -hi } else { 0.0 });
        for (x, px) in row.chunks_exact(c).enumerate() {
            let inside = (0..3).all(|k| px[k] >= lo[k] && px[k] <= self.max[k]);
            if inside && weight.is_none() {
                continue;
            }
            let (mut energy, mut lost, mut over) = (0.0f64, 0.0f64, false);
            for (k, &v) in px.iter().enumerate().take(3) {
                if !v.is_finite() {
                    m.invalid += 1;
                    continue;
                }
                if v < 0.0 && !self.signed {
                    m.negative += 1;
                    continue;
                }
                let a = v.abs();
                energy += f64::from(a);
                if a > self.max[k] {
                    over = true;
                    lost += f64::from(a - self.max[k]);
                    m.largest = m.largest.max(a);
                }
            }
            m.texels += u64::from(over);
            if let Some(weight) = weight {
                let wt = weight(x as u32, y);
                m.total += wt * energy;
                m.lost += wt * lost;
            }
        }
        m
    }

    /// What writing `env` changes: every layer counted; when any value is past the range
    /// (and the codes are not display-referred), the energies weighted by each texel's exact
    /// solid angle, so [`Clipped::share`] is the share of the map's radiant energy lost.
    pub fn measure_map(&self, env: &EnvMap) -> Clipped {
        let counted = env
            .layers()
            .iter()
            .map(|l| self.measure(l, None))
            .fold(Clipped::default(), std::ops::Add::add);
        if counted.texels == 0 || self.display {
            return counted;
        }
        (0..env.layers().len())
            .map(|layer| self.measure_layer(env, layer))
            .fold(Clipped::default(), std::ops::Add::add)
    }

    /// Layer `layer` of `env` measured with its texels' solid angles.
    pub fn measure_layer(&self, env: &EnvMap, layer: usize) -> Clipped {
        let p = *env.projection();
        let (w, h) = (env.width(), env.height());
        let weight = move |x: u32, y: u32| p.texel_solid_angle(layer, x, y, w, h);
        self.measure(&env.layers()[layer], Some(&weight))
    }
}

/// A texel's weight, by its position `(x, y)` in its layer.
pub type Weight = dyn Fn(u32, u32) -> f64 + Sync;

/// What [`Range::fit`] changes when a map (or a picture, or part of one) is written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clipped {
    /// Texels with a colour value past the range (written as the range's end).
    pub texels: u64,
    /// The largest magnitude among the values past the range.
    pub largest: f32,
    /// The energy clipping removes: each texel's weight (solid angle) times what its values
    /// lose, `Σ ω·(|v| − max)`.
    pub lost: f64,
    /// The energy measured, `Σ ω·|v|` over the finite values the storage holds.
    pub total: f64,
    /// Whether [`Clipped::lost`] and [`Clipped::total`] were weighted (else only counts).
    pub weighted: bool,
    /// Negative colour values an unsigned storage writes as 0.
    pub negative: u64,
    /// NaN and infinite colour values.
    pub invalid: u64,
}

impl Default for Clipped {
    /// Nothing measured (and so nothing unweighted).
    fn default() -> Clipped {
        Clipped {
            texels: 0,
            largest: 0.0,
            lost: 0.0,
            total: 0.0,
            weighted: true,
            negative: 0,
            invalid: 0,
        }
    }
}

/// Both measurements together (of one map: parts of it, or its layers).
impl std::ops::Add for Clipped {
    type Output = Clipped;
    fn add(self, o: Clipped) -> Clipped {
        Clipped {
            texels: self.texels + o.texels,
            largest: self.largest.max(o.largest),
            lost: self.lost + o.lost,
            total: self.total + o.total,
            weighted: self.weighted && o.weighted,
            negative: self.negative + o.negative,
            invalid: self.invalid + o.invalid,
        }
    }
}

impl Clipped {
    /// The share of the energy clipping removes, `lost / total`, when it was weighted.
    pub fn share(&self) -> Option<f64> {
        (self.weighted && self.total > 0.0).then(|| self.lost / self.total)
    }

    /// Stops of exposure that bring the largest value inside `range`: the smallest `n` with
    /// `largest · 2⁻ⁿ ≤` the smallest of its channel maxima (0 when nothing is past it).
    pub fn stops_to_fit(&self, range: &Range) -> u32 {
        let mut n = 0;
        let max = range.least_max();
        while n < 256 && self.largest * 0.5f32.powi(n as i32) > max {
            n += 1;
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::ProjectionKind;

    /// Every encoding's largest value decodes to itself, and a larger one is written as it.
    #[test]
    fn each_encoding_holds_its_largest_value_and_no_more() {
        for s in Storage::all() {
            let Storage::Texels(e) = s else { continue };
            let r = s.range();
            let mut img = Image::new(4, 4, 3);
            img.data_mut().fill(1.0);
            img.set(0, 0, &r.max);
            // No finite value lies past float's largest: there, texel 1 is the largest too.
            img.set(
                1,
                0,
                &r.max
                    .map(|m| if m * 4.0 < f32::INFINITY { m * 4.0 } else { m }),
            );
            let mut bytes = Vec::new();
            e.encode(&img, &mut bytes);
            let back = e.decode(&bytes, 4, 4);
            for x in 0..2 {
                for k in 0..3 {
                    let v = back.get(x, 0)[k];
                    assert!(v.is_finite(), "{s:?} texel {x} channel {k}: {v}");
                    // Lossy encodings land near it; none lands past it.
                    assert!(
                        v <= r.max[k],
                        "{s:?} texel {x} channel {k}: {v} > {}",
                        r.max[k]
                    );
                    assert!(v >= r.max[k] * 0.9, "{s:?} texel {x} channel {k}: {v}");
                }
            }
        }
    }

    #[test]
    fn fit_clamps_finite_values_and_keeps_special_ones_where_held() {
        let half = Storage::Texels(Encoding::Rgba16F).range();
        assert_eq!(half.fit(0, 1e6), HALF_MAX);
        assert_eq!(half.fit(0, -1e6), -HALF_MAX);
        assert_eq!(half.fit(0, 1.5), 1.5);
        assert!(half.fit(0, f32::NAN).is_nan());
        assert_eq!(half.fit(0, f32::INFINITY), f32::INFINITY);
        let e = Storage::Texels(Encoding::Rgb9E5).range();
        assert_eq!(e.fit(0, f32::NAN), 0.0);
        assert_eq!(e.fit(0, f32::INFINITY), shared_exp::MAX);
        assert_eq!(e.fit(0, -3.0), 0.0);
        let b = Storage::Texels(Encoding::B10G11R11).range();
        assert_eq!(b.fit(2, 65000.0), 64512.0);
        assert_eq!(b.fit(1, 65000.0), 65000.0);
    }

    /// The measured share agrees with a sum written out here, on a cube with a sun.
    #[test]
    fn the_share_lost_is_the_solid_angle_weighted_excess() {
        let cube = ProjectionKind::Cube.default_projection();
        let mut env = EnvMap::from_fn(cube, 8, 3, |_| [1.0, 2.0, 0.5, 1.0]);
        env.layers_mut()[2].set(3, 4, &[2e5, 1e5, 7e4]);
        env.layers_mut()[4].set(0, 0, &[1e6, 1.0, 1.0]);
        let r = Storage::Texels(Encoding::Rgba16F).range();
        let m = r.measure_map(&env);
        assert_eq!(m.texels, 2);
        assert_eq!(m.largest, 1e6);
        let (mut lost, mut total) = (0.0, 0.0);
        for (l, img) in env.layers().iter().enumerate() {
            for y in 0..8 {
                for x in 0..8 {
                    let w = cube.texel_solid_angle(l, x, y, 8, 8);
                    for &v in img.get(x, y) {
                        total += w * v as f64;
                        lost += w * (v as f64 - 65504.0).max(0.0);
                    }
                }
            }
        }
        let share = m.share().unwrap();
        assert!(
            (share - lost / total).abs() < 1e-9,
            "{share} {}",
            lost / total
        );
        assert_eq!(m.stops_to_fit(&r), 4);
        // Nothing past the range: no texels, and no weighting pass.
        let calm = EnvMap::from_fn(cube, 8, 3, |_| [1.0, 2.0, 0.5, 1.0]);
        let m = r.measure_map(&calm);
        assert_eq!((m.texels, m.weighted, m.share()), (0, false, None));
    }
}
