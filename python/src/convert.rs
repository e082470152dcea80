//! `convert` (one conversion, core's `Resampler`: the CLI's `convert` bit for bit) and the
//! `Remap` plan class (core's `Remap`: planned once for a source shape, applied to many
//! arrays or batches, into `out=`). The work runs with the GIL released, in bands of rows,
//! and Python's signal handlers run between bands (Ctrl-C stops a long call).

use crate::arrays::{self, Dtype, Invalid, OutElem, Pictures};
use crate::errors::request;
use crate::threads::run;
use mirrorball_core::projection::ProjectionSpec;
use mirrorball_core::{
    Choice, Codes, EnvMap, Image, Layout, Outside, Projection, ProjectionKind, ResampleOptions,
    Resampler, Rotation, WorldProjection,
};
use numpy::{
    PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::sync::Arc;

/// A projection argument (`src`, `dst`): the CLI's `NAME[:key=value…]` text.
pub fn spec_arg(arg: &str, text: &str) -> PyResult<ProjectionSpec> {
    ProjectionSpec::parse(text).map_err(|e| request(arg, e))
}

/// A layout argument: any name the CLI's `--layout` takes.
pub fn layout_arg(arg: &str, text: Option<&str>) -> PyResult<Option<Layout>> {
    text.map(|t| t.parse::<Layout>().map_err(|e| request(arg, e)))
        .transpose()
}

/// The rotation, exposure, antialiasing and `outside` arguments as core's options.
pub fn options(
    (yaw, pitch, roll): (f64, f64, f64),
    exposure: f32,
    max_samples: u32,
    outside: Option<&str>,
) -> PyResult<ResampleOptions> {
    let outside = outside
        .map(|o| o.parse::<Outside>().map_err(|e| request("outside", e)))
        .transpose()?;
    for (name, v) in [("yaw", yaw), ("pitch", pitch), ("roll", roll)] {
        if !v.is_finite() {
            return Err(request(
                name,
                format!("{v} is not a finite number of degrees"),
            ));
        }
    }
    if !exposure.is_finite() || exposure.abs() > 64.0 {
        return Err(request(
            "exposure",
            format!("{exposure} stops; give a finite number within ±64"),
        ));
    }
    if !(1..=16).contains(&max_samples) {
        return Err(request(
            "max_samples",
            format!("{max_samples} is outside 1..=16 (1 turns antialiasing off)"),
        ));
    }
    Ok(ResampleOptions {
        rotation: Rotation::from_euler_deg(yaw, pitch, roll),
        exposure,
        max_samples,
        outside,
        ..Default::default()
    })
}

/// What a conversion's arguments say, or what its `v360` option string says in their
/// place: the source, the output's projection, size and layout, and the options.
pub struct Asked {
    pub source: Source,
    pub dst: ProjectionSpec,
    pub size: Option<i64>,
    pub layout: Option<Layout>,
    pub opts: ResampleOptions,
}

/// The conversion arguments `convert` and `Remap` share, read as [`Asked`]. `v360`: FFmpeg
/// v360's options (`IN:OUT[:key=value…]`, the CLI's `--v360`, the library's `v360::parse`)
/// in place of `src`, `dst`, `src_layout`, `layout`, `yaw`, `pitch`, `roll` (refused beside
/// them) and of `size` when it has `w` and `h`.
#[allow(clippy::too_many_arguments)]
pub fn asked(
    v360: Option<&str>,
    (src, dst): (Option<&str>, Option<&str>),
    (size, layout, src_layout): (Option<i64>, Option<&str>, Option<&str>),
    turn: (f64, f64, f64),
    exposure: f32,
    max_samples: u32,
    outside: Option<&str>,
) -> PyResult<Asked> {
    let mut opts = options(turn, exposure, max_samples, outside)?;
    let Some(text) = v360 else {
        return Ok(Asked {
            source: Source::new(src.unwrap_or("latlong"), src_layout)?,
            dst: spec_arg("dst", dst.unwrap_or("cube"))?,
            size,
            layout: layout_arg("layout", layout)?,
            opts,
        });
    };
    let v = mirrorball::v360::parse(text).map_err(|e| request("v360", e))?;
    let given = [
        ("src", src.is_some()),
        ("dst", dst.is_some()),
        ("src_layout", src_layout.is_some()),
        ("layout", layout.is_some()),
        ("size", size.is_some() && v.size.is_some()),
        ("yaw", turn.0 != 0.0),
        ("pitch", turn.1 != 0.0),
        ("roll", turn.2 != 0.0),
    ];
    if let Some((arg, _)) = given.iter().find(|(_, g)| *g) {
        return Err(request(
            arg,
            "v360 says it too: give it in the v360 options only (or leave v360 out)",
        ));
    }
    if v.in_stereo != mirrorball_core::Stereo::Mono || v.out_stereo != mirrorball_core::Stereo::Mono
    {
        return Err(request(
            "v360",
            "in_stereo/out_stereo: stereo pictures are converted by the CLI (convert --v360); here one eye at a time",
        ));
    }
    opts.rotation = v.rotation;
    Ok(Asked {
        source: Source {
            arg: "v360",
            spec: v.from,
            layout: v.in_layout,
        },
        dst: v.to,
        size: v.size.or(size),
        layout: v.layout,
        opts,
    })
}

/// How a source picture is read: its projection text and layout.
#[derive(Clone, Debug)]
pub struct Source {
    /// The argument naming the projection (`src`, or `write`'s `projection`).
    arg: &'static str,
    spec: ProjectionSpec,
    layout: Option<Layout>,
}

impl Source {
    pub fn new(src: &str, src_layout: Option<&str>) -> PyResult<Source> {
        Source::named("src", src, src_layout)
    }

    /// [`Source::new`] with the projection's argument named `arg`.
    pub fn named(arg: &'static str, src: &str, src_layout: Option<&str>) -> PyResult<Source> {
        Ok(Source {
            arg,
            spec: spec_arg(arg, src)?,
            layout: layout_arg("src_layout", src_layout)?,
        })
    }

    /// Layers of the projection.
    pub fn layers(&self) -> usize {
        self.spec.kind.default_projection().layer_count()
    }

    /// Whether each layer comes as its own picture (a leading dimension of the array).
    pub fn separate_layers(&self) -> bool {
        self.layers() > 1 && self.layout == Some(Layout::Separate)
    }

    /// The projection and layout of a `w`×`h` picture (one layer's, for separate layers),
    /// as the CLI reads a picture with `--from` (and `--in-layout`).
    pub fn shape(&self, arg: &str, w: u32, h: u32) -> PyResult<(Projection, Layout)> {
        let n = self.layers();
        let layout = match self.layout {
            Some(l) => l,
            None => Layout::from_extent(w, h, n).map(|g| g.0).ok_or_else(|| {
                request(
                    arg,
                    format!(
                        "a {w}x{h} picture fits no layout of a {} map (six square faces: 4:3 or 3:4 cross, 6:1 or 1:6 strip, v360's 3:2 cells; two halves: 2:1 or 1:2); give src_layout=",
                        self.spec.kind
                    ),
                )
            })?,
        };
        let proj = self
            .spec
            .build(Some((w, h)))
            .map_err(|e| request(self.arg, e))?;
        if layout == Layout::Separate && n == 1 && proj.kind() != ProjectionKind::Mercator {
            let (ew, eh) = proj.layer_extent(w);
            if (h as f64 - eh as f64).abs() / eh as f64 > 0.01 {
                return Err(request(
                    arg,
                    format!(
                        "a {} map of width {w} is {ew}x{eh}, but the picture is {w}x{h} (H×W×C = {h}×{w}); say another {}",
                        proj.name(),
                        self.arg
                    ),
                ));
            }
        }
        Ok((proj, layout))
    }

    /// The maps of `pics`: each picture (or each group of layers) one map.
    pub fn maps(&self, arg: &str, pics: Pictures) -> PyResult<Vec<EnvMap>> {
        let (w, h) = (pics.width(), pics.height());
        if self.separate_layers() {
            let (proj, _) = self.shape(arg, w, h)?;
            let n = self.layers();
            if pics.lead.last() != Some(&n) {
                return Err(request(
                    arg,
                    format!(
                        "src_layout='separate' takes the {n} layers of a {} map as L×H×W×C (or N×L×H×W×C), L = {n}; the array's leading dimensions are {:?}",
                        self.spec.kind, pics.lead
                    ),
                ));
            }
            let mut images = pics.images.into_iter();
            let mut maps = Vec::new();
            loop {
                let layers: Vec<Image> = images.by_ref().take(n).collect();
                if layers.is_empty() {
                    break;
                }
                maps.push(EnvMap::new(proj, layers).map_err(|e| request(arg, e))?);
            }
            return Ok(maps);
        }
        // Each picture read as the CLI reads a picture with --from (and --in-layout): the
        // library's `interpret` (the layout judged by the shape, the shape checked, the
        // layers unpacked), its messages naming this call's arguments.
        let named = |e: mirrorball::Error| {
            let m = e.message.replace("use --from to", "say another src to");
            crate::errors::by_fault(e.fault, m.replace("--from", self.arg))
        };
        pics.images
            .into_iter()
            .map(|img| {
                mirrorball::load::interpret(
                    arg,
                    img,
                    Some(&self.spec),
                    self.layout,
                    None,
                    None,
                    |_| String::new(),
                )
                .map(|(env, _)| env)
                .map_err(named)
            })
            .collect()
    }

    /// Leading dimensions an array may have: a batch, and the layers when separate.
    pub fn lead(&self) -> std::ops::RangeInclusive<usize> {
        match self.separate_layers() {
            true => 1..=2,
            false => 0..=1,
        }
    }
}

/// Where the output's layers go in the array given back: each layer its own H×W×C, or
/// packed into one picture by a layout.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    layout: Layout,
    layers: usize,
    /// One layer's width and height.
    w: usize,
    h: usize,
    c: usize,
}

