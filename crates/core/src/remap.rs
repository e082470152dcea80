//! A conversion planned once and applied to many maps: [`Remap`].
//!
//! [`resample`](crate::resample()) works out every output texel's directions, footprint and
//! filter as it goes. When the same conversion runs again and again (the frames of a video,
//! a folder of maps of one size, an engine's loader), that work is the same each time:
//! [`Remap::new`] does it once and keeps, for each output texel, what it reads. This is what
//! `cv2.remap` and ffmpeg's `v360` filter do with their precomputed coordinate maps, with
//! two differences: the plan also holds the antialiasing (the integration points of texels
//! whose footprint covers many source texels, as solid-angle-weighted taps), and lookups
//! across cube edges, the longitude wrap and the poles are resolved when planning, so
//! applying the plan never branches on a seam.
//!
//! The plan is exactly [`resample`](crate::resample())'s filter, with bilinear fractions
//! kept to 1/65536 of a texel (cv2's fixed-point maps keep 1/32): applied results agree
//! with `resample` to about 1e-5 relative (tested).
//!
//! Memory: 8 bytes per output texel, plus 16 bytes per tap of the few texels that are
//! integrated or straddle a seam (a 6×1024² cube from a 4096×2048 lat-long: about 60 MB).

use crate::codes::{CodeKind, CodeWidth, Float, Narrow, Wide};
use crate::envmap::{bilinear_blend, bilinear_mix, lerp4, seam_taps};
use crate::projection::{Projection, WorldProjection};
use crate::resample::{Job, PointScratch, Pyramid, PyramidPlan, PyramidSpare, RowScratch};
use crate::{Codes, EnvMap, Image, Plane, ResampleOptions};
use mirrorball_simd::{prefetch, CodePairs, F32x4, Pairs};
use rayon::prelude::*;
use std::fmt;
use std::sync::Mutex;

/// The source texel index's bits; the layer sits above them.
const INDEX_BITS: u32 = 29;
const INDEX_MASK: u32 = (1 << INDEX_BITS) - 1;
/// A texel read only through taps (or not at all).
const NO_TEXEL: u32 = u32::MAX;
/// Most layers a source has (a cube's six).
const MAX_LAYERS: usize = 8;

/// One output texel's bilinear lookup: the top-left source texel (layer above
/// `INDEX_BITS`, texel index below) and the fractions towards `+x` and `+y` in 1/65536.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Texel {
    idx: u32,
    fx: u16,
    fy: u16,
}

const EMPTY: Texel = Texel {
    idx: NO_TEXEL,
    fx: 0,
    fy: 0,
};

/// The taps of output texel `x` of a row: `count` weighted source texels of mip `level`.
#[derive(Clone, Copy, Debug)]
struct Group {
    x: u32,
    level: u16,
    count: u16,
}

/// One weighted source texel (layer above `INDEX_BITS`, texel index below).
#[derive(Clone, Copy, Debug)]
struct Tap {
    idx: u32,
    w: f32,
}

/// Why a [`Remap`] cannot be applied to a map: the map is not the shape the plan was made
/// for (the caller's mistake).
#[derive(Clone, Debug, PartialEq)]
pub enum RemapError {
    /// The source's projection differs from the plan's.
    Projection {
        /// What the plan was made for.
        expected: Box<Projection>,
        /// What it was given.
        found: Box<Projection>,
    },
    /// The source's layers are not the size the plan was made for.
    Extent {
        /// `(layers, width, height)` the plan was made for.
        expected: (usize, u32, u32),
        /// `(layers, width, height)` it was given.
        found: (usize, u32, u32),
    },
    /// The output map given to [`Remap::apply_into`] is not the plan's output shape, or its
    /// channel count differs from the source's, or the plan makes a laid-out picture
    /// ([`Remap::laid_out`]), not a map.
    Output,
    /// [`Remap::rows_coded`] was given codes for a plan whose source is not one layer read
    /// as it is (see [`Remap::takes_codes`]).
    Codes,
}

impl fmt::Display for RemapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RemapError::Projection { expected, found } => write!(
                f,
                "the plan converts from {:?}, the map given is {:?}",
                expected, found
            ),
            RemapError::Extent { expected, found } => write!(
                f,
                "the plan converts {}×{}×{} texels, the map given has {}×{}×{}",
                expected.0, expected.1, expected.2, found.0, found.1, found.2
            ),
            RemapError::Output => f.write_str(
                "the output map is not the plan's output projection and size, or its channel \
                 count differs from the source's, or the plan makes a laid-out picture",
            ),
            RemapError::Codes => f.write_str(
                "the plan's source is not one layer read as it is, so it cannot be read as codes",
            ),
        }
    }
}

impl std::error::Error for RemapError {}

/// A conversion from one projection and size to another, planned once and applied to many
/// maps, as `cv2.remap` applies precomputed coordinate maps. For each output texel the plan
/// keeps what it reads: one bilinear lookup, or the solid-angle-weighted taps of a texel
/// that is integrated or straddles a seam, so that applying it never works out a direction
/// or branches on a seam. It is exactly [`resample`](crate::resample())'s filter, with
/// bilinear fractions kept to 1/65536 of a texel: results agree with `resample` to about
/// 1e-5 relative (tested). Memory: 8 bytes per output texel plus 16 per tap (a 6×1024² cube
/// from a 4096×2048 lat-long: about 60 MB).
///
/// ```
/// use mirrorball_core::{EnvMap, ProjectionKind, Remap, ResampleOptions, resample};
/// let latlong = ProjectionKind::LatLong.default_projection();
/// let cube = ProjectionKind::Cube.default_projection();
/// let plan = Remap::new(latlong, (64, 32), 1, cube, 16, &ResampleOptions::default());
/// let src = EnvMap::from_fn(latlong, 64, 3, |d| [d.y as f32 + 1.0, 1.0, 1.0, 1.0]);
/// let fast = plan.apply(&src).unwrap();
/// let slow = resample(&src, cube, 16, &ResampleOptions::default());
/// for (a, b) in fast.layers()[2].data().iter().zip(slow.layers()[2].data()) {
///     assert!((a - b).abs() < 1e-4);
/// }
/// ```
pub struct Remap {
    job: Job,
    src_extent: (u32, u32),
    src_layers: usize,
    /// Per output layer, one entry per texel, row by row.
    texels: Vec<Vec<Texel>>,
    /// Per output layer, the texels read through taps, row by row.
    groups: Vec<Vec<Group>>,
    /// Per output layer, the taps of the groups, in order.
    taps: Vec<Vec<Tap>>,
    /// Per output layer, where each row's groups and taps start (`h + 1` pairs).
    row_starts: Vec<Vec<(u32, u32)>>,
    /// The source's mip levels' block weights, as deep as the taps read.
    pyramid: PyramidPlan,
    /// `Some((width, height))` where the output is one picture laid out from another
    /// plan's layers ([`Remap::laid_out`]), not the projection's layers.
    picture: Option<(u32, u32)>,
    /// The last applied source's mip levels (and blended base), kept to be filled again by
    /// the next.
    spare: Mutex<PyramidSpare>,
}

impl fmt::Debug for Remap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Remap")
            .field("from", &self.job.sproj)
            .field("src_extent", &self.src_extent)
            .field("to", &self.job.dst)
            .field("extent", &(self.job.w, self.job.h))
            .field("picture", &self.picture)
            .field("taps", &self.tap_count())
            .finish()
    }
}

