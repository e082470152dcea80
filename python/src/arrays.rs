//! numpy arrays to `Image`s and back: H×W×C pictures (C 3 or 4) with any leading
//! dimensions (a batch, a map's layers), float32, float16, uint8 or uint16, C-contiguous or
//! not. 8- and 16-bit codes are sRGB as the CLI reads PNG (io's own tables), or linear
//! (`linear=True`: code/255 or code/65535); alpha is always linear.

use crate::errors::request;
use half::f16;
use mirrorball::frames::pipe::{PixFmt, SrgbTable};
use mirrorball_core::{EnvMap, Image, Layout};
use numpy::{
    Element, PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use rayon::prelude::*;
use std::sync::OnceLock;

/// The element types taken and given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dtype {
    F32,
    F16,
    U8,
    U16,
}

impl Dtype {
    fn name(self) -> &'static str {
        match self {
            Dtype::F32 => "float32",
            Dtype::F16 => "float16",
            Dtype::U8 => "uint8",
            Dtype::U16 => "uint16",
        }
    }

    pub fn of_name(name: &str) -> Option<Dtype> {
        Some(match name {
            "float32" => Dtype::F32,
            "float16" => Dtype::F16,
            "uint8" => Dtype::U8,
            "uint16" => Dtype::U16,
            _ => return None,
        })
    }
}

const TAKEN: &str = "float32, float16, uint8 or uint16";

/// The `dtype=` argument: anything `numpy.dtype` takes that is one of ours, or None.
pub fn dtype_arg(py: Python<'_>, dtype: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Dtype>> {
    let Some(d) = dtype.filter(|d| !d.is_none()) else {
        return Ok(None);
    };
    let np = py.import("numpy")?;
    let name: String = np
        .call_method1("dtype", (d,))
        .map_err(|e| request("dtype", e.value(py).to_string()))?
        .getattr("name")?
        .extract()?;
    Dtype::of_name(&name)
        .map(Some)
        .ok_or_else(|| PyTypeError::new_err(format!("dtype: {name}; give {TAKEN}")))
}

/// Pictures read from one array: each H×W×C as an `Image`, in C order of the leading
/// dimensions.
pub struct Pictures {
    pub images: Vec<Image>,
    /// The dimensions before H, W, C.
    pub lead: Vec<usize>,
    pub dtype: Dtype,
}

impl Pictures {
    /// The buffers of the maps' layers back (each picture's texels), for
    /// [`pictures_into`] to fill again.
    pub fn spare_of(maps: Vec<mirrorball_core::EnvMap>) -> Vec<Vec<f32>> {
        maps.into_iter()
            .flat_map(|m| m.into_layers())
            .map(Image::into_vec)
            .collect()
    }

    pub fn height(&self) -> u32 {
        self.images[0].height()
    }
    pub fn width(&self) -> u32 {
        self.images[0].width()
    }
    pub fn channels(&self) -> usize {
        self.images[0].channels()
    }
}

/// What to do with NaN and infinite values in a float array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Invalid {
    /// Refuse the array (the default): `ValueError` naming it.
    Raise,
    /// Set NaN, infinite and negative values to 0, as the CLI does with files.
    Zero,
    /// Keep them.
    Keep,
}

pub fn invalid_arg(s: &str) -> PyResult<Invalid> {
    match s {
        "raise" => Ok(Invalid::Raise),
        "zero" => Ok(Invalid::Zero),
        "keep" => Ok(Invalid::Keep),
        _ => Err(request(
            "invalid",
            format!("'{s}'; give 'raise', 'zero' or 'keep'"),
        )),
    }
}

/// Reads `obj` (named `arg` in errors) as pictures with `lead` leading dimensions allowed
/// (`lead_ok`: how many).
pub fn pictures(
    obj: &Bound<'_, PyAny>,
    arg: &str,
    lead_ok: std::ops::RangeInclusive<usize>,
    linear: bool,
    invalid: Invalid,
) -> PyResult<Pictures> {
    pictures_into(obj, arg, lead_ok, linear, invalid, Vec::new())
}

