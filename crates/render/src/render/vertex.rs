//! Mode 2, per-vertex reflection vectors: each vertex's reflected eye vector, interpolated
//! across the triangle (perspective-correct) and normalised per sample, or in the fast loop
//! interpolated as it is ([`crate::mirror`]).

use glam::Vec3;
use rayon::prelude::*;

/// Each vertex's mirror direction `v − 2(n·v)n` of its unit eye vector `v` (from `eye`, or
/// `forward` for an orthographic camera: `eye` `None`) and unit normal `n`.
pub(super) fn reflections(
    pos: &[Vec3],
    nrm: &[Vec3],
    eye: Option<Vec3>,
    forward: Vec3,
) -> Vec<Vec3> {
    pos.par_iter()
        .zip(nrm.par_iter())
        .map(|(&q, &n)| {
            let v = match eye {
                Some(eye) => (q - eye).normalize_or_zero(),
                None => forward,
            };
            v - 2.0 * n.dot(v) * n
        })
        .collect()
}