impl Remap {
    /// Plans the conversion of `src_layers` layers of `src_extent` (width, height) texels in
    /// `src` to `dst` at edge `size` (see [`WorldProjection::layer_extent`]), with the
    /// rotation, exposure and antialiasing of `opts`.
    pub fn new(
        src: Projection,
        src_extent: (u32, u32),
        src_layers: usize,
        dst: Projection,
        size: u32,
        opts: &ResampleOptions,
    ) -> Remap {
        let extent = dst.layer_extent(size.max(1));
        Remap::with_extent(src, src_extent, src_layers, dst, extent, opts)
    }

    /// [`Remap::new`] with the output's layer width and height given.
    pub fn with_extent(
        src: Projection,
        src_extent: (u32, u32),
        src_layers: usize,
        dst: Projection,
        (w, h): (u32, u32),
        opts: &ResampleOptions,
    ) -> Remap {
        let (sw, sh) = (src_extent.0.max(1), src_extent.1.max(1));
        let job = Job::new(src, (sw, sh), dst, (w.max(1), h.max(1)), opts);
        let n = dst.layer_count();
        let (mut texels, mut groups, mut taps, mut row_starts) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for layer in 0..n {
            // Each row's lookups are planned in place; its taps, few, are gathered after.
            let mut t = vec![EMPTY; job.w as usize * job.h as usize];
            let rows: Vec<PlannedRow> = t
                .par_chunks_mut(job.w as usize)
                .enumerate()
                .map_init(
                    || (RowScratch::new(job.w as usize), PointScratch::new()),
                    |(s, ps), (y, texels)| plan_row(&job, (sw, sh), s, ps, layer, y, texels),
                )
                .collect();
            let (g, k, starts) = PlannedRow::join(rows);
            texels.push(t);
            groups.push(g);
            taps.push(k);
            row_starts.push(starts);
        }
        let depth = groups.iter().flatten().map(|g| g.level as usize).max();
        let pyramid = PyramidPlan::new(&job.sproj, (sw, sh), src_layers, depth.unwrap_or(0));
        Remap {
            job,
            src_extent: (sw, sh),
            src_layers,
            texels,
            groups,
            taps,
            row_starts,
            pyramid,
            picture: None,
            spare: Mutex::new(PyramidSpare::default()),
        }
    }

    /// The plan's output texels laid out as one `width`×`height` picture: texel `(px, py)`
    /// of the new plan's one output is texel `(x, y)` of layer `layer` of this plan's,
    /// where `source(px, py)` is `Some((layer, x, y))`, read through the same lookup and
    /// taps (so the same bits, tested), and zero where it is `None` or names a texel the
    /// output does not have. For a caller that writes a packed picture of the output (a
    /// cube's faces in v360's cells, some of them turned) a row at a time, as an encoder
    /// takes it, without making the output's layers: the new plan's rows come from
    /// [`RemapRows::row_into`] of layer 0. It converts the same source as this one but has
    /// no map to fill: [`Remap::apply`], [`Remap::apply_into`] and [`RemapRows::fill`]
    /// refuse it ([`RemapError::Output`]).
    ///
    /// ```
    /// use mirrorball_core::{EnvMap, ProjectionKind, Remap, ResampleOptions};
    /// let (ll, cube) = (ProjectionKind::LatLong.default_projection(), ProjectionKind::Cube.default_projection());
    /// let plan = Remap::new(ll, (64, 32), 1, cube, 8, &ResampleOptions::default());
    /// // Face 2 turned a quarter: picture row y is face column 7 - y, top to bottom.
    /// let turned = plan.laid_out((8, 8), |px, py| Some((2, 7 - py, px)));
    /// let src = EnvMap::from_fn(ll, 64, 3, |d| [d.x as f32, d.y as f32, d.z as f32, 1.0]);
    /// let faces = plan.apply(&src).unwrap();
    /// let rows = turned.rows(&src).unwrap();
    /// let mut row = vec![0.0; rows.row_len()];
    /// rows.row_into(0, 3, &mut row);
    /// for px in 0..8 {
    ///     assert_eq!(row[px as usize * 3..][..3], *faces.layers()[2].get(4, px));
    /// }
    /// ```
    pub fn laid_out(
        &self,
        (width, height): (u32, u32),
        source: impl Fn(u32, u32) -> Option<(usize, u32, u32)> + Sync,
    ) -> Remap {
        let (w, h) = self.out_extent();
        let (w, h) = (w as usize, h as usize);
        // Each group's first tap, per layer (a row's groups are in order of `x`).
        let first_tap: Vec<Vec<u32>> = (0..self.texels.len())
            .map(|l| {
                let mut k = 0u32;
                let firsts = self.groups[l].iter().map(|g| {
                    k += g.count as u32;
                    k - g.count as u32
                });
                firsts.collect()
            })
            .collect();
        let (pw, ph) = (width.max(1) as usize, height.max(1) as usize);
        let mut t = vec![EMPTY; pw * ph];
        // Texels ahead of the current one whose entries are asked for now: a turned cell
        // reads down a column of the plan, which the hardware does not foresee.
        const AHEAD_LAID: usize = 16;
        let rows: Vec<PlannedRow> = t
            .par_chunks_mut(pw)
            .enumerate()
            .map_init(Vec::new, |sources, (py, entries)| {
                let mut row = PlannedRow {
                    groups: Vec::new(),
                    taps: Vec::new(),
                };
                sources.clear();
                sources.extend((0..pw as u32).map(|px| {
                    source(px, py as u32).filter(|&(l, x, y)| {
                        l < self.texels.len() && (x as usize) < w && (y as usize) < h
                    })
                }));
                for (px, e) in entries.iter_mut().enumerate() {
                    if let Some(&Some((l, x, y))) = sources.get(px + AHEAD_LAID) {
                        prefetch(
                            self.texels[l]
                                .as_ptr()
                                .wrapping_add(y as usize * w + x as usize),
                        );
                    }
                    let Some((l, x, y)) = sources[px] else {
                        continue;
                    };
                    let i = y as usize * w + x as usize;
                    *e = self.texels[l][i];
                    let starts = &self.row_starts[l];
                    let (g0, g1) = (
                        starts[y as usize].0 as usize,
                        starts[y as usize + 1].0 as usize,
                    );
                    let row_groups = &self.groups[l][g0..g1];
                    if let Ok(j) = row_groups.binary_search_by_key(&x, |g| g.x) {
                        let g = row_groups[j];
                        let k = first_tap[l][g0 + j] as usize;
                        row.groups.push(Group { x: px as u32, ..g });
                        row.taps
                            .extend_from_slice(&self.taps[l][k..k + g.count as usize]);
                    }
                }
                row
            })
            .collect();
        let (g, k, starts) = PlannedRow::join(rows);
        Remap {
            job: self.job.clone(),
            src_extent: self.src_extent,
            src_layers: self.src_layers,
            texels: vec![t],
            groups: vec![g],
            taps: vec![k],
            row_starts: vec![starts],
            pyramid: self.pyramid.clone(),
            picture: Some((pw as u32, ph as u32)),
            spare: Mutex::new(PyramidSpare::default()),
        }
    }

    /// The width and height of the output's rows: each layer's, or the laid-out picture's.
    fn out_extent(&self) -> (u32, u32) {
        self.picture.unwrap_or((self.job.w, self.job.h))
    }