/// `obj` as a numpy array: itself, or, for another array library's array on the CPU (a
/// torch tensor, a JAX array: anything with `__dlpack__`), `numpy.from_dlpack(obj)`, the
/// same memory without a copy. A tensor on a GPU is refused, naming `arg`.
pub fn numpy_of<'py>(obj: &Bound<'py, PyAny>, arg: &str) -> PyResult<Bound<'py, PyAny>> {
    if obj.cast::<PyUntypedArray>().is_ok() || !obj.hasattr("__dlpack__")? {
        return Ok(obj.clone());
    }
    let py = obj.py();
    py.import("numpy")?
        .call_method1("from_dlpack", (obj,))
        .map_err(|e| {
            PyTypeError::new_err(format!(
                "{arg}: read through DLPack: {} (a tensor on a GPU: move it to the CPU first, tensor.cpu())",
                e.value(py)
            ))
        })
}

/// [`pictures`] into `spare` (an earlier call's buffers, from [`Pictures::spare_of`]) where
/// they are the right length: no allocation and no page faults for the frames of a loop.
pub fn pictures_into(
    obj: &Bound<'_, PyAny>,
    arg: &str,
    lead_ok: std::ops::RangeInclusive<usize>,
    linear: bool,
    invalid: Invalid,
    spare: Vec<Vec<f32>>,
) -> PyResult<Pictures> {
    let obj = &numpy_of(obj, arg)?;
    let arr = obj.cast::<PyUntypedArray>().map_err(|_| {
        let ty = obj
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_default();
        PyTypeError::new_err(format!(
            "{arg}: a numpy array (H×W×C, C 3 or 4), or an array with __dlpack__ on the CPU, is needed, not {ty}"
        ))
    })?;
    let (shape, (h, w, c)) = checked_shape(arr, arg, lead_ok)?;
    let nd = shape.len();
    let lead = shape[..nd - 3].to_vec();
    let count: usize = lead.iter().product();
    let per = h * w * c;
    let name: String = arr.dtype().getattr("name")?.extract()?;
    let dtype = Dtype::of_name(&name).ok_or_else(|| {
        PyTypeError::new_err(format!(
            "{arg}: dtype {name}; give {TAKEN} (for example {arg}.astype(np.float32))"
        ))
    })?;
    // One buffer a picture, an earlier call's where it has the length.
    let mut bufs = spare;
    bufs.truncate(count);
    for b in &mut bufs {
        if b.len() != per {
            *b = vec![0.0; per];
        }
    }
    bufs.resize_with(count, || vec![0.0; per]);
    let mut nonfinite = 0;
    match dtype {
        Dtype::F32 => nonfinite = floats::<f32>(obj, |v| v, &mut bufs)?,
        Dtype::F16 => nonfinite = floats::<f16>(obj, f16::to_f32, &mut bufs)?,
        Dtype::U8 => {
            let (t, a) = (decode8(linear), alpha8());
            coded::<u8>(obj, c, |v| t[v as usize], |v| a[v as usize], &mut bufs)?
        }
        Dtype::U16 => {
            let t = decode16(linear);
            coded::<u16>(obj, c, |v| t[v as usize], |v| v as f32 / 65535.0, &mut bufs)?
        }
    };
    if matches!(dtype, Dtype::F32 | Dtype::F16) {
        match invalid {
            Invalid::Keep => {}
            Invalid::Raise => {
                if nonfinite > 0 {
                    return Err(nonfinite_error(arg, nonfinite));
                }
            }
            // Core's rule, after the pictures are made.
            Invalid::Zero => {}
        }
    }
    let images: Vec<Image> = bufs
        .into_iter()
        .map(|v| Image::from_vec(w as u32, h as u32, c, v).expect("checked shape"))
        .collect();
    let mut images = images;
    if invalid == Invalid::Zero {
        images.par_iter_mut().for_each(|img| {
            mirrorball_core::sanitize_layer(img);
        });
    }
    Ok(Pictures {
        images,
        lead,
        dtype,
    })
}