impl Placement {
    fn new(
        dst: Projection,
        layout: Option<Layout>,
        (w, h): (u32, u32),
        c: usize,
    ) -> PyResult<Placement> {
        let layers = dst.layer_count();
        let layout = layout.unwrap_or_else(|| Layout::default_for(dst.kind()));
        if !layout.fits(layers) {
            return Err(request(
                "layout",
                format!(
                    "{layout} needs six faces; a {} map has {layers} layers",
                    dst.kind()
                ),
            ));
        }
        Ok(Placement {
            layout,
            layers,
            w: w as usize,
            h: h as usize,
            c,
        })
    }

    /// Whether each layer is its own picture.
    fn separate(&self) -> bool {
        self.layout == Layout::Separate
    }

    /// One map's shape in the array.
    fn item_shape(&self) -> Vec<usize> {
        if self.separate() {
            if self.layers == 1 {
                return vec![self.h, self.w, self.c];
            }
            return vec![self.layers, self.h, self.w, self.c];
        }
        let (pw, ph) = self
            .layout
            .extent(self.layers, self.w as u32, self.h as u32);
        vec![ph as usize, pw as usize, self.c]
    }

    fn item_len(&self) -> usize {
        self.item_shape().iter().product()
    }

    /// Whether layers land by rows (separate, crosses, strips), not packed as a whole
    /// (v360's cells).
    fn by_rows(&self) -> bool {
        !matches!(self.layout, Layout::Cells(_))
    }

