//! Where each texel of a raw output frame comes from, worked out once per run: a frame is
//! encoded straight into the output bytes from its layers, or from each output row as the
//! planned `Remap` makes it, so that no packed copy of the frame (75 MB of `f32` for a
//! 6×1024² cube) is made per frame. Strips and crosses take each row from a layer row;
//! packings whose cells are turned (EAC, v360's cells with turns) take it from the plan
//! laid out as the packed picture (`Remap::laid_out`, [`Packing::lay_out`]), so that no
//! layer is made as floats for them either.
//!
//! The positions are `Layout::pack`'s own: crosses and strips from the cell each layer
//! fills (`Layout::grid_cell`), v360's cells from the face texel each of their texels
//! shows (`CubeCells::each_texel`) and the border texels looked up in a direction; the
//! tests hold both to a probe, a map whose texels hold their own layer and position packed
//! by `pack` itself and read back.

use super::pipe::{PixFmt, SrgbTable};
use mirrorball_core::glam::DVec3;
#[cfg(test)]
use mirrorball_core::EnvMap;
use mirrorball_core::{
    sample_texels, Image, Layout, Projection, Remap, RemapRows, WorldProjection,
};
use rayon::prelude::*;
use std::collections::HashMap;

/// A piece of one packed row taken from one layer: `len` texels written from packed column
/// `at` on, read from texel `(x, y)` of `layer` on in steps of `(dx, dy)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Run {
    at: u32,
    len: u32,
    layer: u32,
    x: u32,
    y: u32,
    dx: i32,
    dy: i32,
}

impl Run {
    /// Whether the run is a piece of one layer row, in order or reversed.
    fn along_row(&self) -> bool {
        self.dy == 0 && self.dx.abs() == 1
    }
}

/// Adds packed texel `at` of a row, read from texel `(x, y)` of `layer`, to the row's runs
/// (`runs[first..]`): the last run grows where the texel continues it (the same layer, the
/// next packed texel, and one step on from its end: the second texel of a run sets the
/// step), else a run starts.
fn push_texel(runs: &mut Vec<Run>, first: usize, at: u32, layer: u32, x: u32, y: u32) {
    if let Some(run) = runs[first..].last_mut() {
        let next = run.at + run.len == at && run.layer == layer;
        let (dx, dy) = (x as i32 - run.x as i32, y as i32 - run.y as i32);
        if next && run.len == 1 && dx.abs() + dy.abs() == 1 {
            (run.dx, run.dy) = (dx, dy);
            run.len = 2;
            return;
        }
        let end = (
            run.x as i32 + run.dx * run.len as i32,
            run.y as i32 + run.dy * run.len as i32,
        );
        if next && run.len > 1 && end == (x as i32, y as i32) {
            run.len += 1;
            return;
        }
    }
    runs.push(Run {
        at,
        len: 1,
        layer,
        x,
        y,
        dx: 1,
        dy: 0,
    });
}

/// Where every texel of a packed `width`×`height` frame comes from.
#[derive(Clone, Debug)]
pub struct Packing {
    width: u32,
    height: u32,
    layer_width: u32,
    /// Per packed row, where its runs start in `runs` (`height + 1` entries).
    row_starts: Vec<u32>,
    runs: Vec<Run>,
    /// Some texels come from no layer (a cross's empty cells): they are zero, as `pack`
    /// leaves them.
    gaps: bool,
    /// Every run lies along a layer row, so rows made one at a time can be encoded.
    along_rows: bool,
    /// Packed texels looked up in a direction, not copied (EAC's border): `(index, dir)`,
    /// read from each frame's map as `Layout::pack` reads them.
    lookups: Vec<(u32, DVec3)>,
}

impl Packing {
    /// The packing of `dst`'s `w`×`h` layers by `layout` (a single layer, or `Separate`,
    /// is the layer itself); `None` if the layout does not fit `dst`. Texels the layout
    /// looks up in a direction (EAC's border: `Layout::looked_up_texels`) are kept as
    /// lookups, made from each frame's map ([`Packing::encode_map`]).
    pub fn new(layout: Layout, dst: Projection, (w, h): (u32, u32)) -> Option<Packing> {
        let n = dst.layer_count();
        if n == 1 || layout == Layout::Separate {
            return (n == 1).then(|| Packing::single(w, h));
        }
        match layout {
            Layout::Cells(cells) => Packing::of_cells(&cells, dst, (w, h)),
            _ => (layout.grid_cell(0, n).is_some()).then(|| Packing::of_grid(layout, n, (w, h))),
        }
    }