/// The shape of `arr` (the argument `arg`), checked: pictures H×W×C (C 3 or 4, none
/// empty, each side within 2³¹) after a number of leading dimensions in `lead_ok`; the
/// shape and (H, W, C).
fn checked_shape(
    arr: &Bound<'_, PyUntypedArray>,
    arg: &str,
    lead_ok: std::ops::RangeInclusive<usize>,
) -> PyResult<(Vec<usize>, (usize, usize, usize))> {
    let shape = arr.shape().to_vec();
    let dims = |s: &[usize]| {
        s.iter()
            .map(|d| d.to_string())
            .collect::<Vec<_>>()
            .join("×")
    };
    let nd = shape.len();
    if nd < 3 || !lead_ok.contains(&(nd - 3)) {
        let want = match (*lead_ok.start(), *lead_ok.end()) {
            (0, 0) => "H×W×C".to_string(),
            (0, 1) => "H×W×C or N×H×W×C".to_string(),
            (a, b) => format!("H×W×C with {a} to {b} dimensions before"),
        };
        return Err(request(
            arg,
            format!(
                "an array of shape {} ({nd} dimensions); give {want} (a grey H×W array: np.dstack([a]*3))",
                dims(&shape)
            ),
        ));
    }
    let (h, w, c) = (shape[nd - 3], shape[nd - 2], shape[nd - 1]);
    if c != 3 && c != 4 {
        return Err(request(
            arg,
            format!(
                "shape {}: {c} channels; give 3 (RGB) or 4 (RGBA)",
                dims(&shape)
            ),
        ));
    }
    if shape.contains(&0) {
        return Err(request(
            arg,
            format!("shape {}: the array is empty", dims(&shape)),
        ));
    }
    if h > u32::MAX as usize / 2 || w > u32::MAX as usize / 2 {
        return Err(request(arg, format!("shape {}: too large", dims(&shape))));
    }
    Ok((shape, (h, w, c)))
}

/// `invalid='raise'` refusing an array holding `bad` NaN or infinite values.
pub fn nonfinite_error(arg: &str, bad: usize) -> PyErr {
    request(
        arg,
        format!("{bad} NaN or infinite values (invalid='zero' sets them to 0, as the CLI does; invalid='keep' keeps them)"),
    )
}

/// Copies a float array's values, in C order (any strides), into `bufs` (one picture's
/// texels each, in order), returning how many are NaN or infinite (counted as they are
/// copied, while in cache).
fn floats<T: Element + Copy + Sync>(
    obj: &Bound<'_, PyAny>,
    f: fn(T) -> f32,
    bufs: &mut [Vec<f32>],
) -> PyResult<usize> {
    let a: PyReadonlyArrayDyn<'_, T> = obj.extract()?;
    fill(&a, bufs, 1 << 15, |d, s| {
        for (d, &v) in d.iter_mut().zip(s) {
            *d = f(v);
        }
        d.iter().filter(|v| !v.is_finite()).count()
    })
}

/// The linear values of an integer array of `c` channels, colour through `colour`, alpha
/// through `alpha`, into `bufs` (one picture's texels each, in order).
fn coded<T: Element + Copy + Sync>(
    obj: &Bound<'_, PyAny>,
    c: usize,
    colour: impl Fn(T) -> f32 + Sync,
    alpha: impl Fn(T) -> f32 + Sync,
    bufs: &mut [Vec<f32>],
) -> PyResult<()> {
    let a: PyReadonlyArrayDyn<'_, T> = obj.extract()?;
    fill(&a, bufs, c * 4096, |d, s| {
        for (i, (d, &v)) in d.iter_mut().zip(s).enumerate() {
            *d = if c == 4 && i % 4 == 3 {
                alpha(v)
            } else {
                colour(v)
            };
        }
        0
    })?;
    Ok(())
}

/// Fills `bufs` (consecutive parts of the array's C order) from `a` through `block(dst,
/// src)` in parallel blocks of `block_len` (a whole number of texels), summing what the
/// blocks return; an array not in C order is read by its logical iteration.
fn fill<T: Element + Copy + Sync>(
    a: &PyReadonlyArrayDyn<'_, T>,
    bufs: &mut [Vec<f32>],
    block_len: usize,
    block: impl Fn(&mut [f32], &[T]) -> usize + Sync,
) -> PyResult<usize> {
    // `as_slice` takes Fortran order too: C order only, else the logical iteration.
    if let Some(s) = a.as_slice().ok().filter(|_| a.is_c_contiguous()) {
        let mut at = 0;
        let mut sum = 0;
        for b in bufs.iter_mut() {
            let part = &s[at..at + b.len()];
            at += b.len();
            sum += b
                .par_chunks_mut(block_len)
                .zip(part.par_chunks(block_len))
                .map(|(d, s)| block(d, s))
                .sum::<usize>();
        }
        return Ok(sum);
    }
    let arr = a.as_array();
    let mut values = arr.iter();
    let mut sum = 0;
    let mut scratch = Vec::with_capacity(block_len);
    for b in bufs.iter_mut() {
        for d in b.chunks_mut(block_len) {
            scratch.clear();
            scratch.extend(values.by_ref().take(d.len()).copied());
            sum += block(d, &scratch);
        }
    }
    Ok(sum)
}