    /// For row `y` of layer `layer`: the element offset of its first texel in one map's
    /// part of the array, and whether the row runs backwards (a cell turned 180°).
    fn row_at(&self, layer: usize, y: usize) -> (usize, bool) {
        let (w, h, c) = (self.w, self.h, self.c);
        if self.separate() {
            return ((layer * h + y) * w * c, false);
        }
        let (col, row, turned) = self
            .layout
            .grid_cell(layer, self.layers)
            .expect("a grid layout holds every layer");
        let (pw, _) = self.layout.extent(self.layers, w as u32, h as u32);
        let (col, row) = (col as usize, row as usize);
        let py = row * h + if turned { h - 1 - y } else { y };
        ((py * pw as usize + col * w) * c, turned)
    }
}

/// The output array: a raw pointer into numpy's buffer, written by rows that never overlap.
struct Dest<T> {
    ptr: *mut T,
    len: usize,
}
// SAFETY: every writer writes its own rows (disjoint ranges, checked against `len`), and
// the buffer outlives the work (the array is held by the caller across it).
unsafe impl<T: Send> Send for Dest<T> {}
unsafe impl<T: Send> Sync for Dest<T> {}

impl<T: OutElem> Dest<T> {
    /// The `len` elements at `offset`, for one writer.
    ///
    /// # Safety
    /// No other writer may hold elements of `offset..offset + len` at the same time.
    #[allow(clippy::mut_from_ref)]
    unsafe fn part(&self, offset: usize, len: usize) -> &mut [T] {
        assert!(offset + len <= self.len, "a row past the array's end");
        // SAFETY: in bounds (asserted); the caller's writers are disjoint.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(offset), len) }
    }

    /// Writes `row` (floats, `c` channels) at `offset`, backwards by texels if `reversed`
    /// (`row` is then turned in place).
    fn put(&self, offset: usize, row: &mut [f32], c: usize, reversed: bool, linear: bool) {
        if reversed {
            reverse_texels(row, c);
        }
        // SAFETY: every row of the output is written by one writer (`make_map`).
        let out = unsafe { self.part(offset, row.len()) };
        T::encode_row(row, c, linear, out);
    }
}

/// Turns a row of texels of `c` channels end for end.
fn reverse_texels(row: &mut [f32], c: usize) {
    let n = row.len() / c;
    for i in 0..n / 2 {
        let (a, b) = row.split_at_mut((n - 1 - i) * c);
        a[i * c..(i + 1) * c].swap_with_slice(&mut b[..c]);
    }
}

/// Rows of one band: at least this many, or an eighth of a layer.
const BAND_ROWS: usize = 16;

