//! numpy arrays to `Image`s and back: H×W×C pictures (C 3 or 4) with any leading
//! dimensions (a batch, a map's layers), float32, float16, uint8 or uint16, C-contiguous or
//! not. 8- and 16-bit codes are sRGB as the CLI reads PNG (io's own tables), or linear
//! (`linear=True`: code/255 or code/65535); alpha is always linear.

use crate::errors::request;
use half::f16;
use mirrorball::frames::pipe::SrgbTable;
use mirrorball_core::Image;
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

    fn of_name(name: &str) -> Option<Dtype> {
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
    /// The buffer of a single picture's texels back, for [`pictures_into`] to fill again.
    pub fn spare_of(maps: Vec<mirrorball_core::EnvMap>) -> Vec<f32> {
        match <[_; 1]>::try_from(maps) {
            Ok([map]) if map.layers().len() == 1 => map
                .into_layers()
                .pop()
                .map(Image::into_vec)
                .unwrap_or_default(),
            _ => Vec::new(),
        }
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

/// [`pictures`] into `spare` (an earlier call's buffer, from [`Pictures::into_spare`]) when
/// it is the right length: no allocation and no page faults for the frames of a loop.
pub fn pictures_into(
    obj: &Bound<'_, PyAny>,
    arg: &str,
    lead_ok: std::ops::RangeInclusive<usize>,
    linear: bool,
    invalid: Invalid,
    spare: Vec<f32>,
) -> PyResult<Pictures> {
    let arr = obj.cast::<PyUntypedArray>().map_err(|_| {
        let ty = obj
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_default();
        PyTypeError::new_err(format!(
            "{arg}: a numpy array (H×W×C, C 3 or 4) is needed, not {ty} (torch: tensor.numpy())"
        ))
    })?;
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
    let lead = shape[..nd - 3].to_vec();
    let count: usize = lead.iter().product();
    let per = h * w * c;
    let name: String = arr.dtype().getattr("name")?.extract()?;
    let dtype = Dtype::of_name(&name).ok_or_else(|| {
        PyTypeError::new_err(format!(
            "{arg}: dtype {name}; give {TAKEN} (for example {arg}.astype(np.float32))"
        ))
    })?;
    let total = count * per;
    let spare = match spare.len() == total {
        true => spare,
        false => Vec::new(),
    };
    let mut nonfinite = 0;
    let flat: Vec<f32> = match dtype {
        Dtype::F32 => floats::<f32>(obj, |v| v, spare, &mut nonfinite)?,
        Dtype::F16 => floats::<f16>(obj, f16::to_f32, spare, &mut nonfinite)?,
        Dtype::U8 => {
            let (t, a) = (decode8(linear), alpha8());
            coded::<u8>(obj, c, |v| t[v as usize], |v| a[v as usize], spare)?
        }
        Dtype::U16 => {
            let t = decode16(linear);
            coded::<u16>(obj, c, |v| t[v as usize], |v| v as f32 / 65535.0, spare)?
        }
    };
    if matches!(dtype, Dtype::F32 | Dtype::F16) {
        match invalid {
            Invalid::Keep => {}
            Invalid::Raise => {
                let bad = nonfinite;
                if bad > 0 {
                    return Err(request(
                        arg,
                        format!("{bad} NaN or infinite values (invalid='zero' sets them to 0, as the CLI does; invalid='keep' keeps them)"),
                    ));
                }
            }
            // Core's rule, after the pictures are made.
            Invalid::Zero => {}
        }
    }
    let images = if count == 1 {
        vec![Image::from_vec(w as u32, h as u32, c, flat).expect("checked shape")]
    } else {
        flat.chunks_exact(per)
            .map(|p| Image::from_vec(w as u32, h as u32, c, p.to_vec()).expect("checked shape"))
            .collect()
    };
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

/// The floats of a float array, in C order (any strides).
/// The floats of a float array, in C order (any strides), into `out` (reused when it has
/// the array's length), counting the NaN and infinite ones into `nonfinite` as they are
/// copied (while in cache).
fn floats<T: Element + Copy + Sync>(
    obj: &Bound<'_, PyAny>,
    f: fn(T) -> f32,
    mut out: Vec<f32>,
    nonfinite: &mut usize,
) -> PyResult<Vec<f32>> {
    let a: PyReadonlyArrayDyn<'_, T> = obj.extract()?;
    // `as_slice` takes Fortran order too: C order only, else the logical iteration.
    let c_order = a.is_c_contiguous();
    let out = match a.as_slice().ok().filter(|_| c_order) {
        Some(s) => {
            if out.len() != s.len() {
                out = vec![0.0; s.len()];
            }
            const BLOCK: usize = 1 << 15;
            *nonfinite = out
                .par_chunks_mut(BLOCK)
                .zip(s.par_chunks(BLOCK))
                .map(|(d, s)| {
                    for (d, &v) in d.iter_mut().zip(s) {
                        *d = f(v);
                    }
                    d.iter().filter(|v| !v.is_finite()).count()
                })
                .sum();
            out
        }
        None => {
            let v: Vec<f32> = a.as_array().iter().map(|&v| f(v)).collect();
            *nonfinite = v.iter().filter(|v| !v.is_finite()).count();
            v
        }
    };
    Ok(out)
}

/// The linear values of an integer array of `c` channels, colour through `colour`, alpha
/// through `alpha`.
fn coded<T: Element + Copy + Sync>(
    obj: &Bound<'_, PyAny>,
    c: usize,
    colour: impl Fn(T) -> f32 + Sync,
    alpha: impl Fn(T) -> f32 + Sync,
    out: Vec<f32>,
) -> PyResult<Vec<f32>> {
    let a: PyReadonlyArrayDyn<'_, T> = obj.extract()?;
    let decode = |i: usize, v: T| {
        if c == 4 && i % 4 == 3 {
            alpha(v)
        } else {
            colour(v)
        }
    };
    let c_order = a.is_c_contiguous();
    Ok(match a.as_slice().ok().filter(|_| c_order) {
        Some(s) => {
            let mut out = out;
            if out.len() != s.len() {
                out = vec![0f32; s.len()];
            }
            out.par_chunks_mut(c * 4096)
                .zip(s.par_chunks(c * 4096))
                .for_each(|(o, s)| {
                    for (i, (o, &v)) in o.iter_mut().zip(s).enumerate() {
                        *o = decode(i, v);
                    }
                });
            out
        }
        None => a
            .as_array()
            .iter()
            .enumerate()
            .map(|(i, &v)| decode(i, v))
            .collect(),
    })
}

fn decode8(linear: bool) -> &'static [f32] {
    static LINEAR: OnceLock<Vec<f32>> = OnceLock::new();
    match linear {
        false => &mirrorball_io::srgb8_to_linear()[..],
        true => LINEAR.get_or_init(|| (0..256).map(|k| k as f32 / 255.0).collect()),
    }
}

fn alpha8() -> &'static [f32] {
    decode8(true)
}

fn decode16(linear: bool) -> &'static [f32] {
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

/// Encodes `src` (interleaved, `c` channels) into `out` as `T`.
pub fn encode_into<T: Send>(
    src: &[f32],
    c: usize,
    out: &mut [T],
    f: impl Fn(usize, f32) -> T + Sync,
) {
    out.par_chunks_mut(c * 4096)
        .zip(src.par_chunks(c * 4096))
        .for_each(|(o, s)| {
            for (o, s) in o.chunks_exact_mut(c).zip(s.chunks_exact(c)) {
                for (i, (o, &v)) in o.iter_mut().zip(s).enumerate() {
                    *o = f(i, v);
                }
            }
        });
}

/// The texels `src` (interleaved, `c` channels) as a flat vector of `dtype`.
fn encode_all<T: Send + Default + Clone>(
    src: &[&[f32]],
    c: usize,
    f: impl Fn(usize, f32) -> T + Sync,
) -> Vec<T> {
    let total: usize = src.iter().map(|s| s.len()).sum();
    let mut out = vec![T::default(); total];
    let mut at = 0;
    for s in src {
        encode_into(s, c, &mut out[at..at + s.len()], &f);
        at += s.len();
    }
    out
}

/// The per-channel encoder of `dtype`.
pub fn encoder_u8(c: usize, linear: bool) -> impl Fn(usize, f32) -> u8 + Sync {
    move |ch, v| {
        if linear || (c == 4 && ch == 3) {
            encode_linear(v, 255.0) as u8
        } else {
            encode8_srgb(v)
        }
    }
}

pub fn encoder_u16(c: usize, linear: bool) -> impl Fn(usize, f32) -> u16 + Sync {
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
    let parts: Vec<&[f32]> = parts.to_vec();
    match dtype {
        Dtype::F32 => {
            let v = py.detach(|| crate::threads::run(|| encode_all(&parts, c, |_, v| v)));
            shaped(py, v, shape)
        }
        Dtype::F16 => {
            let v = py
                .detach(|| crate::threads::run(|| encode_all(&parts, c, |_, v| f16::from_f32(v))));
            shaped(py, v, shape)
        }
        Dtype::U8 => {
            let v =
                py.detach(|| crate::threads::run(|| encode_all(&parts, c, encoder_u8(c, linear))));
            shaped(py, v, shape)
        }
        Dtype::U16 => {
            let v =
                py.detach(|| crate::threads::run(|| encode_all(&parts, c, encoder_u16(c, linear))));
            shaped(py, v, shape)
        }
    }
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
