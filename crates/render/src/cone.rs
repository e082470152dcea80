//! Mode 4, Greene's reflection cones (Greene 1986, §5–6): the rays through a pixel's four
//! corners, reflected off the surface, bound a region of the world projection; that region
//! is filtered rather than point-sampled, so a highly curved surface (where a pixel's
//! reflected rays fan out over much of the sphere) does not alias. The background is filtered
//! the same way over the pixel's primary-ray footprint.
//!
//! **Filter used here (a stand-in until `crates/filter` lands with EWA and SAT filters):**
//! an anisotropic trilinear filter over a box-filtered mip pyramid of the map, built for
//! every layer and sampled seamlessly through [`EnvMap::sample`]. For corner directions
//! `c₀…c₃` (in pixel order `(−,−) (+,−) (+,+) (−,+)`), the footprint's two extents are the
//! angles `α_u = max(∠c₀c₁, ∠c₃c₂)` and `α_v = max(∠c₀c₃, ∠c₁c₂)`. With the minor extent
//! `α_min` and the angular size of a level-0 texel there, `δ = √(density(d)/(w·h))` (the
//! projection's exact area element turns texel area in `uv` into solid angle), the level is
//! `L = log₂(α_min/δ)`, and `⌈α_u/α_min⌉ × ⌈α_v/α_min⌉` (at most 8 along an axis) trilinear
//! lookups are spread over the bilinear patch of the four corner directions and averaged —
//! the way GPU anisotropic filtering spends probes along the major axis.

use glam::DVec3;
use mirrorball_core::{EnvMap, Image, WorldProjection};

/// A box-filtered mip pyramid of an environment map: level 0 is the map, each next level
/// halves every layer's width and height (at least 1 texel).
#[derive(Clone, Debug)]
pub struct Pyramid {
    /// The levels, finest first.
    pub levels: Vec<EnvMap>,
}

/// Halves an image with a 2×2 box (odd edges: the last row/column is repeated).
fn halve(img: &Image) -> Image {
    let (w, h, c) = (img.width(), img.height(), img.channels());
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let mut out = Image::new(nw, nh, c);
    for y in 0..nh {
        for x in 0..nw {
            let mut acc = [0.0f32; 4];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let t = img.get((2 * x + dx).min(w - 1), (2 * y + dy).min(h - 1));
                for k in 0..c {
                    acc[k] += t[k] * 0.25;
                }
            }
            out.set(x, y, &acc[..c]);
        }
    }
    out
}

impl Pyramid {
    /// Builds the pyramid down to a 1-texel level.
    pub fn new(map: &EnvMap) -> Pyramid {
        let mut levels = vec![map.clone()];
        loop {
            let last = levels.last().expect("one level");
            if last.width() <= 1 && last.height() <= 1 {
                break;
            }
            let layers: Vec<Image> = last.layers().iter().map(halve).collect();
            match EnvMap::new(*map.projection(), layers) {
                Ok(m) => levels.push(m),
                Err(_) => break,
            }
        }
        Pyramid { levels }
    }

    /// Trilinear lookup in direction `d` at fractional level `level`.
    pub fn trilinear(&self, d: DVec3, level: f64) -> [f32; 3] {
        let max = (self.levels.len() - 1) as f64;
        let l = level.clamp(0.0, max);
        let l0 = l.floor() as usize;
        let f = (l - l0 as f64) as f32;
        let a = self.levels[l0].sample(d);
        if f <= 0.0 || l0 + 1 >= self.levels.len() {
            return [a[0], a[1], a[2]];
        }
        let b = self.levels[l0 + 1].sample(d);
        [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * f)
    }

    /// The angular size of a level-0 texel at direction `d`.
    fn texel_angle(&self, d: DVec3) -> f64 {
        let m = &self.levels[0];
        let dens = m.projection().density_of_dir(d);
        (dens / (m.width() as f64 * m.height() as f64)).sqrt()
    }

    /// Filters over the cone bounded by unit corner directions `c` (pixel order
    /// `(−,−) (+,−) (+,+) (−,+)`) around the central direction `d`.
    pub fn cone(&self, d: DVec3, c: &[DVec3; 4]) -> [f32; 3] {
        if c.iter().any(|x| !x.is_finite() || x.length_squared() < 0.5) {
            return self.trilinear(d, 0.0);
        }
        let ang = |a: DVec3, b: DVec3| a.angle_between(b);
        let au = ang(c[0], c[1]).max(ang(c[3], c[2]));
        let av = ang(c[0], c[3]).max(ang(c[1], c[2]));
        let minor = au.min(av).max(1e-9);
        let delta = self.texel_angle(d).max(1e-12);
        let level = (minor / delta).log2();
        let ku = ((au / minor).ceil() as usize).clamp(1, 8);
        let kv = ((av / minor).ceil() as usize).clamp(1, 8);
        let mut acc = [0.0f32; 3];
        for j in 0..kv {
            let t = (j as f64 + 0.5) / kv as f64;
            for i in 0..ku {
                let s = (i as f64 + 0.5) / ku as f64;
                let p =
                    (c[0] * (1.0 - s) + c[1] * s) * (1.0 - t) + (c[3] * (1.0 - s) + c[2] * s) * t;
                let p = p.try_normalize().unwrap_or(d);
                let v = self.trilinear(p, level);
                for k in 0..3 {
                    acc[k] += v[k];
                }
            }
        }
        let n = (ku * kv) as f32;
        acc.map(|x| x / n)
    }
}