/// Runs Python's signal handlers (Ctrl-C raises `KeyboardInterrupt` here).
fn check_signals() -> PyResult<()> {
    Python::attach(|py| py.check_signals())
}

/// What makes a map's rows: core's `Resampler` (convert) or a `Remap`'s rows.
trait Rows: Sync {
    /// Makes rows `y0 ..` of `layer` into `band` (whole rows).
    fn rows(&self, layer: usize, y0: usize, band: &mut [f32]);
    /// The plan's rows, where each row can be made alone (straight into the output).
    fn planned(&self) -> Option<&mirrorball_core::RemapRows<'_>> {
        None
    }
}

struct ResamplerRows<'a>(Resampler<'a>);

impl Rows for ResamplerRows<'_> {
    fn rows(&self, layer: usize, y0: usize, band: &mut [f32]) {
        self.0.rows_into(layer, y0 as u32, band);
    }
}

struct RemapRows<'a>(mirrorball_core::RemapRows<'a>, usize);

impl Rows for RemapRows<'_> {
    fn rows(&self, layer: usize, y0: usize, band: &mut [f32]) {
        band.par_chunks_mut(self.1)
            .enumerate()
            .for_each(|(i, row)| self.0.row_into(layer, y0 + i, row));
    }
    fn planned(&self) -> Option<&mirrorball_core::RemapRows<'_>> {
        Some(&self.0)
    }
}

/// Makes every row of one map through `rows` into `dest` at `base` (its first element),
/// band by band, checking signals between bands (on the calling thread: Python runs its
/// handlers on the main thread only). A plan's rows are made one by one on all threads,
/// each encoded into the array while in cache (a float row made straight into it); packed
/// v360 cells are made whole, then packed.
fn make_map<T: OutElem>(
    rows: &dyn Rows,
    place: &Placement,
    dst: Projection,
    dest: &Dest<T>,
    base: usize,
    linear: bool,
) -> PyResult<()> {
    let (w, h, c) = (place.w, place.h, place.c);
    let band = BAND_ROWS.max(h / 8).min(h);
    if let (Some(planned), true) = (rows.planned(), place.by_rows()) {
        for layer in 0..place.layers {
            for y0 in (0..h).step_by(band) {
                let ys = y0..(y0 + band).min(h);
                run(|| {
                    ys.into_par_iter().for_each_init(Vec::new, |buf, y| {
                        let (at, reversed) = place.row_at(layer, y);
                        if !reversed {
                            // SAFETY: row `y` of `layer` is this writer's alone.
                            let out = unsafe { dest.part(base + at, w * c) };
                            if let Some(out) = T::floats(out) {
                                return planned.row_into(layer, y, out);
                            }
                        }
                        buf.resize(w * c, 0.0);
                        planned.row_into(layer, y, buf);
                        dest.put(base + at, buf, c, reversed, linear);
                    })
                });
                check_signals()?;
            }
        }
        return Ok(());
    }
    let mut buf = vec![0f32; band * w * c];
    let mut whole: Vec<Image> = Vec::new();
    for layer in 0..place.layers {
        let mut y0 = 0;
        let mut img = (!place.by_rows()).then(|| Image::new(w as u32, h as u32, c));
        while y0 < h {
            let n = band.min(h - y0);
            let part = &mut buf[..n * w * c];
            run(|| rows.rows(layer, y0, part));
            match img.as_mut() {
                Some(img) => img.data_mut()[y0 * w * c..(y0 + n) * w * c].copy_from_slice(part),
                None => run(|| {
                    part.par_chunks_mut(w * c).enumerate().for_each(|(i, row)| {
                        let (at, reversed) = place.row_at(layer, y0 + i);
                        dest.put(base + at, row, c, reversed, linear);
                    })
                }),
            }
            y0 += n;
            check_signals()?;
        }
        whole.extend(img);
    }
    if !place.by_rows() {
        let env = EnvMap::new(dst, whole).map_err(|e| request("dst", e))?;
        let mut picture =
            run(|| place.layout.pack(&env)).ok_or_else(|| request("layout", "does not fit"))?;
        let row = picture.width() as usize * c;
        run(|| {
            picture
                .data_mut()
                .par_chunks_mut(row)
                .enumerate()
                .for_each(|(y, r)| dest.put(base + y * row, r, c, false, linear))
        });
    }
    Ok(())
}

/// A map's maker: for map `i`, hands its rows (a `Rows`) to the callback that fills the
/// output from them.
type MakeMap<'a> =
    dyn Fn(usize, &mut dyn FnMut(&dyn Rows) -> PyResult<()>) -> PyResult<()> + Sync + 'a;