    /// `Some((width, height))` for a plan made by [`Remap::laid_out`]: its one output
    /// picture's extent.
    pub fn picture(&self) -> Option<(u32, u32)> {
        self.picture
    }

    /// The output projection.
    pub fn projection(&self) -> &Projection {
        &self.job.dst
    }

    /// The output's layer width and height.
    pub fn extent(&self) -> (u32, u32) {
        (self.job.w, self.job.h)
    }

    /// How many weighted taps the plan holds beside its one bilinear lookup per texel
    /// (texels that are integrated or whose lookup straddles a seam).
    pub fn tap_count(&self) -> usize {
        self.taps.iter().map(Vec::len).sum()
    }

    /// Bytes the plan occupies.
    pub fn memory_bytes(&self) -> usize {
        let t: usize = self.texels.iter().map(Vec::len).sum();
        let g: usize = self.groups.iter().map(Vec::len).sum();
        let o: usize = self.row_starts.iter().map(Vec::len).sum();
        t * std::mem::size_of::<Texel>()
            + g * std::mem::size_of::<Group>()
            + self.tap_count() * std::mem::size_of::<Tap>()
            + o * 8
            + self.pyramid.memory_bytes()
    }

    fn check_source(&self, src: &EnvMap) -> Result<(), RemapError> {
        if *src.projection() != self.job.sproj {
            return Err(RemapError::Projection {
                expected: Box::new(self.job.sproj),
                found: Box::new(*src.projection()),
            });
        }
        let found = (src.layers().len(), src.width(), src.height());
        let expected = (self.src_layers, self.src_extent.0, self.src_extent.1);
        if found != expected || src.layers().len() > MAX_LAYERS {
            return Err(RemapError::Extent { expected, found });
        }
        Ok(())
    }

    /// Converts `src`, which must have the projection and size the plan was made for.
    pub fn apply(&self, src: &EnvMap) -> Result<EnvMap, RemapError> {
        let rows = self.rows(src)?;
        if self.picture.is_some() {
            return Err(RemapError::Output);
        }
        let (w, h, c) = (self.job.w, self.job.h, src.channels());
        let layers = (0..self.job.dst.layer_count())
            .map(|layer| Image::par_rows(w, h, c, |y, row| rows.row_into(layer, y, row)))
            .collect();
        EnvMap::new(self.job.dst, layers).map_err(|_| RemapError::Output)
    }

    /// Converts `src` into `out`, reusing its memory; `out` must have the plan's output
    /// projection and size and the source's channel count.
    pub fn apply_into(&self, src: &EnvMap, out: &mut EnvMap) -> Result<(), RemapError> {
        self.check_source(src)?;
        RemapRows::new(self, src).fill(out)
    }

    /// Prepares `src` (the projection and size the plan was made for) to be converted a row
    /// at a time, in any order and from any thread, into the caller's buffers: for
    /// consumers that use each output row at once (an encoder), so that the whole output
    /// map need never exist. Its mip levels, when the plan reads any, are made here.
    pub fn rows<'a>(&'a self, src: &'a EnvMap) -> Result<RemapRows<'a>, RemapError> {
        self.check_source(src)?;
        Ok(RemapRows::new(self, src))
    }

    /// Whether the plan's source can be given as [`Codes`] ([`Remap::rows_coded`]): it is
    /// one layer, and its projection reads it as it is (no overlap blended first).
    pub fn takes_codes(&self) -> bool {
        self.src_layers == 1 && !self.job.sproj.blends_overlap()
    }

    /// [`Remap::rows`] of a source held as integer codes (a raw video frame as it arrives):
    /// every row the same bits as [`Remap::rows`] of the float map the codes' table decodes
    /// them into, with no float copy of the source made (only its mip levels, where the
    /// plan reads any, are floats). The plan must [take codes](Remap::takes_codes), and the
    /// codes be the plan's source extent.
    ///
    /// ```
    /// use mirrorball_core::{Codes, EnvMap, ProjectionKind, Remap, ResampleOptions};
    /// let (ll, cube) = (ProjectionKind::LatLong.default_projection(), ProjectionKind::Cube.default_projection());
    /// let table: Vec<f32> = (0..256).map(|k| (k as f32 / 255.0).powf(2.2)).collect();
    /// let bytes: Vec<u8> = (0..64 * 32 * 3).map(|i| (i * 7 % 256) as u8).collect();
    /// let codes = Codes::u8(&bytes, &table, (64, 32)).unwrap();
    /// let plan = Remap::new(ll, (64, 32), 1, cube, 8, &ResampleOptions::default());
    /// let floats = EnvMap::new(ll, vec![codes.to_image()]).unwrap();
    /// let (a, b) = (plan.rows(&floats).unwrap(), plan.rows_coded(codes).unwrap());
    /// let (mut ra, mut rb) = (vec![0.0; a.row_len()], vec![0.0; b.row_len()]);
    /// a.row_into(2, 5, &mut ra);
    /// b.row_into(2, 5, &mut rb);
    /// assert_eq!(ra, rb); // the same bits
    /// ```
    pub fn rows_coded<'a>(&'a self, src: Codes<'a>) -> Result<RemapRows<'a>, RemapError> {
        self.check_codes(src.extent())?;
        Ok(RemapRows::coded(self, src))
    }

    /// Whether a source of codes of `extent` can be read by this plan: one that [takes
    /// codes](Remap::takes_codes), of that source extent.
    fn check_codes(&self, (w, h): (u32, u32)) -> Result<(), RemapError> {
        if !self.takes_codes() {
            return Err(RemapError::Codes);
        }
        if (w, h) != self.src_extent {
            return Err(RemapError::Extent {
                expected: (1, self.src_extent.0, self.src_extent.1),
                found: (1, w, h),
            });
        }
        Ok(())
    }

    /// [`Remap::rows`] of a one-channel source held as a plane's codes (a YUV frame's Y, U
    /// or V as it arrives): every row the same bits as [`Remap::rows`] of the one-channel
    /// float map of the plane's values ([`Plane::to_image`]), with no float copy of the
    /// plane made (only its mip levels, where the plan reads any). The plan must [take
    /// codes](Remap::takes_codes), and the plane be the plan's source extent.
    pub fn rows_plane<'a>(&'a self, src: Plane<'a>) -> Result<RemapRows<'a>, RemapError> {
        self.check_codes(src.extent())?;
        Ok(RemapRows::plane(self, src))
    }

