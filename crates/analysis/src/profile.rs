//! Zimmons' one-dimensional measure: the angle one pixel step subtends, pixel by pixel, from
//! the centre of a layer to its edge (his figures 13, 30 and 48).
//!
//! Zimmons takes a 512-pixel map and walks from its centre outwards one pixel at a time,
//! measuring the angle between the directions at the two ends of each pixel: along a face
//! axis and along the diagonal (where a step is one pixel in each direction, `√2` pixels
//! long). We do the same for any projection: the points are `uv_k = (½, ½) + k·(sx/w, sy/h)`
//! on the layer that looks along the view axis (−Z: the cube's −Z face, the paraboloid's
//! front half; layer 0 otherwise), their directions come from the projection's `uv_to_dir`,
//! and the angle is `atan2(|a × b|, a·b)`. Where the layer's centre is not inside its domain
//! by a pixel (the dual fisheye, whose lenses touch there), the walks start at the point
//! that looks along the view axis instead (the front lens's centre) ([`walk_start`]).
//!
//! Where the domain ends between two boundaries (a disk map's rim, crossed on the diagonal)
//! the last step is cut at the rim, and reported as partial.
//!
//! Closed forms, for checking (`n` the layer width, `k` the pixel index from the centre,
//! `t_k = 2k/n`): cube `atan t_{k+1} − atan t_k` along an axis; sphere map
//! `2 asin t_{k+1} − 2 asin t_k` (the rim `t = 1` is the single direction straight ahead, so
//! the last pixel spans `2 acos(1 − 2/n) ≈ 4/√n` radians — Zimmons' "singularity"); paraboloid
//! half `2 atan t_{k+1} − 2 atan t_k`.

use crate::geom::angle_between;
use crate::texels::{boundary_radius, VIEW};
use glam::{DVec2, DVec3};
use mirrorball_core::{Projection, WorldProjection};
use serde::Serialize;

/// One walk from the centre outwards.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Walk {
    /// `horizontal` (towards +u), `vertical` (towards the top, −v) or `diagonal` (both).
    pub name: String,
    /// Angle subtended by pixel `k` (from the centre), degrees.
    pub degrees: Vec<f64>,
    /// The last step is cut at the rim: its length as a fraction of a full step (1 if not).
    pub last_fraction: f64,
    /// First pixel's angle.
    pub first: f64,
    /// Last full pixel's angle.
    pub last: f64,
    /// Smallest angle over full pixels.
    pub min: f64,
    /// Largest angle over full pixels.
    pub max: f64,
    /// `max / min` over full pixels: Zimmons' distortion ratio.
    pub ratio: f64,
}

/// The three walks on one projection.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Profile {
    /// Projection name.
    pub projection: String,
    /// The edge size.
    pub size: u32,
    /// The layer walked.
    pub layer: usize,
    /// Layer width.
    pub width: u32,
    /// Layer height.
    pub height: u32,
    /// Along the horizontal axis, the vertical axis and the diagonal.
    pub walks: Vec<Walk>,
}

/// The layer that looks along the view axis (where `dir_to_uv(−Z)` lands), else 0.
pub fn view_layer<P: WorldProjection + ?Sized>(p: &P) -> usize {
    p.dir_to_uv(VIEW).map_or(0, |(l, _)| l)
}

/// Walks from `(½, ½)` in steps of `step` (in `uv`) until the domain or the layer ends.
pub fn walk<P: WorldProjection + ?Sized>(p: &P, layer: usize, step: DVec2, name: &str) -> Walk {
    walk_from(p, layer, DVec2::splat(0.5), step, name)
}

/// Where the walks of `layer` start: the layer's centre `(½, ½)`, or, where a pixel's step
/// from it in some walk's direction leaves the domain (the dual fisheye's centre, where its
/// two lenses touch), the point that looks along the view axis (the front lens's centre).
pub fn walk_start<P: WorldProjection + ?Sized>(p: &P, layer: usize, steps: &[DVec2]) -> DVec2 {
    let c = DVec2::splat(0.5);
    let inside = |uv: DVec2| {
        (0.0..=1.0).contains(&uv.x)
            && (0.0..=1.0).contains(&uv.y)
            && p.uv_to_dir(layer, uv).is_some()
    };
    if inside(c) && steps.iter().all(|&s| inside(c + s)) {
        return c;
    }
    match p.dir_to_uv(VIEW) {
        Some((l, uv)) if l == layer => uv,
        _ => c,
    }
}