/// The output array (`out` when given, checked; else a new one) and the maps made into it
/// by `rows_of(i)` for map `i` of `count`.
#[allow(clippy::too_many_arguments)]
fn make_all<'py>(
    py: Python<'py>,
    count: usize,
    batched: bool,
    place: Placement,
    dst: Projection,
    dtype: Dtype,
    linear: bool,
    out: Option<&Bound<'py, PyAny>>,
    make: &MakeMap<'_>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut shape = place.item_shape();
    if batched {
        shape.insert(0, count);
    }
    let array = match out {
        Some(o) => {
            arrays::check_out(o, &shape, dtype)?;
            o.clone()
        }
        None => match dtype {
            Dtype::F32 => PyArrayDyn::<f32>::zeros(py, shape.clone(), false).into_any(),
            Dtype::F16 => PyArrayDyn::<half::f16>::zeros(py, shape.clone(), false).into_any(),
            Dtype::U8 => PyArrayDyn::<u8>::zeros(py, shape.clone(), false).into_any(),
            Dtype::U16 => PyArrayDyn::<u16>::zeros(py, shape.clone(), false).into_any(),
        },
    };
    fn typed<T: OutElem>(
        py: Python<'_>,
        array: &Bound<'_, PyAny>,
        count: usize,
        place: &Placement,
        dst: Projection,
        make: &MakeMap<'_>,
        linear: bool,
    ) -> PyResult<()> {
        let arr = array.cast::<PyArrayDyn<T>>()?;
        let mut rw = arr
            .try_readwrite()
            .map_err(|e| request("out", format!("cannot be written: {e}")))?;
        let slice = rw
            .as_slice_mut()
            .map_err(|_| request("out", "not C-contiguous"))?;
        let dest = Dest {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
        };
        let item = place.item_len();
        py.detach(|| {
            for i in 0..count {
                make(i, &mut |rows| {
                    make_map(rows, place, dst, &dest, i * item, linear)
                })?;
            }
            Ok(())
        })
    }
    match dtype {
        Dtype::F32 => typed::<f32>(py, &array, count, &place, dst, make, linear)?,
        Dtype::F16 => typed::<half::f16>(py, &array, count, &place, dst, make, linear)?,
        Dtype::U8 => typed::<u8>(py, &array, count, &place, dst, make, linear)?,
        Dtype::U16 => typed::<u16>(py, &array, count, &place, dst, make, linear)?,
    }
    Ok(array)
}

/// The output projection and its layers' size: `size` as the CLI's `--size` (a cube's face
/// edge, a lat-long's width…), by default the source's resolution kept.
fn destination(
    dst: &ProjectionSpec,
    size: Option<i64>,
    src: &EnvMap,
) -> PyResult<(Projection, (u32, u32))> {
    let dst = dst.build(None).map_err(|e| request("dst", e))?;
    let size = match size {
        None => src.natural_size(dst.kind()),
        Some(s) if (1..=65536).contains(&s) => s as u32,
        Some(s) => return Err(request("size", format!("{s} is outside 1..=65536"))),
    };
    Ok((dst, dst.layer_extent(size)))
}