    /// The packing of v360's cells (`c3x2`, `c6x1`, `c1x6`, `eac`) from the texels each
    /// cell shows (`CubeCells::each_texel`) and the border texels looked up in a direction
    /// (`Layout::looked_up_texels`): the same runs as [`Packing::probed`] (tested), without
    /// its two copies of the frame's texels. `None` where the layout does not take the
    /// layers (not six square faces).
    fn of_cells(
        cells: &mirrorball_core::CubeCells,
        dst: Projection,
        (w, h): (u32, u32),
    ) -> Option<Packing> {
        if dst.layer_count() != 6 || w != h {
            return None;
        }
        let (pw, ph) = cells.extent(w);
        let mut rows: Vec<Vec<Run>> = vec![Vec::new(); ph as usize];
        let mut shown = 0usize;
        cells.each_texel(w, |i, px, py, fx, fy| {
            shown += 1;
            push_texel(&mut rows[py as usize], 0, px, cells.faces[i] as u32, fx, fy);
        });
        let lookups: Vec<(u32, DVec3)> = Layout::Cells(*cells)
            .looked_up_texels(&dst, w)
            .into_iter()
            .map(|(x, y, d)| (y * pw + x, d))
            .collect();
        let mut runs = Vec::new();
        let mut row_starts = Vec::with_capacity(ph as usize + 1);
        for mut row in rows {
            // Each cell's piece of the row came whole; the pieces, left to right.
            row.sort_unstable_by_key(|r| r.at);
            row_starts.push(runs.len() as u32);
            runs.append(&mut row);
        }
        row_starts.push(runs.len() as u32);
        let along_rows = lookups.is_empty() && runs.iter().all(Run::along_row);
        Some(Packing {
            width: pw,
            height: ph,
            layer_width: w,
            row_starts,
            runs,
            gaps: shown + lookups.len() < pw as usize * ph as usize,
            along_rows,
            lookups,
        })
    }

    /// This packing at `1/2^s` of its size in both directions, for a planar YUV frame's
    /// colour planes (4:2:0: `s = 1`) whose layers are made at their own size: colour texel
    /// `(x, y)` shows what luma texel `(2^s·x, 2^s·y)` shows, its layer texel's position
    /// halved `s` times, or is looked up in that texel's direction. Exact (each colour
    /// texel's layer texel covers its own block) where every cell starts at a multiple of
    /// `2^s` (v360's cells, EAC's border of two included, for faces of an even size);
    /// `None` where a size or a cell does not divide, or a colour texel would show nothing
    /// its block shows.
    pub fn halved(&self, s: u32) -> Option<Packing> {
        let step = 1u32 << s;
        let (w, h) = (self.width >> s, self.height >> s);
        if s == 0
            || !self.width.is_multiple_of(step)
            || !self.height.is_multiple_of(step)
            || !self.layer_width.is_multiple_of(step)
        {
            return None;
        }
        let mut runs = Vec::new();
        let mut row_starts = Vec::with_capacity(h as usize + 1);
        let mut shown = 0usize;
        for y in 0..h {
            row_starts.push(runs.len() as u32);
            let first = runs.len();
            let luma = self.row_starts[(y << s) as usize] as usize
                ..self.row_starts[(y << s) as usize + 1] as usize;
            for run in &self.runs[luma] {
                for k in 0..run.len {
                    let at = run.at + k;
                    if !at.is_multiple_of(step) {
                        continue;
                    }
                    let lx = run.x as i64 + run.dx as i64 * k as i64;
                    let ly = run.y as i64 + run.dy as i64 * k as i64;
                    push_texel(
                        &mut runs,
                        first,
                        at >> s,
                        run.layer,
                        (lx >> s) as u32,
                        (ly >> s) as u32,
                    );
                    shown += 1;
                }
            }
        }
        row_starts.push(runs.len() as u32);
        let lookups: Vec<(u32, DVec3)> = self
            .lookups
            .iter()
            .filter(|&&(i, _)| {
                (i % self.width).is_multiple_of(step) && (i / self.width).is_multiple_of(step)
            })
            .map(|&(i, d)| (((i / self.width) >> s) * w + ((i % self.width) >> s), d))
            .collect();
        // Every colour texel shows something where every luma texel did.
        if !self.gaps && shown + lookups.len() != w as usize * h as usize {
            return None;
        }
        let along_rows = lookups.is_empty() && runs.iter().all(Run::along_row);
        Some(Packing {
            width: w,
            height: h,
            layer_width: self.layer_width >> s,
            row_starts,
            runs,
            gaps: self.gaps,
            along_rows,
            lookups,
        })
    }

    /// The packing of a layout that puts each of `n` layers whole in a cell of its grid
    /// (`Layout::grid_cell`: crosses and strips), from the cells alone: a turned cell's
    /// rows are its layer's, last first, read backwards. The same runs as
    /// [`Packing::probed`] (tested), without its two copies of the frame's texels.
    fn of_grid(layout: Layout, n: usize, (w, h): (u32, u32)) -> Packing {
        let (gc, gr) = layout.grid(n);
        let mut by_cell = vec![None; (gc * gr) as usize];
        for i in 0..n {
            if let Some((col, row, turned)) = layout.grid_cell(i, n) {
                by_cell[(row * gc + col) as usize] = Some((i as u32, turned));
            }
        }
        let gaps = by_cell.iter().any(Option::is_none);
        let mut runs = Vec::new();
        let mut row_starts = Vec::with_capacity((gr * h) as usize + 1);
        for r in 0..gr * h {
            row_starts.push(runs.len() as u32);
            let (row, y) = (r / h, r % h);
            for col in 0..gc {
                if let Some((layer, turned)) = by_cell[(row * gc + col) as usize] {
                    runs.push(match turned {
                        false => Run {
                            at: col * w,
                            len: w,
                            layer,
                            x: 0,
                            y,
                            dx: 1,
                            dy: 0,
                        },
                        true => Run {
                            at: col * w,
                            len: w,
                            layer,
                            x: w - 1,
                            y: h - 1 - y,
                            // A one-texel run has no direction; the probe calls it +x.
                            dx: if w > 1 { -1 } else { 1 },
                            dy: 0,
                        },
                    });
                }
            }
        }
        row_starts.push(runs.len() as u32);
        Packing {
            width: gc * w,
            height: gr * h,
            layer_width: w,
            row_starts,
            runs,
            gaps,
            along_rows: true,
            lookups: Vec::new(),
        }
    }