    /// Fills output row `y` of `layer`: the bilinear pass, then the taps, then exposure.
    #[inline(always)]
    fn fill_row<const C: usize>(
        &self,
        pyr: &Pyramid,
        base: Base<'_>,
        layer: usize,
        y: usize,
        row: &mut [f32],
    ) {
        let w = self.out_extent().0 as usize;
        let sw = self.src_extent.0 as usize;
        let (groups, taps, starts) = (
            &self.groups[layer],
            &self.taps[layer],
            &self.row_starts[layer],
        );
        let entries = &self.texels[layer][y * w..(y + 1) * w];
        match base {
            Base::Floats(planes) => {
                gather_row::<C>(entries, planes, self.src_layers == 1, sw * C, row)
            }
            Base::Codes(c) => match c.kind() {
                CodeKind::Wide => {
                    gather_row_codes::<Wide>(entries, c.bytes(), Wide::table(c.table()), sw, row)
                }
                CodeKind::Narrow => gather_row_codes::<Narrow>(
                    entries,
                    c.bytes(),
                    Narrow::table(c.table()),
                    sw,
                    row,
                ),
                // The caller's floats are the float path's layer: its gather, its bits.
                CodeKind::Float => {
                    let mut planes: [&[f32]; MAX_LAYERS] = [&[]; MAX_LAYERS];
                    planes[0] = c.floats();
                    gather_row::<3>(entries, &planes, true, sw * 3, row)
                }
            },
            Base::Plane(p) if p.wide() => gather_row_plane::<2>(entries, p, sw, row),
            Base::Plane(p) => gather_row_plane::<1>(entries, p, sw, row),
        }
        let ((g0, t0), (g1, _)) = (starts[y], starts[y + 1]);
        let mut k = t0 as usize;
        for g in &groups[g0 as usize..g1 as usize] {
            let group = &taps[k..k + g.count as usize];
            k += g.count as usize;
            let Some(o) = row.get_mut(g.x as usize * C..(g.x as usize + 1) * C) else {
                continue;
            };
            match base {
                Base::Codes(c) if g.level == 0 => {
                    let n = c.extent().0 as usize * c.extent().1 as usize;
                    match c.kind() {
                        CodeKind::Wide => {
                            sum_taps_codes::<Wide>(group, c.bytes(), Wide::table(c.table()), n, o)
                        }
                        CodeKind::Narrow => sum_taps_codes::<Narrow>(
                            group,
                            c.bytes(),
                            Narrow::table(c.table()),
                            n,
                            o,
                        ),
                        CodeKind::Float => sum_taps_codes::<Float>(group, c.bytes(), (), n, o),
                    }
                }
                Base::Plane(p) if g.level == 0 => {
                    // The next groups' taps' source texels asked for now (the integrated
                    // texels' footprints wander over many source rows).
                    let ahead = taps.get(k..).unwrap_or(&[]);
                    match p.wide() {
                        true => sum_taps_plane::<2>(group, ahead, p, o),
                        false => sum_taps_plane::<1>(group, ahead, p, o),
                    }
                }
                _ => sum_taps::<C>(group, pyr.level(g.level as usize), o),
            }
        }
        let scale = self.job.scale;
        if scale != 1.0 {
            for px in row.chunks_exact_mut(C) {
                for v in &mut px[..C.min(3)] {
                    *v *= scale;
                }
            }
        }
    }
}

/// Where a [`RemapRows`]' base level is read: the source's float layers, or its codes.
#[derive(Clone, Copy)]
enum Base<'a> {
    Floats(&'a [&'a [f32]; MAX_LAYERS]),
    Codes(Codes<'a>),
    Plane(Plane<'a>),
}

/// A source made ready for a [`Remap`]: output rows made one at a time (see
/// [`Remap::rows`]), each exactly as [`Remap::apply_into`] makes it.
pub struct RemapRows<'a> {
    remap: &'a Remap,
    pyr: Pyramid<'a>,
    c: usize,
    /// The base level as codes, where [`Remap::rows_coded`] made these rows.
    codes: Option<Codes<'a>>,
    /// The base level as a plane's codes, where [`Remap::rows_plane`] made these rows.
    plane: Option<Plane<'a>>,
}

impl<'a> RemapRows<'a> {
    fn new(remap: &'a Remap, src: &'a EnvMap) -> RemapRows<'a> {
        let pyr = Pyramid::planned(src, &remap.pyramid, RemapRows::spare(remap));
        RemapRows::with(remap, pyr, src.channels(), None, None)
    }

    fn coded(remap: &'a Remap, src: Codes<'a>) -> RemapRows<'a> {
        let pyr = Pyramid::planned_codes(src, &remap.pyramid, RemapRows::spare(remap));
        RemapRows::with(remap, pyr, 3, Some(src), None)
    }

    fn plane(remap: &'a Remap, src: Plane<'a>) -> RemapRows<'a> {
        let pyr = Pyramid::planned_plane(src, &remap.pyramid, RemapRows::spare(remap));
        RemapRows::with(remap, pyr, 1, None, Some(src))
    }

    /// The mip levels the plan's last rows gave back, for this source to fill.
    fn spare(remap: &Remap) -> PyramidSpare {
        std::mem::take(&mut *remap.spare.lock().unwrap_or_else(|e| e.into_inner()))
    }

    fn with(
        remap: &'a Remap,
        pyr: Pyramid<'a>,
        c: usize,
        codes: Option<Codes<'a>>,
        plane: Option<Plane<'a>>,
    ) -> RemapRows<'a> {
        RemapRows {
            remap,
            pyr,
            c,
            codes,
            plane,
        }
    }

    /// Makes every row into `out` (in parallel), reusing its memory: `out` must have the
    /// plan's output projection and size and the source's channel count.
    pub fn fill(&self, out: &mut EnvMap) -> Result<(), RemapError> {
        let job = &self.remap.job;
        if *out.projection() != job.dst
            || (out.width(), out.height()) != (job.w, job.h)
            || self.remap.picture.is_some()
            || out.channels() != self.c
        {
            return Err(RemapError::Output);
        }
        let w = self.row_len();
        for (layer, img) in out.layers_mut().iter_mut().enumerate() {
            img.data_mut()
                .par_chunks_mut(w)
                .enumerate()
                .for_each(|(y, row)| self.row_into(layer, y, row));
        }
        Ok(())
    }

    /// Floats in one output row (width × the source's channels).
    pub fn row_len(&self) -> usize {
        self.remap.out_extent().0 as usize * self.c
    }

    /// Makes row `y` of output layer `layer` into `row` ([`RemapRows::row_len`] floats).
    ///
    /// # Panics
    /// If `layer` or `y` is outside the plan's output, or `row` is not one row long.
    pub fn row_into(&self, layer: usize, y: usize, row: &mut [f32]) {
        assert!(layer < self.remap.texels.len() && y < self.remap.out_extent().1 as usize);
        assert_eq!(row.len(), self.row_len());
        if let Some(codes) = self.codes {
            let base = Base::Codes(codes);
            return self.remap.fill_row::<3>(&self.pyr, base, layer, y, row);
        }
        if let Some(plane) = self.plane {
            let base = Base::Plane(plane);
            return self.remap.fill_row::<1>(&self.pyr, base, layer, y, row);
        }
        // The base as the pyramid holds it (a dual fisheye's overlap blended).
        let mut planes: [&[f32]; MAX_LAYERS] = [&[]; MAX_LAYERS];
        for (p, l) in planes.iter_mut().zip(self.pyr.level(0)) {
            *p = l.data();
        }
        let base = Base::Floats(&planes);
        match self.c {
            1 => self.remap.fill_row::<1>(&self.pyr, base, layer, y, row),
            3 => self.remap.fill_row::<3>(&self.pyr, base, layer, y, row),
            _ => self.remap.fill_row::<4>(&self.pyr, base, layer, y, row),
        }
    }
}

impl Drop for RemapRows<'_> {
    /// Gives the mip levels back to the plan, for the next source to fill.
    fn drop(&mut self) {
        let spare = self.pyr.take_spare();
        *self.remap.spare.lock().unwrap_or_else(|e| e.into_inner()) = spare;
    }
}