/// Converts an environment map (H×W×C, or a batch N×H×W×C) from projection `src` to `dst`
/// with mirrorball's antialiasing: the CLI's `mirrorball convert`, bit for bit.
///
/// `src`, `dst`: projection texts as the CLI's --from/--to take them
/// (`NAME[:key=value…]`: "latlong", "cube", "fisheye:fov=190:lens=equisolid").
/// `size`: as --size (a cube's face edge, a lat-long's width); default: the source's
/// resolution kept. `layout`: how a multi-layer output is packed ("hcross" by default for
/// cubes, "separate" gives L×H×W×C, also "vcross", "hstrip", "vstrip", "c3x2", "eac").
/// `src_layout`: how the source's layers are packed (default: judged by its shape;
/// "separate" takes L×H×W×C). `yaw`/`pitch`/`roll` (degrees) turn the world as the CLI's
/// flags. `outside`: what texels outside the output's covered part hold, "black" or "rim"
/// (the CLI's --outside; default: black for fisheye, dual fisheye, Hammer and sinusoidal,
/// the rim's value for sphere, angular and paraboloid maps). `dtype`: the result's
/// (default: the input's). uint8/uint16 arrays are sRGB codes,
/// as the CLI reads PNG; `linear=True` reads and writes them as linear codes. `invalid`:
/// NaN and infinite values "raise" (default), are set to "zero" (as the CLI), or "keep".
/// `v360`: FFmpeg's v360 filter options ("e:eac:yaw=30:w=3840:h=2160", the CLI's --v360)
/// in place of `src`, `dst`, `src_layout`, `layout`, `yaw`, `pitch`, `roll` and, with `w`
/// and `h`, `size`: what v360 means by them, refused beside them.
#[pyfunction]
#[pyo3(signature = (array, src=None, dst=None, size=None, layout=None, *, src_layout=None, yaw=0.0, pitch=0.0, roll=0.0, exposure=0.0, max_samples=8, outside=None, v360=None, dtype=None, linear=false, invalid="raise", out=None))]
#[allow(clippy::too_many_arguments)]
pub fn convert<'py>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    src: Option<&str>,
    dst: Option<&str>,
    size: Option<i64>,
    layout: Option<&str>,
    src_layout: Option<&str>,
    yaw: f64,
    pitch: f64,
    roll: f64,
    exposure: f32,
    max_samples: u32,
    outside: Option<&str>,
    v360: Option<&str>,
    dtype: Option<&Bound<'py, PyAny>>,
    linear: bool,
    invalid: &str,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let Asked {
        source,
        dst,
        size,
        layout,
        opts,
    } = asked(
        v360,
        (src, dst),
        (size, layout, src_layout),
        (yaw, pitch, roll),
        exposure,
        max_samples,
        outside,
    )?;
    let want = arrays::dtype_arg(py, dtype)?;
    let invalid = arrays::invalid_arg(invalid)?;
    // Checked before the array is read.
    dst.build(None).map_err(|e| request("dst", e))?;
    let pics = arrays::pictures(array, "array", source.lead(), linear, invalid)?;
    let batched = pics.lead.len() > usize::from(source.separate_layers());
    let (dtype, c) = (want.unwrap_or(pics.dtype), pics.channels());
    let maps = source.maps("array", pics)?;
    let (dst, extent) = destination(&dst, size, &maps[0])?;
    let place = Placement::new(dst, layout, extent, c)?;
    let make = |i: usize, f: &mut dyn FnMut(&dyn Rows) -> PyResult<()>| {
        let r = run(|| Resampler::new(&maps[i], dst, extent.0, extent.1, &opts));
        f(&ResamplerRows(r))
    };
    make_all(
        py,
        maps.len(),
        batched,
        place,
        dst,
        dtype,
        linear,
        out,
        &make,
    )
}

/// The projection names `src` and `dst` take (canonical names; aliases are accepted too).
#[pyfunction]
pub fn projections() -> Vec<String> {
    ProjectionKind::all().map(|k| k.to_string()).collect()
}

/// A conversion planned once for sources of one shape and applied to many arrays or
/// batches (core's `Remap`: what cv2.remap's precomputed maps are, with mirrorball's
/// antialiasing in the plan). Results agree with `convert` to about 1e-5 relative.
///
/// `src_shape`: the source pictures' (H, W) or (H, W, C) (one layer's, with
/// src_layout="separate"). The other arguments are `convert`'s.
#[pyclass(module = "mirrorball", frozen)]
pub struct Remap {
    plan: Arc<mirrorball_core::Remap>,
    source: Source,
    /// The source picture's width and height.
    src_extent: (u32, u32),
    /// Whether each source picture is the projection's one layer as it is (no layout to
    /// unpack).
    one_picture: bool,
    dst: Projection,
    layout: Option<Layout>,
    extent: (u32, u32),
    /// The last source's float texels, filled again by the next `apply`.
    spare: std::sync::Mutex<Vec<Vec<f32>>>,
}