    /// The packing of any layout `Layout::pack` knows, read off a packed probe: a map whose
    /// texels hold their own layer and position, packed once. What the tests hold
    /// [`Packing::of_grid`] and [`Packing::of_cells`] to: `pack`'s own placement.
    #[cfg(test)]
    fn probed(layout: Layout, dst: Projection, (w, h): (u32, u32)) -> Option<Packing> {
        let n = dst.layer_count();
        // Every texel says where it is: (layer + 1, x, y), exact in `f32` (sides ≤ 2^16);
        // the packed picture's zeros are cells no layer fills.
        let layers = (0..n)
            .map(|l| {
                let mut img = Image::new(w, h, 3);
                img.data_mut()
                    .par_chunks_mut(w as usize * 3)
                    .enumerate()
                    .for_each(|(y, row)| {
                        for (x, t) in row.chunks_exact_mut(3).enumerate() {
                            t.copy_from_slice(&[(l + 1) as f32, x as f32, y as f32]);
                        }
                    });
                img
            })
            .collect();
        let probe = EnvMap::new(dst, layers).ok()?;
        let pic = layout.pack(&probe)?;
        drop(probe);
        let (pw, ph) = (pic.width(), pic.height());
        let mut looked_up = vec![false; pw as usize * ph as usize];
        let lookups: Vec<(u32, DVec3)> = layout
            .looked_up_texels(&dst, w)
            .into_iter()
            .map(|(x, y, d)| {
                let i = y * pw + x;
                looked_up[i as usize] = true;
                (i, d)
            })
            .collect();
        let mut runs: Vec<Run> = Vec::new();
        let mut row_starts = Vec::with_capacity(ph as usize + 1);
        let mut gaps = false;
        for (r, row) in pic.data().chunks_exact(pw as usize * 3).enumerate() {
            row_starts.push(runs.len() as u32);
            let first = runs.len();
            for (at, t) in row.chunks_exact(3).enumerate() {
                if looked_up[r * pw as usize + at] {
                    continue;
                }
                if t[0] == 0.0 {
                    gaps = true;
                    continue;
                }
                // Every other texel is a copy of one layer texel (a blend of positions here
                // would be a layout this does not know).
                if t.iter().any(|v| v.fract() != 0.0)
                    || t[0] as usize > n
                    || t[1] >= w as f32
                    || t[2] >= h as f32
                {
                    return None;
                }
                let (layer, x, y) = (t[0] as u32 - 1, t[1] as u32, t[2] as u32);
                push_texel(&mut runs, first, at as u32, layer, x, y);
            }
        }
        row_starts.push(runs.len() as u32);
        let along_rows = lookups.is_empty() && runs.iter().all(Run::along_row);
        Some(Packing {
            width: pw,
            height: ph,
            layer_width: w,
            row_starts,
            runs,
            gaps,
            along_rows,
            lookups,
        })
    }

    /// A frame that is one `w`×`h` layer.
    pub fn single(w: u32, h: u32) -> Packing {
        let runs = (0..h)
            .map(|y| Run {
                at: 0,
                len: w,
                layer: 0,
                x: 0,
                y,
                dx: 1,
                dy: 0,
            })
            .collect();
        Packing {
            width: w,
            height: h,
            layer_width: w,
            row_starts: (0..=h).collect(),
            runs,
            gaps: false,
            along_rows: true,
            lookups: Vec::new(),
        }
    }

