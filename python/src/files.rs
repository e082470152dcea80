//! `read` and `write`: every format mirrorball knows, through the `mirrorball` library's
//! `load` and `save` (what the CLI calls: the projection recorded in the file or guessed
//! from its shape, OpenEXR's `envmap` tag, layouts, cube containers, atomic writes).

use crate::arrays::{self, Dtype, Invalid};
use crate::convert::{layout_arg, spec_arg, Source};
use crate::errors::{self, by_fault, request};
use crate::threads::run;
use mirrorball::io::{ExrCompression, Format, Limits, Precision, WriteOptions};
use mirrorball::save::SaveOptions;
use mirrorball_core::Choice;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// A path argument: `str` or `os.PathLike`.
pub fn path_arg(path: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    path.extract::<PathBuf>().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "path: a str or os.PathLike is needed, not {}",
            path.get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        ))
    })
}

/// The library's error as Python's, by fault.
pub fn lib_error(e: mirrorball::Error) -> PyErr {
    by_fault(e.fault, e.message)
}

/// A path as the library takes it (its names are text).
pub fn path_text(path: &Path) -> PyResult<String> {
    path.to_str()
        .map(str::to_string)
        .ok_or_else(|| request("path", format!("{}: not valid UTF-8", path.display())))
}

/// Reads an environment map (OpenEXR, Radiance HDR, PNG, JPEG, WebP, KTX2, DDS; one file a
/// layer with "{face}" in the name) as the CLI reads it, and returns `(array, info)`. The
/// array is the map's layers: H×W×C for one-layer projections, L×H×W×C otherwise (a cube's
/// six faces in OpenGL order +X −X +Y −Y +Z −Z), linear light (8- and 16-bit files decoded
/// from sRGB), as `dtype` (default float32; uint8/uint16 are sRGB codes unless
/// `linear=True`). The projection is `src` (the CLI's --from) if given, else what the file
/// records, else OpenEXR's envmap tag, else guessed from the shape; `src_layout` is the
/// CLI's --in-layout. `info`: "projection" (the text `convert`'s `src` takes), "layout"
/// ("separate": pass it as `src_layout`), "decided", "description", "invalid" (NaN,
/// infinite and negative values in the file, kept as read).
///
/// Raises FileNotFoundError / PermissionError / IsADirectoryError as Python does, and
/// mirrorball.InputError (a ValueError) for a file whose content cannot be read.
#[pyfunction]
#[pyo3(signature = (path, *, src=None, src_layout=None, dtype=None, linear=false))]
pub fn read<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    src: Option<&str>,
    src_layout: Option<&str>,
    dtype: Option<&Bound<'py, PyAny>>,
    linear: bool,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let path = path_arg(path)?;
    let from = src.map(|s| spec_arg("src", s)).transpose()?;
    let layout = layout_arg("src_layout", src_layout)?;
    let dtype = arrays::dtype_arg(py, dtype)?.unwrap_or(Dtype::F32);
    let text = path_text(&path)?;
    if !text.contains(mirrorball::load::FACE) {
        errors::check_readable(&path)?;
    }
    let source = py
        .detach(|| run(|| mirrorball::load(&text, from.as_ref(), layout, &Limits::default())))
        .map_err(lib_error)?;
    let env = &source.env;
    let info = PyDict::new(py);
    info.set_item("projection", env.projection().to_string())?;
    info.set_item("layout", mirrorball::Layout::Separate.to_string())?;
    info.set_item("decided", &source.decided)?;
    info.set_item("description", &source.description)?;
    info.set_item("invalid", source.invalid)?;
    let array = arrays::map_to_numpy(py, env, mirrorball::Layout::Separate, dtype, linear)?;
    Ok((array, info))
}

/// `write`'s arguments about the container, checked against `format`: the precision asked
/// for and OpenEXR's compression.
fn container_args(
    format: Format,
    precision: Option<&str>,
    compression: Option<&str>,
    quality: i64,
    mips: bool,
) -> PyResult<(Option<Precision>, ExrCompression)> {
    let precision = precision
        .map(|p| p.parse::<Precision>().map_err(|e| request("precision", e)))
        .transpose()?;
    if let Some(p) = precision.filter(|p| !format.precisions().contains(p)) {
        return Err(request(
            "precision",
            format!("{} does not apply to {}", p.name(), format.name()),
        ));
    }
    let exr_compression = compression
        .map(|c| {
            c.parse::<ExrCompression>()
                .map_err(|e| request("compression", e))
        })
        .transpose()?
        .unwrap_or_default();
    if compression.is_some() && format != Format::Exr {
        return Err(request("compression", "applies to .exr only"));
    }
    if mips && !format.is_cube_container() {
        return Err(request("mips", "applies to .ktx2 and .dds only"));
    }
    if !(1..=100).contains(&quality) {
        return Err(request("quality", format!("{quality} is outside 1..=100")));
    }
    Ok((precision, exr_compression))
}