#[pymethods]
impl Remap {
    #[new]
    #[pyo3(signature = (src_shape, src=None, dst=None, size=None, layout=None, *, src_layout=None, yaw=0.0, pitch=0.0, roll=0.0, exposure=0.0, max_samples=8, outside=None, v360=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        src_shape: Vec<i64>,
        src: Option<&str>,
        dst: Option<&str>,
        size: Option<i64>,
        layout: Option<&str>,
        src_layout: Option<&str>,
        yaw: f64,
        pitch: f64,
        roll: f64,
        exposure: f32,
        max_samples: u32,
        outside: Option<&str>,
        v360: Option<&str>,
    ) -> PyResult<Remap> {
        let Asked {
            source,
            dst,
            size,
            layout,
            opts,
        } = asked(
            v360,
            (src, dst),
            (size, layout, src_layout),
            (yaw, pitch, roll),
            exposure,
            max_samples,
            outside,
        )?;
        let (h, w) = match src_shape[..] {
            [h, w] | [h, w, 3] | [h, w, 4] if h > 0 && w > 0 && h <= 1 << 20 && w <= 1 << 20 => {
                (h as u32, w as u32)
            }
            _ => {
                return Err(request(
                    "src_shape",
                    format!("{src_shape:?}; give (H, W) or (H, W, C) with C 3 or 4"),
                ))
            }
        };
        let (proj, l) = source.shape("src_shape", w, h)?;
        // The layers' extent, as unpacking gives it.
        let (lw, lh) = match l {
            Layout::Separate => (w, h),
            Layout::Cells(cells) => {
                let n = cells
                    .face_size(w, h)
                    .ok_or_else(|| request("src_shape", format!("{w}x{h} fits no {l} layout")))?;
                (n, n)
            }
            l => {
                let (gc, gr) = l.grid(proj.layer_count());
                if w % gc != 0 || h % gr != 0 || w / gc != h / gr {
                    return Err(request(
                        "src_shape",
                        format!("a {w}x{h} picture is not a {l} of square faces"),
                    ));
                }
                (w / gc, h / gr)
            }
        };
        let n = proj.layer_count();
        let probe = EnvMap::new(proj, (0..n).map(|_| Image::new(lw, lh, 3)).collect())
            .map_err(|e| request("src_shape", e))?;
        let (dst, extent) = destination(&dst, size, &probe)?;
        drop(probe);
        Placement::new(dst, layout, extent, 3)?;
        let plan = py.detach(|| {
            run(|| mirrorball_core::Remap::with_extent(proj, (lw, lh), n, dst, extent, &opts))
        });
        Ok(Remap {
            plan: Arc::new(plan),
            source,
            src_extent: (w, h),
            one_picture: n == 1 && l == Layout::Separate,
            dst,
            layout,
            extent,
            spare: std::sync::Mutex::new(Vec::new()),
        })
    }

    /// Converts `array` (the plan's source shape, or a batch N×…) into a new array, or into
    /// `out` (C-contiguous, the result's shape and dtype) and returns it.
    #[pyo3(signature = (array, out=None, *, dtype=None, linear=false, invalid="raise"))]
    fn apply<'py>(
        &self,
        py: Python<'py>,
        array: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
        dtype: Option<&Bound<'py, PyAny>>,
        linear: bool,
        invalid: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let want = arrays::dtype_arg(py, dtype)?;
        let invalid: Invalid = arrays::invalid_arg(invalid)?;
        let array = &arrays::numpy_of(array, "array")?;
        if let Some(made) = self.apply_in_place(py, array, out, want, linear, invalid)? {
            return Ok(made);
        }
        let spare = std::mem::take(&mut *self.spare.lock().unwrap_or_else(|e| e.into_inner()));
        let pics =
            arrays::pictures_into(array, "array", self.source.lead(), linear, invalid, spare)?;
        if (pics.width(), pics.height()) != self.src_extent {
            return Err(request(
                "array",
                format!(
                    "pictures of {}x{} (W×H); the plan was made for {}x{}",
                    pics.width(),
                    pics.height(),
                    self.src_extent.0,
                    self.src_extent.1
                ),
            ));
        }
        let batched = pics.lead.len() > usize::from(self.source.separate_layers());
        let (dtype, c) = (want.unwrap_or(pics.dtype), pics.channels());
        let maps = self.source.maps("array", pics)?;
        let place = Placement::new(self.dst, self.layout, self.extent, c)?;
        let plan = &self.plan;
        let row = self.extent.0 as usize * c;
        let make = |i: usize, f: &mut dyn FnMut(&dyn Rows) -> PyResult<()>| {
            let rows = run(|| plan.rows(&maps[i])).map_err(|e| request("array", e))?;
            f(&RemapRows(rows, row))
        };
        let made = make_all(
            py,
            maps.len(),
            batched,
            place,
            self.dst,
            dtype,
            linear,
            out,
            &make,
        );
        *self.spare.lock().unwrap_or_else(|e| e.into_inner()) = Pictures::spare_of(maps);
        made
    }

    /// The shape of one result (without a batch's N), for channels `c`.
    #[pyo3(signature = (c=3))]
    fn output_shape(&self, c: usize) -> PyResult<Vec<usize>> {
        if c != 3 && c != 4 {
            return Err(request("c", format!("{c}; give 3 or 4")));
        }
        Ok(Placement::new(self.dst, self.layout, self.extent, c)?.item_shape())
    }

    /// The bytes the plan holds.
    #[getter]
    fn nbytes(&self) -> usize {
        self.plan.memory_bytes()
    }

    /// The output projection's text.
    #[getter]
    fn dst(&self) -> String {
        self.dst.to_string()
    }

    fn __repr__(&self) -> String {
        format!(
            "Remap({}x{} {} -> {} {}x{}x{})",
            self.src_extent.0,
            self.src_extent.1,
            self.source.spec.kind,
            self.dst,
            self.extent.0,
            self.extent.1,
            self.dst.layer_count()
        )
    }
}