    /// The packed frame's width and height.
    pub fn extent(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Whether [`Packing::encode_rows`] can encode this packing (every run lies along a
    /// layer row: strips, crosses, a single layer).
    pub fn along_rows(&self) -> bool {
        self.along_rows
    }

    /// Encodes `layers` (the packing's, RGB or RGBA: alpha is dropped) as one `fmt` frame
    /// into `out`, texel for texel as `fmt` would encode `Layout::pack`'s picture.
    pub fn encode_layers(&self, fmt: impl Into<FrameCodes>, layers: &[Image], out: &mut Vec<u8>) {
        let c = layers[0].channels();
        let w = self.layer_width as usize;
        self.encode_with(fmt.into(), c, out, |run, _row, gathered, put| {
            let data = layers[run.layer as usize].data();
            if run.dx == 1 && run.dy == 0 {
                let i = (run.y as usize * w + run.x as usize) * c;
                return put(&data[i..i + run.len as usize * c]);
            }
            put(gather(run, c, gathered, |y| {
                &data[y * w * c..(y + 1) * w * c]
            }))
        });
    }

    /// Encodes `env` (the packing's projection and size) as one `fmt` frame into `out`, as
    /// `fmt` would encode `Layout::pack`'s picture: the copied texels from its layers, the
    /// looked-up ones (EAC's border) read from it in their directions. The reference
    /// [`Picture::encode_rows`] is held to.
    #[cfg(test)]
    pub fn encode_map(&self, fmt: impl Into<FrameCodes>, env: &EnvMap, out: &mut Vec<u8>) {
        let fmt = fmt.into();
        self.encode_layers(fmt, env.layers(), out);
        if self.lookups.is_empty() {
            return;
        }
        let c = env.channels();
        let values: Vec<f32> = self
            .lookups
            .par_iter()
            .flat_map_iter(|&(_, d)| {
                let v = env.sample(d);
                (0..c).map(move |k| v[k])
            })
            .collect();
        let at = self.lookups.iter().map(|&(i, _)| i);
        encode_at(fmt, (self.width, self.height), at, &values, c, out);
    }

    /// `plan` (of this packing's layers) laid out as the packed picture
    /// ([`Remap::laid_out`]), for a packing whose runs leave layer rows (turned cells), and
    /// what encodes the laid-out plan's rows: every row of the picture made and encoded by
    /// one thread as [`Packing::encode_rows`] makes a strip's, with no map of the faces
    /// made. The looked-up texels (EAC's border) read a few face texels each
    /// ([`sample_texels`] on `dst`'s faces): those are made by the laid-out plan too, in
    /// rows past the picture's, and the lookups blended from them as `Layout::pack` blends
    /// them from a map (the same bytes, tested).
    pub fn lay_out(&self, plan: &Remap, dst: &Projection) -> (Remap, Picture) {
        let (n, (pw, ph)) = (self.layer_width, (self.width, self.height));
        // The face texels the lookups read, each once, in the order first read.
        let mut ring: Vec<(usize, u32, u32)> = Vec::new();
        let mut seen: HashMap<(usize, u32, u32), u32> = HashMap::new();
        let lookups = self
            .lookups
            .iter()
            .map(|&(at, d)| {
                let mut reads = Vec::with_capacity(4);
                sample_texels::<1>(dst, (n, n), d, |l, x, y| {
                    let id = *seen.entry((l, x, y)).or_insert_with(|| {
                        ring.push((l, x, y));
                        ring.len() as u32 - 1
                    });
                    reads.push(id);
                    [0.0]
                });
                Lookup { at, d, reads }
            })
            .collect();
        let extra = (ring.len() as u32).div_ceil(pw);
        let source = |px: u32, py: u32| {
            if py >= ph {
                let i = ((py - ph) * pw + px) as usize;
                return ring.get(i).copied();
            }
            let runs = &self.runs[self.row_starts[py as usize] as usize..]
                [..(self.row_starts[py as usize + 1] - self.row_starts[py as usize]) as usize];
            let run = runs.iter().find(|r| r.at <= px && px < r.at + r.len)?;
            let k = (px - run.at) as i64;
            Some((
                run.layer as usize,
                (run.x as i64 + run.dx as i64 * k) as u32,
                (run.y as i64 + run.dy as i64 * k) as u32,
            ))
        };
        let laid = plan.laid_out((pw, ph + extra), source);
        let picture = Picture {
            rows: Packing::single(pw, ph),
            dst: *dst,
            n,
            ring,
            lookups,
        };
        (laid, picture)
    }

    /// Encodes the frame whose rows `rows` makes (a `Remap` of the packing's layers) into
    /// `out`, each row made and encoded by one thread while it is in its cache. Only for a
    /// packing [`along_rows`](Packing::along_rows).
    pub fn encode_rows(&self, fmt: impl Into<FrameCodes>, rows: &RemapRows, out: &mut Vec<u8>) {
        assert!(
            self.along_rows,
            "a packing with turned cells is encoded from layers"
        );
        let c = rows.row_len() / self.layer_width as usize;
        self.encode_with(fmt.into(), c, out, |run, row, gathered, put| {
            row.resize(rows.row_len(), 0.0);
            rows.row_into(run.layer as usize, run.y as usize, row);
            if run.dx == 1 {
                let i = run.x as usize * c;
                return put(&row[i..i + run.len as usize * c]);
            }
            let row = &row[..];
            put(gather(run, c, gathered, |_| row))
        });
    }

    /// Encodes every packed row in parallel, the texels of each run (in the run's order,
    /// `c` channels each) handed to `put` by `texels(run, scratch row, scratch run, put)`.
    fn encode_with<F>(&self, fmt: FrameCodes, c: usize, out: &mut Vec<u8>, texels: F)
    where
        F: Fn(&Run, &mut Vec<f32>, &mut Vec<f32>, &mut dyn FnMut(&[f32])) + Sync,
    {
        let (w, h) = (self.width as usize, self.height as usize);
        let px = fmt.pixel_bytes();
        out.resize(w * h * px, 0);
        let table = fmt.table();
        let runs_of =
            |r: usize| &self.runs[self.row_starts[r] as usize..self.row_starts[r + 1] as usize];
        let init = || (Vec::new(), Vec::new());
        match fmt {
            FrameCodes::Pix(PixFmt::Gbrpf32le) => {
                let (g, rest) = out.split_at_mut(w * h * 4);
                let (b, r) = rest.split_at_mut(w * h * 4);
                g.par_chunks_mut(w * 4)
                    .zip(b.par_chunks_mut(w * 4))
                    .zip(r.par_chunks_mut(w * 4))
                    .enumerate()
                    .for_each_init(init, |(row, gathered), (y, ((g, b), r))| {
                        if self.gaps {
                            for p in [&mut *g, &mut *b, &mut *r] {
                                p.fill(0);
                            }
                        }
                        for run in runs_of(y) {
                            let span = run.at as usize * 4..(run.at + run.len) as usize * 4;
                            texels(run, row, gathered, &mut |s| {
                                for (plane, k) in
                                    [&mut *g, &mut *b, &mut *r].into_iter().zip(PixFmt::PLANES)
                                {
                                    for (d, s) in plane[span.clone()]
                                        .chunks_exact_mut(4)
                                        .zip(s.chunks_exact(c))
                                    {
                                        d.copy_from_slice(&s[k].to_le_bytes());
                                    }
                                }
                            });
                        }
                    });
            }
            _ => out.par_chunks_mut(w * px).enumerate().for_each_init(
                init,
                |(row, gathered), (y, bytes)| {
                    if self.gaps {
                        bytes.fill(0);
                    }
                    for run in runs_of(y) {
                        let d = &mut bytes[run.at as usize * px..(run.at + run.len) as usize * px];
                        texels(run, row, gathered, &mut |s| fmt.encode(table, s, c, d));
                    }
                },
            ),
        }
    }
}

/// A looked-up texel of a packed frame: its index in the frame, its direction, and the
/// [`Picture`]'s ring texels it reads, in the order [`sample_texels`] reads them.
#[derive(Clone, Debug)]
struct Lookup {
    at: u32,
    d: DVec3,
    reads: Vec<u32>,
}

/// A packed frame made a row at a time by a plan laid out as its picture
/// ([`Packing::lay_out`]): v360's turned cells (EAC) encoded as a strip's rows are, with
/// no map of the faces made.
#[derive(Clone, Debug)]
pub struct Picture {
    /// The picture's rows as one layer (texels no face shows are zero, until looked up).
    rows: Packing,
    /// The faces' projection and edge, which the lookups are made in.
    dst: Projection,
    n: u32,
    /// The face texels the lookups read, made by the laid-out plan in the rows past the
    /// picture's, in order.
    ring: Vec<(usize, u32, u32)>,
    lookups: Vec<Lookup>,
}

impl Picture {
    /// Encodes the frame whose rows `rows` (of the laid-out plan) makes into `out`: the
    /// picture's rows as they are made, then the looked-up texels from the ring's.
    pub fn encode_rows(&self, fmt: impl Into<FrameCodes>, rows: &RemapRows, out: &mut Vec<u8>) {
        let codes = fmt.into();
        self.rows.encode_rows(codes, rows, out);
        if self.lookups.is_empty() {
            return;
        }
        let (pw, ph) = (self.rows.width as usize, self.rows.height as usize);
        let c = rows.row_len() / pw;
        let mut ring = vec![0.0f32; self.ring.len().div_ceil(pw) * pw * c];
        ring.par_chunks_mut(pw * c)
            .enumerate()
            .for_each(|(r, row)| rows.row_into(0, ph + r, row));
        let values: Vec<f32> = match c {
            1 => self.looked_up::<1>(&ring),
            3 => self.looked_up::<3>(&ring),
            _ => self.looked_up::<4>(&ring),
        };
        let at = self.lookups.iter().map(|l| l.at);
        encode_at(
            codes,
            (self.rows.width, self.rows.height),
            at,
            &values,
            c,
            out,
        );
    }

    /// Every lookup's `C` channels, blended from the ring texels' values as
    /// [`EnvMap::sample`] blends a map's.
    fn looked_up<const C: usize>(&self, ring: &[f32]) -> Vec<f32> {
        self.lookups
            .par_iter()
            .flat_map_iter(|l| {
                let mut k = 0;
                let v = sample_texels::<C>(&self.dst, (self.n, self.n), l.d, |layer, x, y| {
                    let id = l.reads[k] as usize;
                    k += 1;
                    assert_eq!(self.ring[id], (layer, x, y), "a lookup reads what it read");
                    ring[id * C..][..C].try_into().expect("C channels")
                });
                v.into_iter()
            })
            .collect()
    }
}

/// Writes `values` (`c` channels each) into the texels `at` of a `w`×`h` `fmt` frame.
fn encode_at(
    fmt: FrameCodes,
    (w, h): (u32, u32),
    at: impl Iterator<Item = u32>,
    values: &[f32],
    c: usize,
    out: &mut [u8],
) {
    let (n, px, table) = (w as usize * h as usize, fmt.pixel_bytes(), fmt.table());
    for (i, v) in at.zip(values.chunks_exact(c)) {
        let i = i as usize;
        match fmt {
            FrameCodes::Pix(PixFmt::Gbrpf32le) => {
                for (plane, k) in PixFmt::PLANES.into_iter().enumerate() {
                    let at = (plane * n + i) * 4;
                    out[at..at + 4].copy_from_slice(&v[k].to_le_bytes());
                }
            }
            _ => fmt.encode(table, v, c, &mut out[i * px..(i + 1) * px]),
        }
    }
}

/// The texels of `run` in its order, copied into `into` from the layer rows `row(y)` gives.
fn gather<'s, 'r>(
    run: &Run,
    c: usize,
    into: &'s mut Vec<f32>,
    row: impl Fn(usize) -> &'r [f32],
) -> &'s [f32] {
    match c {
        1 => gather_c::<1, _>(run, into, row),
        3 => gather_c::<3, _>(run, into, row),
        _ => gather_c::<4, _>(run, into, row),
    }
}

/// [`gather`] for `C` channels, each texel copied as one fixed-size piece.
#[inline(always)]
fn gather_c<'s, 'r, const C: usize, R: Fn(usize) -> &'r [f32]>(
    run: &Run,
    into: &'s mut Vec<f32>,
    row: R,
) -> &'s [f32] {
    let n = run.len as usize;
    if run.dy == 0 && run.dx == -1 && n <= run.x as usize + 1 {
        // A row piece reversed (a mirrored cell): one slice, its texels in reverse order.
        let src = &row(run.y as usize)[(run.x as usize + 1 - n) * C..(run.x as usize + 1) * C];
        into.clear();
        if C == 1 {
            into.extend(src.iter().rev());
        } else {
            for t in src.chunks_exact(C).rev() {
                into.extend_from_slice(t);
            }
        }
        return into;
    }
    into.resize(n * C, 0.0);
    for (k, t) in into.chunks_exact_mut(C).enumerate() {
        let x = (run.x as i64 + run.dx as i64 * k as i64) as usize;
        let y = (run.y as i64 + run.dy as i64 * k as i64) as usize;
        let src: &[f32; C] = row(y)[x * C..(x + 1) * C].try_into().expect("C floats");
        let dst: &mut [f32; C] = t.try_into().expect("C floats");
        *dst = *src;
    }
    into
}