/// The bilinear pass of one output row: every texel that has a lookup gets it, every other
/// one zero (its taps, if any, are added afterwards).
#[inline(always)]
fn gather_row<const C: usize>(
    entries: &[Texel],
    planes: &[&[f32]; MAX_LAYERS],
    single: bool,
    stride: usize,
    row: &mut [f32],
) {
    if C == 1 {
        // One channel (a plane of a YUV frame): four texels at a time.
        if single {
            if let Some(p) = Pairs::new([planes[0]], stride) {
                return gather_row_one(entries, &p, planes, stride, row);
            }
        } else {
            // Every slot a layer: those past the source's layers (never named by an entry)
            // read the first.
            let all = planes.map(|p| if p.is_empty() { planes[0] } else { p });
            if let Some(p) = Pairs::new(all, stride) {
                return gather_row_one(entries, &p, planes, stride, row);
            }
        }
    }
    if single {
        gather_row_lanes::<C, true>(entries, planes, stride, row)
    } else {
        gather_row_lanes::<C, false>(entries, planes, stride, row)
    }
}

/// The bilinear pass of a one-channel source, four output texels at a time: each texel's
/// top and bottom pairs read at once ([`Pairs`]), turned into lanes and blended with
/// `lerp4`'s arithmetic lane by lane, so the same bits as [`gather_one`], which makes the
/// texels [`Pairs`] cannot read (an empty entry, a footprint past the end) and the row's
/// last few. `N`: 1 for a one-layer source (the layer bits not decoded), else
/// [`MAX_LAYERS`].
#[inline(always)]
fn gather_row_one<const N: usize>(
    entries: &[Texel],
    pairs: &Pairs<'_, N>,
    planes: &[&[f32]; MAX_LAYERS],
    stride: usize,
    row: &mut [f32],
) {
    const Q: f32 = 1.0 / 65536.0;
    let n = row.len().min(entries.len());
    let last = pairs.last();
    let layer = |idx: u32| {
        if N == 1 {
            0
        } else {
            (idx >> INDEX_BITS) as usize & (N - 1)
        }
    };
    let slices = if N == 1 {
        [planes[0]; MAX_LAYERS]
    } else {
        *planes
    };
    let blocks = n / 4 * 4;
    for x in (0..blocks).step_by(4) {
        // The source texels of the entries a few ahead, asked for now (see
        // `gather_row_lanes`).
        if let Some(ahead) = entries.get(x + AHEAD..x + AHEAD + 4) {
            for a in ahead {
                let data = slices[layer(a.idx)];
                let i = (a.idx & INDEX_MASK) as usize;
                if i <= last {
                    let p = data.as_ptr().wrapping_add(i);
                    prefetch(p);
                    prefetch(p.wrapping_add(stride));
                }
            }
        }
        let e: &[Texel; 4] = entries[x..x + 4].try_into().expect("four entries");
        let i = e.map(|t| (t.idx & INDEX_MASK) as usize);
        let [a, b, c, d] = pairs.get(e.map(|t| layer(t.idx)), i);
        let q = F32x4::splat(Q);
        let fx = F32x4::from_array(e.map(|t| t.fx as f32)) * q;
        let fy = F32x4::from_array(e.map(|t| t.fy as f32)) * q;
        let top = a + fx * (b - a);
        let bot = c + fx * (d - c);
        (top + fy * (bot - top)).store(&mut row[x..x + 4]);
        // An empty entry's index (NO_TEXEL's, all ones) is past `last`, as is a footprint
        // that would read past the end: those lanes were read clamped and are made again.
        for (k, t) in e.iter().enumerate() {
            if i[k] > last {
                gather_one::<1>(t, planes, stride, &mut row[x + k..x + k + 1]);
            }
        }
    }
    for x in blocks..row.len() {
        match entries.get(x) {
            Some(t) => gather_one::<1>(t, planes, stride, &mut row[x..x + 1]),
            None => row[x] = 0.0,
        }
    }
}

/// One texel of the bilinear pass, in plain arithmetic (the reference for the four-lane
/// loop).
#[inline(always)]
fn gather_one<const C: usize>(
    t: &Texel,
    planes: &[&[f32]; MAX_LAYERS],
    stride: usize,
    out: &mut [f32],
) {
    const Q: f32 = 1.0 / 65536.0;
    if t.idx == NO_TEXEL {
        out.fill(0.0);
        return;
    }
    let data = planes[(t.idx >> INDEX_BITS) as usize];
    let i = (t.idx & INDEX_MASK) as usize * C;
    match (
        data.get(i..i + 2 * C),
        data.get(i + stride..i + stride + 2 * C),
    ) {
        (Some(r0), Some(r1)) => lerp4::<C>(r0, r1, t.fx as f32 * Q, t.fy as f32 * Q, out),
        _ => out.fill(0.0),
    }
}

/// Entries ahead of the current one whose source texels [`gather_row_lanes`] prefetches.
const AHEAD: usize = 24;

/// The bilinear pass four channels at a time: each texel's four source texels blended with
/// [`bilinear_blend`] (`lerp4`'s arithmetic, so the same bits). `SINGLE`: the source has
/// one layer, so the entry's layer bits are not decoded.
#[inline(always)]
fn gather_row_lanes<const C: usize, const SINGLE: bool>(
    entries: &[Texel],
    planes: &[&[f32]; MAX_LAYERS],
    stride: usize,
    row: &mut [f32],
) {
    const Q: f32 = 1.0 / 65536.0;
    let n = row.len();
    let plane = |idx: u32| {
        if SINGLE {
            planes[0]
        } else {
            planes[(idx >> INDEX_BITS) as usize & (MAX_LAYERS - 1)]
        }
    };
    for (x, t) in entries.iter().enumerate() {
        // The source texels of the entry a few ahead, asked for now (a hint: the lookups
        // of an output row wander over source rows, which the hardware does not foresee).
        if let Some(a) = entries.get(x + AHEAD) {
            let data = plane(a.idx);
            let i = (a.idx & INDEX_MASK) as usize * C;
            if a.idx != NO_TEXEL && i + stride < data.len() {
                let p = data.as_ptr().wrapping_add(i);
                prefetch(p);
                prefetch(p.wrapping_add(stride));
            }
        }
        let o = x * C;
        let data = plane(t.idx);
        let i = (t.idx & INDEX_MASK) as usize * C;
        // An empty entry (NO_TEXEL) fails this test, as do the last texels of a row or an
        // image, where a four-float read or write would pass the end.
        if t.idx == NO_TEXEL || i + stride + C + 4 > data.len() || o + 4 > n {
            gather_one::<C>(t, planes, stride, &mut row[o..o + C]);
            continue;
        }
        let (fx, fy) = (t.fx as f32 * Q, t.fy as f32 * Q);
        // Four lanes; for C = 3 the fourth lands on the next texel's first channel, which
        // that texel (or the zero of an empty one) overwrites next.
        bilinear_blend(&data[i..], stride, C, fx, fy).store(&mut row[o..]);
    }
}

/// The weighted sum of `taps` over the layers of one mip level, into `out`: four channels
/// at once wherever a four-float read fits.
#[inline(always)]
fn sum_taps<const C: usize>(taps: &[Tap], level: &[Image], out: &mut [f32]) {
    let mut acc = F32x4::splat(0.0);
    let mut tail = [0.0f32; C];
    for t in taps {
        let data = level[(t.idx >> INDEX_BITS) as usize].data();
        let i = (t.idx & INDEX_MASK) as usize * C;
        if i + 4 <= data.len() {
            acc = acc + F32x4::splat(t.w) * F32x4::load(&data[i..]);
        } else if let Some(v) = data.get(i..i + C) {
            for c in 0..C {
                tail[c] += t.w * v[c];
            }
        }
    }
    let lanes = acc.to_array();
    for c in 0..C {
        out[c] = lanes[c] + tail[c];
    }
}