pub fn decode8(linear: bool) -> &'static [f32] {
    static LINEAR: OnceLock<Vec<f32>> = OnceLock::new();
    match linear {
        false => &mirrorball_io::srgb8_to_linear()[..],
        true => LINEAR.get_or_init(|| (0..256).map(|k| k as f32 / 255.0).collect()),
    }
}

fn alpha8() -> &'static [f32] {
    decode8(true)
}

pub fn decode16(linear: bool) -> &'static [f32] {
    static LINEAR: OnceLock<Vec<f32>> = OnceLock::new();
    match linear {
        false => mirrorball_io::srgb16_to_linear(),
        true => LINEAR.get_or_init(|| (0..65536).map(|k| k as f32 / 65535.0).collect()),
    }
}

/// Linear light to the nearest 8-bit sRGB code, clamped to [0, 1], NaN 0: io's PNG rule,
/// through the library's fast table that gives its codes exactly (`SrgbTable`, what raw
/// video frames use).
fn encode8_srgb(l: f32) -> u8 {
    SrgbTable::get(255.0).code8(l) as u8
}

/// Linear light to the nearest 16-bit sRGB code, as io's PNG writer (the same table).
fn encode16_srgb(l: f32) -> u16 {
    SrgbTable::get(65535.0).code16(l) as u16
}

/// A linear value (alpha, or a colour with `linear=True`) to an integer of `max`.
fn encode_linear(a: f32, max: f32) -> f32 {
    if a > 0.0 {
        (a.min(1.0) * max + 0.5).floor()
    } else {
        0.0
    }
}

/// An output element type: how a row of linear floats becomes its elements.
pub trait OutElem: Element + Copy + Default + Send + Sync {
    /// Encodes `src` (texels of `c` channels, the fourth alpha) into `out` (as many
    /// elements): floats as they are, integers as the module documents.
    fn encode_row(src: &[f32], c: usize, linear: bool, out: &mut [Self]);
    /// `out` as floats where the element is `f32` (rows are then made straight into it).
    fn floats(_out: &mut [Self]) -> Option<&mut [f32]> {
        None
    }
}

impl OutElem for f32 {
    fn encode_row(src: &[f32], _: usize, _: bool, out: &mut [f32]) {
        out.copy_from_slice(src);
    }
    fn floats(out: &mut [f32]) -> Option<&mut [f32]> {
        Some(out)
    }
}

impl OutElem for f16 {
    fn encode_row(src: &[f32], _: usize, _: bool, out: &mut [f16]) {
        for (o, &v) in out.iter_mut().zip(src) {
            *o = f16::from_f32(v);
        }
    }
}