/// What a packed frame's texels are written as: a pipe's pixel format, or one plane of a
/// planar YUV frame ([`PlaneCodes`]).
#[derive(Clone, Copy, Debug)]
pub enum FrameCodes {
    /// RGB texels in a pipe's pixel format.
    Pix(PixFmt),
    /// One channel: a plane's codes.
    Plane(PlaneCodes),
}

impl From<PixFmt> for FrameCodes {
    fn from(f: PixFmt) -> FrameCodes {
        FrameCodes::Pix(f)
    }
}

impl From<PlaneCodes> for FrameCodes {
    fn from(p: PlaneCodes) -> FrameCodes {
        FrameCodes::Plane(p)
    }
}

impl FrameCodes {
    fn pixel_bytes(self) -> usize {
        match self {
            FrameCodes::Pix(f) => f.pixel_bytes(),
            FrameCodes::Plane(p) => p.bytes,
        }
    }

    /// The sRGB code table of an integer pixel format, looked up once per frame.
    fn table(self) -> Option<&'static SrgbTable> {
        match self {
            FrameCodes::Pix(f) => f.table(),
            FrameCodes::Plane(_) => None,
        }
    }

    /// Texels of `c` channels (one for a plane) into their bytes, `table` being
    /// [`FrameCodes::table`].
    #[inline]
    fn encode(self, table: Option<&SrgbTable>, src: &[f32], c: usize, dst: &mut [u8]) {
        match self {
            FrameCodes::Pix(f) => f.encode_texels(table, src, c, dst),
            FrameCodes::Plane(p) => p.encode(src, dst),
        }
    }
}