/// [`gather_row_lanes`] of a one-layer source held as codes (`sw` texels a row): each
/// texel's four source texels read through the table and blended with [`bilinear_mix`],
/// so every value is the float path's to the bit (the float source being the table's
/// decoding of the codes).
#[inline(always)]
fn gather_row_codes<W: CodeWidth>(
    entries: &[Texel],
    bytes: &[u8],
    table: W::Table<'_>,
    sw: usize,
    row: &mut [f32],
) {
    const Q: f32 = 1.0 / 65536.0;
    let n = row.len();
    let texel_bytes = W::TEXEL_BYTES;
    let read = |k: usize| {
        let [r, g, b] = W::texel(bytes, table, k);
        F32x4::from_array([r, g, b, 0.0])
    };
    for (x, t) in entries.iter().enumerate() {
        if let Some(a) = entries.get(x + AHEAD) {
            let i = (a.idx & INDEX_MASK) as usize * texel_bytes;
            if a.idx != NO_TEXEL && i + sw * texel_bytes < bytes.len() {
                let p = bytes.as_ptr().wrapping_add(i);
                prefetch(p);
                prefetch(p.wrapping_add(sw * texel_bytes));
            }
        }
        let o = x * 3;
        if t.idx == NO_TEXEL {
            row[o..o + 3].fill(0.0);
            continue;
        }
        let i = (t.idx & INDEX_MASK) as usize;
        let v = bilinear_mix(
            [read(i), read(i + 1), read(i + sw), read(i + sw + 1)],
            t.fx as f32 * Q,
            t.fy as f32 * Q,
        );
        if o + 4 <= n {
            v.store(&mut row[o..]);
        } else {
            row[o..o + 3].copy_from_slice(&v.to_array()[..3]);
        }
    }
}

/// [`sum_taps`] of a one-layer source of `texels` texels held as codes: the same sums in
/// the same order (the last texel, which [`sum_taps`] cannot read four floats at, added
/// apart as there), so the same bits.
#[inline(always)]
fn sum_taps_codes<W: CodeWidth>(
    taps: &[Tap],
    bytes: &[u8],
    table: W::Table<'_>,
    texels: usize,
    out: &mut [f32],
) {
    let mut acc = F32x4::splat(0.0);
    let mut tail = [0.0f32; 3];
    for t in taps {
        let i = (t.idx & INDEX_MASK) as usize;
        let v = W::texel(bytes, table, i);
        if i * 3 + 4 <= texels * 3 {
            acc = acc + F32x4::splat(t.w) * F32x4::from_array([v[0], v[1], v[2], 0.0]);
        } else {
            for c in 0..3 {
                tail[c] += t.w * v[c];
            }
        }
    }
    let lanes = acc.to_array();
    for c in 0..3 {
        out[c] = lanes[c] + tail[c];
    }
}

/// [`gather_row_one`] of a one-layer plane held as codes of `B` bytes (`sw` texels a row):
/// each corner read as `code − offset`, as [`Plane::value`] reads it, so the same bits as
/// the float path from [`Plane::to_image`]; [`plane_one`] makes the texels the four-lane
/// reads cannot (empty entries, footprints past the end, the row's last few).
#[inline(always)]
fn gather_row_plane<const B: usize>(
    entries: &[Texel],
    plane: Plane<'_>,
    sw: usize,
    row: &mut [f32],
) {
    const Q: f32 = 1.0 / 65536.0;
    let n = row.len().min(entries.len());
    let Some(pairs) = CodePairs::<B>::new(plane.bytes(), sw) else {
        for (x, o) in row.iter_mut().enumerate() {
            *o = entries.get(x).map_or(0.0, |t| plane_one(t, plane, sw));
        }
        return;
    };
    let last = pairs.last();
    let bytes = plane.bytes();
    let off = F32x4::splat(plane.offset());
    let blocks = n / 4 * 4;
    for x in (0..blocks).step_by(4) {
        if let Some(ahead) = entries.get(x + AHEAD..x + AHEAD + 4) {
            for a in ahead {
                let i = (a.idx & INDEX_MASK) as usize;
                if i <= last {
                    let p = bytes.as_ptr().wrapping_add(i * B);
                    prefetch(p);
                    prefetch(p.wrapping_add(sw * B));
                }
            }
        }
        let e: &[Texel; 4] = entries[x..x + 4].try_into().expect("four entries");
        let i = e.map(|t| (t.idx & INDEX_MASK) as usize);
        let [a, b, c, d] = pairs.get(i).map(|v| v.to_f32() - off);
        let q = F32x4::splat(Q);
        let fx = F32x4::from_array(e.map(|t| t.fx as f32)) * q;
        let fy = F32x4::from_array(e.map(|t| t.fy as f32)) * q;
        let top = a + fx * (b - a);
        let bot = c + fx * (d - c);
        (top + fy * (bot - top)).store(&mut row[x..x + 4]);
        for (k, t) in e.iter().enumerate() {
            if i[k] > last {
                row[x + k] = plane_one(t, plane, sw);
            }
        }
    }
    for (x, o) in row.iter_mut().enumerate().skip(blocks) {
        *o = entries.get(x).map_or(0.0, |t| plane_one(t, plane, sw));
    }
}

/// [`gather_one`] of a plane's codes: one texel in plain arithmetic.
#[inline(always)]
fn plane_one(t: &Texel, plane: Plane<'_>, sw: usize) -> f32 {
    const Q: f32 = 1.0 / 65536.0;
    let i = (t.idx & INDEX_MASK) as usize;
    if t.idx == NO_TEXEL || i + sw + 2 > plane.len() {
        return 0.0;
    }
    let v = |k: usize| plane.value(k);
    let mut out = [0.0];
    let (r0, r1) = ([v(i), v(i + 1)], [v(i + sw), v(i + sw + 1)]);
    lerp4::<1>(&r0, &r1, t.fx as f32 * Q, t.fy as f32 * Q, &mut out);
    out[0]
}

/// [`sum_taps`] of a one-layer plane held as codes: the same sums in the same order (the
/// last three texels, which [`sum_taps`] cannot read four floats at, added apart as
/// there), so the same bits.
/// `ahead`: the taps after these, whose first source texels are prefetched.
#[inline(always)]
fn sum_taps_plane<const B: usize>(taps: &[Tap], ahead: &[Tap], plane: Plane<'_>, out: &mut [f32]) {
    const AHEAD_TAPS: usize = 16;
    let (mut acc, mut tail) = (0.0f32, 0.0f32);
    let bytes = plane.bytes();
    let n = bytes.len() / B;
    let off = plane.offset();
    let value = |i: usize| -> f32 {
        let code = if B == 1 {
            bytes[i] as f32
        } else {
            u16::from_le_bytes([bytes[2 * i], bytes[2 * i + 1]]) as f32
        };
        code - off
    };
    for (j, t) in taps.iter().enumerate() {
        if let Some(a) = ahead.get(j + AHEAD_TAPS) {
            prefetch(
                bytes
                    .as_ptr()
                    .wrapping_add((a.idx & INDEX_MASK) as usize * B),
            );
        }
        let i = (t.idx & INDEX_MASK) as usize;
        if i + 4 <= n {
            acc += t.w * value(i);
        } else if i < n {
            tail += t.w * value(i);
        }
    }
    out[0] = acc + tail;
}

