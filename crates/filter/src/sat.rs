//! Summed-area tables (Crow 1984): the mean over any axis-aligned box of texels in constant
//! time.
//!
//! Each layer keeps `S(x, y) = Σ_{x' < x, y' < y} (L Ω, Ω)` in `f64`, so a box's
//! solid-angle-weighted mean radiance is `ΣLΩ / ΣΩ` from four lookups per table — on a
//! cube map that is the mean over the piece of the sphere the box covers, not the mean of
//! texel values (which would over-weight the small corner texels).
//!
//! A box reaching past the edge of its layer is split: the part inside, and the parts
//! beyond each edge, whose corner texels are sent through
//! [`WorldProjection::wrap_texel`] to the neighbouring face (or around the longitude
//! wrap, or over a pole), where they span another axis-aligned box. The parts beyond a
//! cube *corner* (outside two edges at once) are left out, as there is no face there.

use mirrorball_core::{EnvMap, WorldProjection};
use rayon::prelude::*;

/// Summed-area tables of every layer of a map.
pub struct SummedAreaTable {
    w: u32,
    h: u32,
    /// Per layer, `(w + 1) × (h + 1)` entries of `[ΣLΩ (RGB), ΣΩ]`.
    tables: Vec<Vec<[f64; 4]>>,
    proj: mirrorball_core::Projection,
}

impl SummedAreaTable {
    /// Builds the tables (exact texel solid angles as weights).
    pub fn new(env: &EnvMap) -> SummedAreaTable {
        let (w, h) = (env.width(), env.height());
        let proj = *env.projection();
        let omega = crate::mip::texel_solid_angles(&proj, w, h);
        let c = env.channels();
        let tables = env
            .layers()
            .par_iter()
            .enumerate()
            .map(|(layer, img)| {
                let om = &omega[layer.min(omega.len() - 1)];
                let (wu, hu) = (w as usize, h as usize);
                let mut t = vec![[0.0f64; 4]; (wu + 1) * (hu + 1)];
                for y in 0..hu {
                    let mut row = [0.0f64; 4];
                    let data = img.row(y as u32);
                    for x in 0..wu {
                        let o = om[y * wu + x];
                        let p = &data[x * c..x * c + 3];
                        row[0] += p[0] as f64 * o;
                        row[1] += p[1] as f64 * o;
                        row[2] += p[2] as f64 * o;
                        row[3] += o;
                        let above = t[y * (wu + 1) + x + 1];
                        t[(y + 1) * (wu + 1) + x + 1] = [
                            above[0] + row[0],
                            above[1] + row[1],
                            above[2] + row[2],
                            above[3] + row[3],
                        ];
                    }
                }
                t
            })
            .collect();
        SummedAreaTable { w, h, tables, proj }
    }

    /// `[ΣLΩ (RGB), ΣΩ]` over texels `x0..x1 × y0..y1` of `layer` (clipped to the layer).
    pub fn box_sum(&self, layer: usize, x0: i64, y0: i64, x1: i64, y1: i64) -> [f64; 4] {
        let (w, h) = (self.w as i64, self.h as i64);
        let (x0, x1) = (x0.clamp(0, w), x1.clamp(0, w));
        let (y0, y1) = (y0.clamp(0, h), y1.clamp(0, h));
        if x1 <= x0 || y1 <= y0 {
            return [0.0; 4];
        }
        let t = &self.tables[layer];
        let s = (w + 1) as usize;
        let at = |x: i64, y: i64| t[y as usize * s + x as usize];
        let (a, b, c, d) = (at(x1, y1), at(x0, y1), at(x1, y0), at(x0, y0));
        std::array::from_fn(|k| a[k] - b[k] - c[k] + d[k])
    }

    /// The solid-angle-weighted mean radiance (RGB) over texels `x0..x1 × y0..y1` of
    /// `layer` (`x1`, `y1` exclusive; any of them may lie outside the layer, see the
    /// module docs). `None` if the box covers no solid angle.
    pub fn box_mean(&self, layer: usize, x0: i64, y0: i64, x1: i64, y1: i64) -> Option<[f64; 3]> {
        let (w, h) = (self.w as i64, self.h as i64);
        let mut acc = self.box_sum(layer, x0, y0, x1, y1);
        // The eight regions around the layer: columns (<0, inside, ≥w) × rows (…).
        let cols = [(x0, x1.min(0)), (x0.max(0), x1.min(w)), (x0.max(w), x1)];
        let rows = [(y0, y1.min(0)), (y0.max(0), y1.min(h)), (y0.max(h), y1)];
        for (ci, &(cx0, cx1)) in cols.iter().enumerate() {
            for (ri, &(ry0, ry1)) in rows.iter().enumerate() {
                if (ci == 1 && ri == 1) || cx1 <= cx0 || ry1 <= ry0 {
                    continue;
                }
                let (la, ax, ay) = self.proj.wrap_texel(layer, cx0, ry0, self.w, self.h);
                let (lb, bx, by) = self
                    .proj
                    .wrap_texel(layer, cx1 - 1, ry1 - 1, self.w, self.h);
                if la != lb || (ci != 1 && ri != 1 && la != layer && self.proj.layer_count() > 1) {
                    // Beyond a cube corner, or mapped onto two layers: no single box.
                    continue;
                }
                let (mx0, mx1) = (ax.min(bx) as i64, ax.max(bx) as i64 + 1);
                let (my0, my1) = (ay.min(by) as i64, ay.max(by) as i64 + 1);
                // Neighbours map grid to grid (perhaps turned a quarter): the image has the
                // region's area. Anything else wrapped around (e.g. across the longitude
                // seam after crossing a pole): leave it out rather than take its complement.
                let area = (cx1 - cx0) * (ry1 - ry0);
                if (mx1 - mx0) * (my1 - my0) > 2 * area + 2 {
                    continue;
                }
                let s = self.box_sum(la, mx0, my0, mx1, my1);
                for k in 0..4 {
                    acc[k] += s[k];
                }
            }
        }
        (acc[3] > 0.0).then(|| [acc[0] / acc[3], acc[1] / acc[3], acc[2] / acc[3]])
    }
}