/// One plane of a planar YUV frame as codes: each value is the code less the plane's
/// `neutral` (so that a texel nothing is read into, zero, is black luma or grey chroma);
/// written back as `value + neutral` rounded to the nearest code, clamped to `[0, max]`, in
/// one byte or two (little-endian).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneCodes {
    /// Bytes a code: 1 or 2.
    pub bytes: usize,
    /// The code of zero: 0 for luma, the middle code for chroma.
    pub neutral: f32,
    /// The largest code (255, 1023, 4095, 65535).
    pub max: f32,
}

impl PlaneCodes {
    /// The code of one value (NaN: 0).
    #[inline(always)]
    pub fn code(&self, v: f32) -> u16 {
        // `max` takes the other operand of a NaN, so NaN becomes 0. Non-negative after the
        // clamp, so adding ½ and truncating rounds half up, as `round` does for
        // non-negative values, without a libm call.
        let x = (v + self.neutral).max(0.0).min(self.max) + 0.5;
        // SAFETY: `x` is finite and in [0.5, 65535.5], so it fits an i32.
        (unsafe { x.to_int_unchecked::<i32>() }) as u16
    }

    /// Values into codes (eight at a time where the compiler vectorises the loop).
    pub fn encode(&self, src: &[f32], dst: &mut [u8]) {
        if self.bytes == 1 {
            for (d, &v) in dst.iter_mut().zip(src) {
                *d = self.code(v) as u8;
            }
        } else {
            for (d, &v) in dst.chunks_exact_mut(2).zip(src) {
                d.copy_from_slice(&self.code(v).to_le_bytes());
            }
        }
    }
}