/// One planned output row's taps (its lookups are written into the plan in place).
struct PlannedRow {
    groups: Vec<Group>,
    taps: Vec<Tap>,
}

/// A plan's groups and taps, and where each row's start (`rows + 1` pairs).
type Joined = (Vec<Group>, Vec<Tap>, Vec<(u32, u32)>);

impl PlannedRow {
    /// The rows' groups and taps one after another, each in one allocation of its final
    /// size (tens of megabytes of taps, not grown by doubling), with each row's start.
    fn join(rows: Vec<PlannedRow>) -> Joined {
        let g_len = rows.iter().map(|r| r.groups.len()).sum();
        let k_len = rows.iter().map(|r| r.taps.len()).sum();
        let (mut g, mut k) = (Vec::with_capacity(g_len), Vec::with_capacity(k_len));
        let mut starts = Vec::with_capacity(rows.len() + 1);
        starts.push((0u32, 0u32));
        for r in rows {
            g.extend_from_slice(&r.groups);
            k.extend_from_slice(&r.taps);
            starts.push((g.len() as u32, k.len() as u32));
        }
        (g, k, starts)
    }

    /// Closes the group of output texel `x` whose taps start at `start`: equal source texels
    /// merged, weights divided by `wsum`.
    fn close(&mut self, x: usize, level: usize, start: usize, wsum: f32) {
        let t = &mut self.taps[start..];
        t.sort_unstable_by_key(|t| t.idx);
        let mut n = 0;
        for i in 0..t.len() {
            if n > 0 && t[n - 1].idx == t[i].idx {
                t[n - 1].w += t[i].w;
            } else {
                t[n] = t[i];
                n += 1;
            }
        }
        for t in &mut t[..n] {
            t.w /= wsum;
        }
        self.taps.truncate(start + n);
        self.groups.push(Group {
            x: x as u32,
            level: level as u16,
            count: n as u16,
        });
    }
}

/// Plans output row `y` of `layer`.
fn plan_row(
    job: &Job,
    (sw, sh): (u32, u32),
    s: &mut RowScratch,
    ps: &mut PointScratch,
    layer: usize,
    y: usize,
    texels: &mut [Texel],
) -> PlannedRow {
    job.locate(s, layer, y);
    let mut row = PlannedRow {
        groups: Vec::new(),
        taps: Vec::new(),
    };
    for (x, (&ddens, lk)) in s.dens.iter().zip(&s.look).enumerate() {
        if ddens < 0.0 || lk.layer == u32::MAX {
            continue;
        }
        let (level, m) = match job.integration_ratio(ddens, lk) {
            Some(ratio) => job.points(ps, layer, x, y, ratio),
            None => (0, 0),
        };
        let lext = level_extent(sw, sh, level);
        let start = row.taps.len();
        let mut wsum = 0.0f32;
        for (k, sl) in ps.slook[..m].iter().enumerate() {
            if sl.layer != u32::MAX {
                push_bilinear(&job.sproj, lext, sl, ps.sw[k], &mut row.taps);
                wsum += ps.sw[k];
            }
        }
        if wsum > 0.0 {
            row.close(x, level, start, wsum);
            continue;
        }
        // One bilinear lookup at the centre: in the dense pass when its 2×2 texels lie
        // inside the layer, else as taps that cross the seam.
        row.taps.truncate(start);
        match interior(sw, sh, lk.layer, lk.u, lk.v) {
            Some(t) => texels[x] = t,
            None => {
                push_bilinear(&job.sproj, (sw, sh), lk, 1.0, &mut row.taps);
                row.close(x, 0, start, 1.0);
            }
        }
    }
    row
}