/// Writes a map to `path` as the CLI's `convert` writes its output (the extension picks the
/// container), atomically, and returns the files written. With `projection` (the text
/// `convert` takes) the array is a map of it: H×W×C (layers packed in one picture are
/// unpacked as `src_layout` says or its shape suggests) or its layers L×H×W×C; the file
/// records the projection, and `layout` packs a multi-layer map ("hcross" by default for
/// cubes; "separate" writes one file a layer, "{face}" in the name or _px … added). Without
/// `projection`, an H×W×C picture is written as it is. `precision`: "half", "float", "8",
/// "16" (default: the array's dtype where the container takes it, else the container's
/// own). `compression`: OpenEXR's. `mips`: a KTX2/DDS cube's mip chain. uint8/uint16
/// arrays are sRGB codes unless `linear=True`. `invalid="keep"` writes NaN and infinities
/// where the container holds them.
#[pyfunction]
#[pyo3(signature = (path, array, *, projection=None, layout=None, precision=None, compression=None, quality=92, mips=false, src_layout=None, linear=false, invalid="raise"))]
#[allow(clippy::too_many_arguments)]
pub fn write(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    array: &Bound<'_, PyAny>,
    projection: Option<&str>,
    layout: Option<&str>,
    precision: Option<&str>,
    compression: Option<&str>,
    quality: i64,
    mips: bool,
    src_layout: Option<&str>,
    linear: bool,
    invalid: &str,
) -> PyResult<Vec<String>> {
    let path = path_arg(path)?;
    let text = path_text(&path)?;
    let invalid = arrays::invalid_arg(invalid)?;
    let format =
        mirrorball::save::check_container(&text).map_err(|e| request("path", e.message))?;
    let (precision, exr_compression) =
        container_args(format, precision, compression, quality, mips)?;
    let layout = layout_arg("layout", layout)?;
    let write_precision = |dtype: Dtype| {
        precision.or_else(|| {
            let p = match dtype {
                Dtype::F32 => Precision::Float,
                Dtype::F16 => Precision::Half,
                Dtype::U8 => Precision::U8,
                Dtype::U16 => Precision::U16,
            };
            format.precisions().contains(&p).then_some(p)
        })
    };
    let Some(projection) = projection else {
        let pics = arrays::pictures(array, "array", 0..=0, linear, invalid)?;
        if format.is_cube_container() {
            return Err(request(
                "projection",
                format!("{} holds a cube map: say projection=\"cube\" and give its faces (6×H×W×C) or a packed picture", format.name()),
            ));
        }
        let opts = WriteOptions {
            precision: write_precision(pics.dtype),
            exr_compression,
            jpeg_quality: quality as u8,
            declared: None,
            note: None,
        };
        let picture = pics.images.into_iter().next().expect("one picture");
        py.detach(|| run(|| mirrorball::io::write_image(&path, &picture, &opts)))
            .map_err(errors::io)?;
        return Ok(vec![text]);
    };
    let source = Source::named("projection", projection, src_layout)?;
    let layers = source.layers();
    let separate = layers > 1
        && array
            .getattr("ndim")
            .and_then(|n| n.extract::<usize>())
            .ok()
            == Some(4);
    let source = match separate {
        true => Source::named("projection", projection, Some("separate"))?,
        false => source,
    };
    let lead = *source.lead().start();
    let pics = arrays::pictures(array, "array", lead..=lead, linear, invalid)?;
    let opts = SaveOptions {
        layout,
        write: WriteOptions {
            precision: write_precision(pics.dtype),
            exr_compression,
            jpeg_quality: quality as u8,
            declared: None,
            note: None,
        },
        mips,
        keep_invalid: invalid == Invalid::Keep,
    };
    let env = source.maps("array", pics)?.remove(0);
    if let Some(dir) = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty() && !d.is_dir())
    {
        let e = std::fs::metadata(dir)
            .err()
            .unwrap_or_else(|| std::io::Error::from(std::io::ErrorKind::NotADirectory));
        return Err(errors::os_error(dir, &e));
    }
    let saved = py
        .detach(|| run(|| mirrorball::save(&env, &text, &opts)))
        .map_err(lib_error)?;
    Ok(saved
        .files
        .iter()
        .map(|p| p.display().to_string())
        .collect())
}