impl PixFmt {
    /// The sRGB code table of an integer format.
    fn table(self) -> Option<&'static SrgbTable> {
        match self {
            PixFmt::Rgb24 => Some(SrgbTable::get(255.0)),
            PixFmt::Rgb48le => Some(SrgbTable::get(65535.0)),
            PixFmt::Rgbf32le | PixFmt::Gbrpf32le => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::{ProjectionKind, Remap};

    /// Layers of `dst` with distinct texels, partly outside `[0, 1]` and NaN.
    fn layers(dst: Projection, w: u32, h: u32) -> Vec<Image> {
        (0..dst.layer_count())
            .map(|l| {
                let mut img = Image::new(w, h, 3);
                for (i, v) in img.data_mut().iter_mut().enumerate() {
                    *v = match (i * 7 + l * 13) % 97 {
                        0 => f32::NAN,
                        1 => -0.5,
                        k => k as f32 / 80.0,
                    };
                }
                img
            })
            .collect()
    }

    /// A plane's codes: the neutral value added back, rounded to nearest, clamped; NaN
    /// and the infinities land on the range's ends, never wrap.
    #[test]
    fn plane_codes_round_and_clamp() {
        let chroma = PlaneCodes {
            bytes: 1,
            neutral: 128.0,
            max: 255.0,
        };
        let cases = [
            (0.0, 128),
            (-0.49, 128),
            (0.5, 129),
            (-128.6, 0),
            (126.6, 255),
            (1e30, 255),
            (f32::INFINITY, 255),
            (f32::NEG_INFINITY, 0),
            (f32::NAN, 0),
        ];
        for (v, want) in cases {
            assert_eq!(chroma.code(v), want, "{v}");
        }
        let ten = PlaneCodes {
            bytes: 2,
            neutral: 64.0,
            max: 1023.0,
        };
        let mut out = [0u8; 6];
        ten.encode(&[0.0, 958.6, 5000.0], &mut out);
        assert_eq!(out, [64, 0, 0xff, 0x03, 0xff, 0x03]);
        // Each value against `round` over a sweep (the vectorised loop and the plain one).
        let values: Vec<f32> = (0..4000).map(|i| i as f32 * 0.0731 - 140.0).collect();
        let mut bytes = vec![0u8; values.len()];
        chroma.encode(&values, &mut bytes);
        for (v, b) in values.iter().zip(&bytes) {
            assert_eq!(*b as f32, (v + 128.0).round().clamp(0.0, 255.0), "{v}");
        }
    }

    /// Two packings place every texel alike.
    fn assert_same(a: &Packing, b: &Packing, what: &str) {
        let shape = |p: &Packing| (p.width, p.height, p.layer_width, p.gaps, p.along_rows);
        assert_eq!(shape(a), shape(b), "{what}");
        assert_eq!(a.row_starts, b.row_starts, "{what}");
        assert_eq!(a.runs, b.runs, "{what}");
        assert_eq!(a.lookups, b.lookups, "{what}");
    }

    /// v360's cells (every face order and turn string the tests of `layout.rs` use, and EAC's
    /// padded cells), packed from the texels each cell shows, are what the probe reads off
    /// `pack`, lookups included.
    #[test]
    fn a_cells_packing_is_the_probed_packing() {
        let cube = ProjectionKind::Cube.default_projection();
        let eac = ProjectionKind::Eac.default_projection();
        for (name, dst) in [
            ("c3x2", cube),
            ("c6x1", cube),
            ("c1x6", cube),
            ("eac", eac),
            ("eac", cube),
            ("c3x2:forder=fbrlud:frot=123012", cube),
            ("c6x1:forder=udfblr:frot=000123", cube),
        ] {
            let layout: Layout = name.parse().unwrap();
            assert!(matches!(layout, Layout::Cells(_)), "{name}");
            for n in [1, 2, 3, 6] {
                let (a, b) = (
                    Packing::new(layout, dst, (n, n)).unwrap(),
                    Packing::probed(layout, dst, (n, n)).unwrap(),
                );
                assert_same(&a, &b, &format!("{name} of {dst:?} at {n}"));
            }
        }
    }

    /// Crosses and strips, packed from their cells, are what the probe reads off `pack`.
    #[test]
    fn a_grid_packing_is_the_probed_packing() {
        for kind in [ProjectionKind::Cube, ProjectionKind::Paraboloid] {
            let dst = kind.default_projection();
            for layout in [
                Layout::HorizontalCross,
                Layout::VerticalCross,
                Layout::HorizontalStrip,
                Layout::VerticalStrip,
            ] {
                for (w, h) in [(1, 1), (2, 2), (5, 5), (7, 3)] {
                    let probed = Packing::probed(layout, dst, (w, h));
                    if !layout.fits(dst.layer_count()) {
                        assert!(probed.is_none() && Packing::new(layout, dst, (w, h)).is_none());
                        continue;
                    }
                    let (a, b) = (Packing::new(layout, dst, (w, h)).unwrap(), probed.unwrap());
                    assert_same(&a, &b, &format!("{kind:?} {layout} {w}x{h}"));
                    assert!(a.lookups.is_empty());
                }
            }
        }
    }

    #[test]
    fn the_packed_bytes_are_the_packed_picture_encoded() {
        let cube = ProjectionKind::Cube.default_projection();
        let (w, h) = (5, 5);
        let env = EnvMap::new(cube, layers(cube, w, h)).unwrap();
        for layout in [
            Layout::HorizontalCross,
            Layout::VerticalCross,
            Layout::HorizontalStrip,
            Layout::VerticalStrip,
        ] {
            let pic = layout.pack(&env).unwrap();
            let p = Packing::new(layout, cube, (w, h)).unwrap();
            assert_eq!(p.extent(), (pic.width(), pic.height()), "{layout}");
            assert!(p.along_rows(), "{layout}");
            for fmt in [
                PixFmt::Rgb24,
                PixFmt::Rgb48le,
                PixFmt::Rgbf32le,
                PixFmt::Gbrpf32le,
            ] {
                let (mut want, mut got) = (Vec::new(), vec![7u8; 3]);
                fmt.encode(&pic, &mut want);
                p.encode_layers(fmt, env.layers(), &mut got);
                assert!(want == got, "{layout} {fmt}: bytes differ");
                // Rows made by a Remap and encoded as they are made: the same bytes as
                // the Remap's layers encoded.
                let ll = ProjectionKind::LatLong.default_projection();
                let plan = Remap::with_extent(ll, (16, 8), 1, cube, (w, h), &Default::default());
                let src = EnvMap::from_fn(ll, 16, 3, |d| [d.x as f32 + 0.5, d.y as f32, 0.3, 1.0]);
                let made = plan.apply(&src).unwrap();
                let (mut want, mut got) = (Vec::new(), Vec::new());
                p.encode_layers(fmt, made.layers(), &mut want);
                p.encode_rows(fmt, &plan.rows(&src).unwrap(), &mut got);
                assert!(want == got, "{layout} {fmt}: rows differ");
            }
        }
        // One layer: the layer itself; a cube without a packed layout does not fit.
        let ll = ProjectionKind::LatLong.default_projection();
        assert_eq!(
            Packing::new(Layout::Separate, ll, (8, 4)).unwrap().extent(),
            (8, 4)
        );
        assert!(Packing::new(Layout::Separate, cube, (8, 8)).is_none());
        // EAC's border texels are looked up, not copied: read from the map in their
        // directions, the same bytes as `pack`'s picture encoded.
        let eac = ProjectionKind::Eac.default_projection();
        let layout = Layout::default_for(ProjectionKind::Eac);
        let env = EnvMap::new(eac, layers(eac, 16, 16)).unwrap();
        let p = Packing::new(layout, eac, (16, 16)).unwrap();
        assert!(!p.along_rows() && !p.lookups.is_empty());
        let pic = layout.pack(&env).unwrap();
        for fmt in [
            PixFmt::Rgb24,
            PixFmt::Rgb48le,
            PixFmt::Rgbf32le,
            PixFmt::Gbrpf32le,
        ] {
            let (mut want, mut got) = (Vec::new(), Vec::new());
            fmt.encode(&pic, &mut want);
            p.encode_map(fmt, &env, &mut got);
            assert!(want == got, "eac {fmt}: bytes differ");
        }
    }

    /// A packing with turned cells, made by the plan laid out as its picture, is the
    /// plan's map packed and encoded (the looked-up border included): the same bytes, in
    /// every format, for v360's cells with turns and EAC's padded ones, faces of 1 to 16
    /// texels some of them integrated, from a float source and from codes.
    #[test]
    fn a_laid_out_picture_is_the_packed_map_encoded() {
        use mirrorball_core::Codes;
        let ll = ProjectionKind::LatLong.default_projection();
        let cube = ProjectionKind::Cube.default_projection();
        let eac = ProjectionKind::Eac.default_projection();
        let (sw, sh) = (128u32, 64u32);
        let bytes: Vec<u8> = (0..sw * sh * 3).map(|i| (i * 29 % 253) as u8).collect();
        let codes = Codes::u8(&bytes, mirrorball_io::srgb8_to_linear(), (sw, sh)).unwrap();
        let src = EnvMap::new(ll, vec![codes.to_image()]).unwrap();
        for (name, dst) in [
            ("eac", eac),
            ("eac", cube),
            ("c3x2:forder=fbrlud:frot=123012", cube),
            ("c6x1:forder=udfblr:frot=000123", cube),
            ("hstrip", cube),
        ] {
            let layout: Layout = name.parse().unwrap();
            for n in [1, 2, 3, 8, 16] {
                let what = format!("{name} of {dst:?} at {n}");
                let plan = Remap::with_extent(ll, (sw, sh), 1, dst, (n, n), &Default::default());
                let made = plan.apply(&src).unwrap();
                let p = Packing::new(layout, dst, (n, n)).unwrap();
                let (laid, pic) = p.lay_out(&plan, &dst);
                assert_eq!(laid.picture().unwrap().0, p.width, "{what}");
                for fmt in [
                    PixFmt::Rgb24,
                    PixFmt::Rgb48le,
                    PixFmt::Rgbf32le,
                    PixFmt::Gbrpf32le,
                ] {
                    let mut want = Vec::new();
                    p.encode_map(fmt, &made, &mut want);
                    for rows in [laid.rows(&src).unwrap(), laid.rows_coded(codes).unwrap()] {
                        let mut got = vec![9u8; 5];
                        pic.encode_rows(fmt, &rows, &mut got);
                        assert!(want == got, "{what} {fmt}: bytes differ");
                    }
                }
            }
        }
    }
}