/// [`walk`] from `start` (the centre of the layer's domain): the rim, where the last step
/// is cut, found along the walk's own ray.
pub fn walk_from<P: WorldProjection + ?Sized>(
    p: &P,
    layer: usize,
    start: DVec2,
    step: DVec2,
    name: &str,
) -> Walk {
    let c = start;
    let centred = c == DVec2::splat(0.5);
    let inside = |uv: DVec2| {
        (0.0..=1.0).contains(&uv.x)
            && (0.0..=1.0).contains(&uv.y)
            && p.uv_to_dir(layer, uv).is_some()
    };
    let dir = |uv: DVec2| p.uv_to_dir(layer, uv).expect("inside");
    let mut degrees = Vec::new();
    let mut last_fraction = 1.0;
    let mut k = 0u32;
    let mut prev: DVec3 = dir(c);
    loop {
        let next = c + step * (k + 1) as f64;
        // Stop when the next boundary is (numerically) off the layer.
        if inside(next) {
            let d = dir(next);
            degrees.push(angle_between(prev, d).to_degrees());
            prev = d;
            k += 1;
            continue;
        }
        // Cut the last step at the domain's boundary, if any of it is inside.
        let along = step.normalize();
        let angle = along.y.atan2(along.x);
        let rb = if centred {
            boundary_radius(p, layer, angle)
        } else {
            rim_along(&inside, c, along, (step * (k + 1) as f64).length())
        };
        let r_here = (step * k as f64).length();
        let frac = (rb - r_here) / step.length();
        if frac > 1e-9 {
            let end = c + along * rb;
            if let Some(d) = p.uv_to_dir(layer, end) {
                degrees.push(angle_between(prev, d).to_degrees());
                last_fraction = frac.min(1.0);
            }
        }
        break;
    }
    let full = if last_fraction < 1.0 {
        &degrees[..degrees.len().saturating_sub(1)]
    } else {
        &degrees[..]
    };
    let min = full.iter().copied().fold(f64::INFINITY, f64::min);
    let max = full.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Walk {
        name: name.to_string(),
        first: full.first().copied().unwrap_or(f64::NAN),
        last: full.last().copied().unwrap_or(f64::NAN),
        min,
        max,
        ratio: max / min,
        degrees,
        last_fraction,
    }
}

/// The distance from `c` along the unit vector `along` to the rim of the domain
/// (`inside`), known to be crossed before `beyond`: by bisection.
fn rim_along(inside: &impl Fn(DVec2) -> bool, c: DVec2, along: DVec2, beyond: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, beyond);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if inside(c + along * mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Zimmons' measure on `p` at edge `size`: horizontal, vertical and diagonal walks.
///
/// ```
/// use mirrorball_analysis::profile::profile;
/// use mirrorball_core::ProjectionKind;
/// // On a cube face a texel at the centre subtends twice the angle of one at the edge
/// // (d atan x / dx = 1/(1 + x²)), three times along the diagonal (1/(1 + 2)).
/// let p = profile(&ProjectionKind::Cube.default_projection(), 256);
/// let ratio = |name: &str| p.walks.iter().find(|w| w.name == name).unwrap().ratio;
/// assert!((ratio("horizontal") - 2.0).abs() < 0.02);
/// assert!((ratio("diagonal") - 3.0).abs() < 0.03);
/// ```
pub fn profile(p: &Projection, size: u32) -> Profile {
    let (w, h) = p.layer_extent(size);
    let layer = view_layer(p);
    let (sx, sy) = (1.0 / w as f64, 1.0 / h as f64);
    let steps = [
        ("horizontal", DVec2::new(sx, 0.0)),
        ("vertical", DVec2::new(0.0, -sy)),
        ("diagonal", DVec2::new(sx, -sy)),
    ];
    let start = walk_start(p, layer, &steps.map(|s| s.1));
    let walks = steps
        .iter()
        .map(|&(name, step)| walk_from(p, layer, start, step, name))
        .collect();
    Profile {
        projection: p.name().to_string(),
        size,
        layer,
        width: w,
        height: h,
        walks,
    }
}