impl Remap {
    /// [`Remap::apply`] reading the array where it lies, with no float copy of it: for a
    /// plan whose source is one picture read as it is (a lat-long, a fisheye…), and an RGB
    /// array (or batch) of uint8, uint16 or float32, C-contiguous, in the machine's byte
    /// order. The rows are core's coded rows, the same bits as the copied source's (core's
    /// test); `None` where the array is not such (the caller copies it), or where floats
    /// hold values `invalid='zero'` must change.
    fn apply_in_place<'py>(
        &self,
        py: Python<'py>,
        array: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
        want: Option<Dtype>,
        linear: bool,
        invalid: Invalid,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        if !self.one_picture || !self.plan.takes_codes() {
            return Ok(None);
        }
        let Ok(arr) = array.cast::<PyUntypedArray>() else {
            return Ok(None);
        };
        let shape = arr.shape().to_vec();
        let (w, h) = (self.src_extent.0 as usize, self.src_extent.1 as usize);
        let nd = shape.len();
        let fits = (nd == 3 || nd == 4)
            && shape[nd - 3..] == [h, w, 3]
            && !shape.contains(&0)
            && arr.is_c_contiguous()
            && arr.dtype().is_native_byteorder() != Some(false);
        if !fits {
            return Ok(None);
        }
        let name: String = arr.dtype().getattr("name")?.extract()?;
        let (count, batched) = (if nd == 4 { shape[0] } else { 1 }, nd == 4);
        let per = w * h * 3;
        let extent = self.src_extent;
        match name.as_str() {
            "uint8" => {
                let a: PyReadonlyArrayDyn<'_, u8> = array.extract()?;
                let s = a.as_slice()?;
                let table = arrays::decode8(linear);
                self.apply_codes(
                    py,
                    (count, batched),
                    want.unwrap_or(Dtype::U8),
                    linear,
                    out,
                    &|i| Codes::u8(&s[i * per..(i + 1) * per], table, extent).ok(),
                )
                .map(Some)
            }
            "uint16" if cfg!(target_endian = "little") => {
                let a: PyReadonlyArrayDyn<'_, u16> = array.extract()?;
                let s = a.as_slice()?;
                // SAFETY: the elements' bytes, read only while `a` is borrowed; on this
                // target they are the little-endian codes `Codes::u16le` reads.
                let bytes =
                    unsafe { std::slice::from_raw_parts(s.as_ptr().cast::<u8>(), s.len() * 2) };
                let table = arrays::decode16(linear);
                self.apply_codes(
                    py,
                    (count, batched),
                    want.unwrap_or(Dtype::U16),
                    linear,
                    out,
                    &|i| Codes::u16le(&bytes[i * per * 2..(i + 1) * per * 2], table, extent).ok(),
                )
                .map(Some)
            }
            "float32" => {
                let a: PyReadonlyArrayDyn<'_, f32> = array.extract()?;
                let s = a.as_slice()?;
                // What `invalid` asks of the values, checked on all threads first.
                let bad = |f: fn(&[f32]) -> usize| {
                    py.detach(|| run(|| s.par_chunks(1 << 15).map(f).sum::<usize>()))
                };
                match invalid {
                    Invalid::Keep => {}
                    Invalid::Raise => {
                        let n = bad(|b| b.iter().filter(|v| !v.is_finite()).count());
                        if n > 0 {
                            return Err(arrays::nonfinite_error("array", n));
                        }
                    }
                    Invalid::Zero => {
                        if bad(|b| mirrorball_core::count_invalid(b, false) as usize) > 0 {
                            return Ok(None);
                        }
                    }
                }
                self.apply_codes(
                    py,
                    (count, batched),
                    want.unwrap_or(Dtype::F32),
                    linear,
                    out,
                    &|i| Codes::f32(&s[i * per..(i + 1) * per], extent).ok(),
                )
                .map(Some)
            }
            _ => Ok(None),
        }
    }

    /// The plan applied to `count` sources given as codes (`codes(i)`: source `i`), into
    /// a new array of `dtype` or `out`.
    fn apply_codes<'py, 'c>(
        &self,
        py: Python<'py>,
        (count, batched): (usize, bool),
        dtype: Dtype,
        linear: bool,
        out: Option<&Bound<'py, PyAny>>,
        codes: &(dyn Fn(usize) -> Option<Codes<'c>> + Sync),
    ) -> PyResult<Bound<'py, PyAny>> {
        let place = Placement::new(self.dst, self.layout, self.extent, 3)?;
        let (plan, row) = (&self.plan, self.extent.0 as usize * 3);
        let make = |i: usize, f: &mut dyn FnMut(&dyn Rows) -> PyResult<()>| {
            let c = codes(i).ok_or_else(|| request("array", "not the plan's source shape"))?;
            let rows = plan.rows_coded(c).map_err(|e| request("array", e))?;
            f(&RemapRows(rows, row))
        };
        make_all(
            py, count, batched, place, self.dst, dtype, linear, out, &make,
        )
    }
}
