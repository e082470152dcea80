//! A blend of the parts of a map that see the same directions (a dual fisheye's overlap),
//! worked out once for a map's size and applied to every map of that size.
//!
//! Each texel in the overlap becomes `own · itself + (1 − own) · Σ wₖ · tₖ`, where the
//! `tₖ` are the four texels of the other part's bilinear lookup at the texel's direction
//! (the lookup every conversion makes, seams included) and `own` the projection's weight
//! of the texel's own part there. The projection decides the weights and the lookups
//! ([`WorldProjection::overlap_blend`](super::WorldProjection::overlap_blend)); applying
//! them is a copy of the map and one weighted sum per overlap texel, so a frame of video
//! costs no direction, no trigonometry and no branch on the lenses.

use crate::Image;
use rayon::prelude::*;

/// One texel of the overlap: where it is in its row, its own weight, and the other part's
/// bilinear lookup as four texel indices (into the layer, row-major) and their weights.
#[derive(Clone, Copy, Debug)]
struct Mixed {
    x: u32,
    own: f32,
    taps: [u32; 4],
    weights: [f32; 4],
}

/// A planned overlap blend of one-layer maps of one size (see the module docs).
#[derive(Clone, Debug)]
pub struct OverlapBlend {
    extent: (u32, u32),
    /// Where each row's texels start in `mixed` (`height + 1` entries).
    rows: Vec<u32>,
    mixed: Vec<Mixed>,
}

impl OverlapBlend {
    /// The blend of a `w`×`h` layer from each texel's mix: `mix(x, y)` gives the texel's own
    /// weight and the other part's lookup `[(texel index, weight); 4]`, or `None` where the
    /// texel stays as it is (one part alone sees it). Rows are worked out in parallel.
    pub(crate) fn from_fn<F>((w, h): (u32, u32), mix: F) -> OverlapBlend
    where
        F: Fn(u32, u32) -> Option<(f32, [(u32, f32); 4])> + Sync,
    {
        let per_row: Vec<Vec<Mixed>> = (0..h)
            .into_par_iter()
            .map(|y| {
                (0..w)
                    .filter_map(|x| {
                        let (own, look) = mix(x, y)?;
                        Some(Mixed {
                            x,
                            own,
                            taps: look.map(|(i, _)| i),
                            weights: look.map(|(_, wt)| wt),
                        })
                    })
                    .collect()
            })
            .collect();
        let mut rows = Vec::with_capacity(h as usize + 1);
        let mut mixed = Vec::with_capacity(per_row.iter().map(Vec::len).sum());
        rows.push(0);
        for r in per_row {
            mixed.extend(r);
            rows.push(mixed.len() as u32);
        }
        OverlapBlend {
            extent: (w, h),
            rows,
            mixed,
        }
    }

    /// The layer size the blend was planned for.
    pub fn extent(&self) -> (u32, u32) {
        self.extent
    }

    /// How many texels the blend mixes.
    pub fn len(&self) -> usize {
        self.mixed.len()
    }

    /// Whether the blend mixes no texel.
    pub fn is_empty(&self) -> bool {
        self.mixed.is_empty()
    }

    /// Bytes the plan occupies.
    pub fn memory_bytes(&self) -> usize {
        self.mixed.len() * std::mem::size_of::<Mixed>() + self.rows.len() * 4
    }

    /// `src` blended into `out`, reusing `out`'s memory where it already has `src`'s shape.
    ///
    /// # Panics
    /// If `src` is not the size the blend was planned for.
    pub fn apply_into(&self, src: &Image, out: &mut Image) {
        let (w, h, c) = (src.width(), src.height(), src.channels());
        assert_eq!(
            (w, h),
            self.extent,
            "an overlap blend applied to another size"
        );
        if (out.width(), out.height(), out.channels()) != (w, h, c) {
            *out = Image::new(w, h, c);
        }
        let s = src.data();
        let stride = w as usize * c;
        out.data_mut()
            .par_chunks_mut(stride)
            .enumerate()
            .for_each(|(y, row)| {
                row.copy_from_slice(&s[y * stride..][..stride]);
                let run = &self.mixed[self.rows[y] as usize..self.rows[y + 1] as usize];
                match c {
                    1 => mix_row::<1>(run, s, row),
                    3 => mix_row::<3>(run, s, row),
                    _ => mix_row::<4>(run, s, row),
                }
            });
    }

    /// `src` blended, in a new image.
    pub fn apply(&self, src: &Image) -> Image {
        let mut out = Image::new(0, 0, src.channels());
        self.apply_into(src, &mut out);
        out
    }
}

#[inline(always)]
fn mix_row<const C: usize>(run: &[Mixed], src: &[f32], row: &mut [f32]) {
    for m in run {
        let mut other = [0.0f32; C];
        for (&t, &wt) in m.taps.iter().zip(&m.weights) {
            let texel = &src[t as usize * C..][..C];
            for (o, v) in other.iter_mut().zip(texel) {
                *o += wt * v;
            }
        }
        let at = &mut row[m.x as usize * C..][..C];
        for (a, o) in at.iter_mut().zip(other) {
            *a = m.own * *a + (1.0 - m.own) * o;
        }
    }
}