impl OutElem for u8 {
    fn encode_row(src: &[f32], c: usize, linear: bool, out: &mut [u8]) {
        if c == 3 && !linear {
            // RGB sRGB codes: the library's raw-frame encoder (eight lanes, io's codes).
            return PixFmt::Rgb24.encode_texels(Some(SrgbTable::get(255.0)), src, 3, out);
        }
        if c == 3 {
            // Linear codes: each value rounded, a loop the compiler vectorises.
            for (o, &v) in out.iter_mut().zip(src) {
                *o = (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            }
            return;
        }
        per_value(src, c, out, encoder_u8(c, linear))
    }
}

impl OutElem for u16 {
    fn encode_row(src: &[f32], c: usize, linear: bool, out: &mut [u16]) {
        if c == 3 && !linear && cfg!(target_endian = "little") {
            // SAFETY: the elements' bytes, written as little-endian codes, which on this
            // target are the `u16`s themselves; `u8` has no alignment.
            let bytes = unsafe {
                std::slice::from_raw_parts_mut(out.as_mut_ptr().cast::<u8>(), out.len() * 2)
            };
            let table = SrgbTable::get(65535.0);
            return PixFmt::Rgb48le.encode_texels(Some(table), src, 3, bytes);
        }
        per_value(src, c, out, encoder_u16(c, linear))
    }
}

/// Each value of `src` (texels of `c` channels) through `f(channel, value)`.
fn per_value<T>(src: &[f32], c: usize, out: &mut [T], f: impl Fn(usize, f32) -> T) {
    for (o, s) in out.chunks_exact_mut(c).zip(src.chunks_exact(c)) {
        for (i, (o, &v)) in o.iter_mut().zip(s).enumerate() {
            *o = f(i, v);
        }
    }
}

/// The texels `src` (interleaved, `c` channels) as a flat vector of `T`, in parallel blocks.
fn encode_all<T: OutElem>(src: &[&[f32]], c: usize, linear: bool) -> Vec<T> {
    let total: usize = src.iter().map(|s| s.len()).sum();
    let mut out = vec![T::default(); total];
    let mut at = 0;
    for s in src {
        out[at..at + s.len()]
            .par_chunks_mut(c * 4096)
            .zip(s.par_chunks(c * 4096))
            .for_each(|(o, s)| T::encode_row(s, c, linear, o));
        at += s.len();
    }
    out
}

/// The per-channel encoder of `dtype`.
fn encoder_u8(c: usize, linear: bool) -> impl Fn(usize, f32) -> u8 + Sync {
    move |ch, v| {
        if linear || (c == 4 && ch == 3) {
            encode_linear(v, 255.0) as u8
        } else {
            encode8_srgb(v)
        }
    }
}

fn encoder_u16(c: usize, linear: bool) -> impl Fn(usize, f32) -> u16 + Sync {
    move |ch, v| {
        if linear || (c == 4 && ch == 3) {
            encode_linear(v, 65535.0) as u16
        } else {
            encode16_srgb(v)
        }
    }
}

/// A numpy array of `shape` and `dtype` holding `parts` (interleaved texels of `c`
/// channels, in order), encoded as the module documents.
pub fn to_numpy<'py>(
    py: Python<'py>,
    parts: &[&[f32]],
    shape: &[usize],
    c: usize,
    dtype: Dtype,
    linear: bool,
) -> PyResult<Bound<'py, PyAny>> {
    fn shaped<'py, T: Element>(
        py: Python<'py>,
        v: Vec<T>,
        shape: &[usize],
    ) -> PyResult<Bound<'py, PyAny>> {
        let a = PyArray1::from_vec(py, v);
        Ok(a.reshape(shape)?.into_any())
    }
    fn typed<'py, T: OutElem>(
        py: Python<'py>,
        parts: &[&[f32]],
        shape: &[usize],
        c: usize,
        linear: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let v = py.detach(|| crate::threads::run(|| encode_all::<T>(parts, c, linear)));
        shaped(py, v, shape)
    }
    match dtype {
        Dtype::F32 => typed::<f32>(py, parts, shape, c, linear),
        Dtype::F16 => typed::<f16>(py, parts, shape, c, linear),
        Dtype::U8 => typed::<u8>(py, parts, shape, c, linear),
        Dtype::U16 => typed::<u16>(py, parts, shape, c, linear),
    }
}

/// A map as one numpy array: its layers L×H×W×C (H×W×C for one layer) with
/// `Layout::Separate`, else packed into one picture by `layout`.
pub fn map_to_numpy<'py>(
    py: Python<'py>,
    env: &EnvMap,
    layout: Layout,
    dtype: Dtype,
    linear: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let c = env.channels();
    if layout == Layout::Separate {
        let parts: Vec<&[f32]> = env.layers().iter().map(Image::data).collect();
        let mut shape = vec![env.height() as usize, env.width() as usize, c];
        if parts.len() > 1 {
            shape.insert(0, parts.len());
        }
        return to_numpy(py, &parts, &shape, c, dtype, linear);
    }
    let picture = layout.pack(env).ok_or_else(|| {
        request(
            "layout",
            format!("{layout} does not fit a {} map", env.projection().kind()),
        )
    })?;
    let shape = [picture.height() as usize, picture.width() as usize, c];
    to_numpy(py, &[picture.data()], &shape, c, dtype, linear)
}

/// `out=`: a writable C-contiguous array of `shape` and `dtype`, checked.
pub fn check_out(out: &Bound<'_, PyAny>, shape: &[usize], dtype: Dtype) -> PyResult<()> {
    let arr = out
        .cast::<PyUntypedArray>()
        .map_err(|_| PyTypeError::new_err("out: a numpy array is needed"))?;
    let name: String = arr.dtype().getattr("name")?.extract()?;
    if name != dtype.name() {
        return Err(PyTypeError::new_err(format!(
            "out: dtype {name}; the result is {} (give dtype= to choose)",
            dtype.name()
        )));
    }
    if arr.shape() != shape {
        return Err(request(
            "out",
            format!("shape {:?}; the result is {:?}", arr.shape(), shape),
        ));
    }
    if !arr.is_c_contiguous() {
        return Err(request("out", "not C-contiguous"));
    }
    Ok(())
}