/// The extent of mip level `level` of a `w`×`h` source (halving, as the pyramid does).
fn level_extent(w: u32, h: u32, level: usize) -> (u32, u32) {
    let (mut w, mut h) = (w, h);
    for _ in 0..level {
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
    (w, h)
}

/// The lookup at `(u, v)` in a `w`×`h` layer when its 2×2 texels lie inside the layer,
/// with the same `f32` arithmetic as the conversion's bilinear filter.
#[inline]
fn interior(w: u32, h: u32, layer: u32, u: f32, v: f32) -> Option<Texel> {
    let (wi, hi) = (w as i32, h as i32);
    let (x0, y0, fx, fy) = crate::bilinear_corner(u, v, w, h);
    let fits = x0 >= 0 && y0 >= 0 && x0 + 1 < wi && y0 + 1 < hi;
    if !fits || w as u64 * h as u64 > INDEX_MASK as u64 + 1 || layer as usize >= MAX_LAYERS {
        return None;
    }
    let idx = y0 as u64 * w as u64 + x0 as u64;
    let q = |f: f32| quantize_fraction(f);
    Some(Texel {
        idx: (layer << INDEX_BITS) | idx as u32,
        fx: q(fx),
        fy: q(fy),
    })
}

/// A bilinear fraction `f` in `[0, 1)` in 1/65536 of a texel, rounded to nearest with ties
/// away from zero (as `f32::round`, which without SSE4.1 is a libm call: a tenth of the
/// planning time). `f · 65536` is exact (a power of two), and so is its difference from its
/// truncation, so the comparison with ½ decides as `round` does, to the bit (tested).
#[inline(always)]
fn quantize_fraction(f: f32) -> u16 {
    let s = f * 65536.0;
    let t = s as u32;
    let r = t + (s - t as f32 >= 0.5) as u32;
    r.min(65535) as u16
}

/// The four taps of a bilinear lookup in a `w`×`h` layer, weights scaled by `wt`. Inside
/// the layer the `f32` arithmetic of the conversion's bilinear filter; where the lookup
/// straddles a seam, each corner outside the layer is moved to where it really is (across a
/// cube edge, the longitude wrap, a pole), as the conversion's `f64` filter does.
fn push_bilinear(
    proj: &Projection,
    (w, h): (u32, u32),
    lk: &crate::projection::Lookup,
    wt: f32,
    taps: &mut Vec<Tap>,
) {
    let layer = lk.layer as usize;
    if let Some(t) = interior(w, h, lk.layer, lk.u, lk.v) {
        // Same arithmetic as the dense pass: fractions in 1/65536.
        let (fx, fy) = (t.fx as f32 / 65536.0, t.fy as f32 / 65536.0);
        let i = t.idx;
        for (idx, cw) in [
            (i, (1.0 - fx) * (1.0 - fy)),
            (i + 1, fx * (1.0 - fy)),
            (i + w, (1.0 - fx) * fy),
            (i + w + 1, fx * fy),
        ] {
            taps.push(Tap { idx, w: wt * cw });
        }
        return;
    }
    let x = lk.u as f64 * w as f64 - 0.5;
    let y = lk.v as f64 * h as f64 - 0.5;
    let (x0, y0) = (x.floor() as i64, y.floor() as i64);
    let f = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    for (l, tx, ty, cw) in seam_taps(proj, layer, (w, h), (x0, y0), f) {
        taps.push(Tap {
            idx: ((l as u32) << INDEX_BITS) | (ty * w + tx),
            w: wt * cw,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::{
        gather_one, gather_row, quantize_fraction, Texel, INDEX_BITS, MAX_LAYERS, NO_TEXEL,
    };
    use crate::{EnvMap, Image, ProjectionKind, Remap, ResampleOptions};

    /// A one-channel source (one plane of a YUV frame) is converted as the first channel of
    /// a three-channel one holding the same values, antialiasing (integrated texels, the
    /// mip levels they read) and seams included.
    #[test]
    fn one_channel_planes_convert_as_the_first_channel() {
        let (ll, cube) = (
            ProjectionKind::LatLong.default_projection(),
            ProjectionKind::Cube.default_projection(),
        );
        let (w, h) = (96u32, 48u32);
        let value = |i: usize| ((i * 37 + i / 7) % 251) as f32;
        let mut one = Image::new(w, h, 1);
        let mut three = Image::new(w, h, 3);
        for (i, v) in one.data_mut().iter_mut().enumerate() {
            *v = value(i);
        }
        for (i, t) in three.data_mut().chunks_exact_mut(3).enumerate() {
            t.copy_from_slice(&[value(i), 1.0, 2.0]);
        }
        let (one, three) = (
            EnvMap::new(ll, vec![one]).unwrap(),
            EnvMap::new(ll, vec![three]).unwrap(),
        );
        // A small cube integrates many source texels each; a large one reads bilinearly.
        for size in [5, 64] {
            let plan = Remap::new(ll, (w, h), 1, cube, size, &ResampleOptions::default());
            assert!(size > 5 || plan.tap_count() > 0, "integrated texels tested");
            let (a, b) = (plan.apply(&one).unwrap(), plan.apply(&three).unwrap());
            assert_eq!(a.channels(), 1);
            for (la, lb) in a.layers().iter().zip(b.layers()) {
                for (x, t) in la.data().iter().zip(lb.data().chunks_exact(3)) {
                    assert!(
                        (x - t[0]).abs() <= 1e-4 * t[0].abs().max(1.0),
                        "{x} {}",
                        t[0]
                    );
                }
            }
        }
    }

    /// The one-channel pass (four texels at a time) gives [`gather_one`]'s bits for every
    /// entry: empty ones, footprints at the image's last texels and past them, rows whose
    /// length is not a multiple of four, one layer and several.
    #[test]
    fn one_channel_rows_are_the_reference_bits() {
        let (sw, sh) = (37usize, 11usize);
        let mut seed = 12345u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as u32
        };
        let layers: Vec<Vec<f32>> = (0..3)
            .map(|_| {
                (0..sw * sh)
                    .map(|_| next() as f32 / 7919.0 - 1000.0)
                    .collect()
            })
            .collect();
        let len = sw * sh;
        for n_layers in [1usize, 3] {
            let mut planes: [&[f32]; MAX_LAYERS] = [&[]; MAX_LAYERS];
            for (p, l) in planes.iter_mut().zip(&layers[..n_layers]) {
                *p = l;
            }
            for w in [1usize, 3, 4, 5, 8, 31, 64] {
                let entries: Vec<Texel> = (0..w)
                    .map(|x| {
                        let r = next();
                        let idx = match r % 8 {
                            0 => NO_TEXEL,
                            // The last footprints that fit, and the first that do not.
                            1 => (len - sw - 2 + (r as usize / 8) % 3) as u32,
                            _ => (r as usize / 8 % (len - sw - 1)) as u32,
                        };
                        let layer = if idx == NO_TEXEL {
                            0
                        } else {
                            (x % n_layers) as u32
                        };
                        Texel {
                            idx: idx | layer << INDEX_BITS,
                            fx: next() as u16,
                            fy: if x % 5 == 0 { 0 } else { next() as u16 },
                        }
                    })
                    .collect();
                let mut fast = vec![f32::NAN; w];
                gather_row::<1>(&entries, &planes, n_layers == 1, sw, &mut fast);
                for (x, t) in entries.iter().enumerate() {
                    let mut want = [f32::NAN];
                    gather_one::<1>(t, &planes, sw, &mut want);
                    assert_eq!(
                        fast[x].to_bits(),
                        want[0].to_bits(),
                        "{n_layers} layers, width {w}, texel {x}: {t:?}"
                    );
                }
            }
        }
    }

    /// A plane read as codes ([`Remap::rows_plane`]) gives, row for row, the bits of the
    /// float map of its values: 8- and 16-bit codes, integrated texels and their mip
    /// levels, seams, bilinear lookups, a laid-out plan.
    #[test]
    fn planes_read_as_codes_are_the_float_planes_bits() {
        use crate::Plane;
        let (ll, cube) = (
            ProjectionKind::LatLong.default_projection(),
            ProjectionKind::Cube.default_projection(),
        );
        let (w, h) = (96u32, 48u32);
        let n = (w * h) as usize;
        let narrow: Vec<u8> = (0..n).map(|i| ((i * 37 + i / 7) % 256) as u8).collect();
        let wide: Vec<u8> = (0..n)
            .flat_map(|i| (((i * 389 + i / 5) % 1024) as u16).to_le_bytes())
            .collect();
        let planes = [
            Plane::u8(&narrow, 16.0, (w, h)).unwrap(),
            Plane::u16le(&wide, 512.0, (w, h)).unwrap(),
        ];
        for size in [5, 24, 64] {
            let plan = Remap::new(ll, (w, h), 1, cube, size, &ResampleOptions::default());
            assert!(size > 5 || plan.tap_count() > 0, "integrated texels tested");
            let turned = plan.laid_out((size * 2, size), |px, py| {
                (px < size).then_some((2, size - 1 - py, px))
            });
            for p in planes {
                let floats = EnvMap::new(ll, vec![p.to_image()]).unwrap();
                for plan in [&plan, &turned] {
                    let (a, b) = (plan.rows(&floats).unwrap(), plan.rows_plane(p).unwrap());
                    let (mut ra, mut rb) = (vec![0.0; a.row_len()], vec![0.0; b.row_len()]);
                    let (layers, rows) = match plan.picture() {
                        Some((_, ph)) => (1, ph),
                        None => (6, plan.extent().1),
                    };
                    for layer in 0..layers {
                        for y in 0..rows as usize {
                            a.row_into(layer, y, &mut ra);
                            b.row_into(layer, y, &mut rb);
                            let bits =
                                |r: &[f32]| r.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                            assert_eq!(bits(&ra), bits(&rb), "size {size}, layer {layer}, row {y}");
                        }
                    }
                }
            }
        }
        // A plane of another size is refused.
        let plan = Remap::new(ll, (w, h), 1, cube, 8, &ResampleOptions::default());
        let small = Plane::u8(&narrow[..n / 2], 0.0, (w, h / 2)).unwrap();
        assert!(plan.rows_plane(small).is_err());
        assert!(Plane::u8(&narrow[..n - 1], 0.0, (w, h)).is_err());
    }

    #[test]
    fn fractions_quantize_as_round_does() {
        let want = |f: f32| ((f * 65536.0).round() as u32).min(65535) as u16;
        // Every tie (k + ½)/65536 and its neighbours one ulp either side, the ends, and a
        // sweep of every 97th f32 in [0, 1).
        let mut values = vec![0.0f32, f32::from_bits(1.0f32.to_bits() - 1), 1e-30];
        for k in 0..65536u32 {
            let tie = (k as f32 + 0.5) / 65536.0;
            values.extend([
                tie,
                f32::from_bits(tie.to_bits() - 1),
                f32::from_bits(tie.to_bits() + 1),
            ]);
        }
        values.extend((0..1.0f32.to_bits()).step_by(97).map(f32::from_bits));
        for f in values {
            assert_eq!(quantize_fraction(f), want(f), "{f:e}");
        }
    }
}
