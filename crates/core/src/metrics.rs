//! Comparing environment maps: error metrics suited to high dynamic range.

use crate::projection::WorldProjection;
use crate::EnvMap;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Log-domain PSNR of `test` against `reference` (same projection and size), in dB.
///
/// Each colour value `x` is taken to `ln(1 + max(x, 0))`, which compresses highlights so a
/// sun does not drown everything else, and the squared errors are averaged with each texel
/// weighted by its exact solid angle, so every direction counts equally whatever the
/// projection. The peak is the reference's largest log value.
/// `PSNR = 10 log₁₀(peak² / MSE)`. Returns `None` if the maps differ in shape.
pub fn log_psnr(reference: &EnvMap, test: &EnvMap) -> Option<f64> {
    log_psnr_where(reference, test, |_| true)
}

/// [`log_psnr`] over the texels whose centre direction satisfies `keep` (for example, the
/// directions an intermediate projection covers, when judging a round trip through a
/// fisheye or a Mercator map that leaves the rest black).
pub fn log_psnr_where<F>(reference: &EnvMap, test: &EnvMap, keep: F) -> Option<f64>
where
    F: Fn(DVec3) -> bool + Sync,
{
    if reference.projection().kind() != test.projection().kind()
        || reference.width() != test.width()
        || reference.height() != test.height()
        || reference.layers().len() != test.layers().len()
    {
        return None;
    }
    let (w, h) = (reference.width(), reference.height());
    let p = *reference.projection();
    let lg = |x: f32| (x.max(0.0) as f64).ln_1p();
    let (mut se, mut wsum, mut peak) = (0.0f64, 0.0f64, 0.0f64);
    for layer in 0..reference.layers().len() {
        let (a, b) = (&reference.layers()[layer], &test.layers()[layer]);
        let rows = (0..h).into_par_iter().map(|y| {
            let (mut s, mut ws, mut pk) = (0.0f64, 0.0f64, 0.0f64);
            for x in 0..w {
                let wt = p.texel_solid_angle(layer, x, y, w, h);
                if wt <= 0.0 {
                    continue;
                }
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                if !p
                    .uv_to_dir(layer, p.nearest_covered(layer, uv))
                    .is_some_and(&keep)
                {
                    continue;
                }
                let (pa, pb) = (a.get(x, y), b.get(x, y));
                for c in 0..3 {
                    let (la, lb) = (lg(pa[c]), lg(pb[c]));
                    if !la.is_finite() || !lb.is_finite() {
                        continue;
                    }
                    s += wt * (la - lb) * (la - lb);
                    pk = pk.max(la);
                }
                ws += 3.0 * wt;
            }
            (s, ws, pk)
        });
        let (s, ws, pk) = crate::par::fold_in_order(rows, (0.0, 0.0, 0.0), |a, b| {
            (a.0 + b.0, a.1 + b.1, a.2.max(b.2))
        });
        se += s;
        wsum += ws;
        peak = peak.max(pk);
    }
    let mse = se / wsum.max(f64::MIN_POSITIVE);
    if mse == 0.0 {
        return Some(f64::INFINITY);
    }
    Some(10.0 * (peak * peak / mse).log10())
}
