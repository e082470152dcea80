//! `read` and `write`: every format io knows, through io's `read`, `write_image` and
//! `write_cube` (atomic writes; the projection recorded where the container has a place).

use crate::arrays::{self, Dtype};
use crate::convert::{layout_arg, spec_arg};
use crate::errors::{self, request};
use crate::threads::run;
use mirrorball_core::{guess, Choice, EnvMap, Image, Layout, Stereo, WorldProjection};
use mirrorball_io::{ExrCompression, Format, Limits, MapInfo, Precision, WriteOptions};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// A path argument: `str` or `os.PathLike`.
fn path_arg(path: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
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

/// read(path, *, dtype="float32", linear=False)
/// --
///
/// Reads an environment map (OpenEXR, Radiance HDR, PNG, JPEG, WebP, KTX2, DDS) and returns
/// `(array, info)`: the picture as the file holds it, H×W×C (a KTX2/DDS cube: its six
/// level-0 faces, 6×H×W×C in OpenGL order +X −X +Y −Y +Z −Z), linear light (8- and 16-bit
/// files decoded from sRGB as the CLI reads them), as `dtype` (default float32; uint8 and
/// uint16 are sRGB codes unless `linear=True`). `info` is a dict: "projection" (the text
/// `convert`'s `src` takes: what the file records, else guessed from the shape as the CLI
/// does), "layout" (`src_layout`), "decided" (how), "format", "description", "invalid"
/// (NaN, infinite and negative values in the file, kept as read).
///
/// Raises FileNotFoundError / PermissionError / IsADirectoryError as Python does, and
/// mirrorball.InputError (a ValueError) for a file whose content cannot be read.
#[pyfunction]
#[pyo3(signature = (path, *, dtype=None, linear=false))]
pub fn read<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    dtype: Option<&Bound<'py, PyAny>>,
    linear: bool,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let path = path_arg(path)?;
    let dtype = arrays::dtype_arg(py, dtype)?.unwrap_or(Dtype::F32);
    errors::check_readable(&path)?;
    let loaded = py
        .detach(|| run(|| mirrorball_io::read(&path, &Limits::default())))
        .map_err(errors::io)?;
    let invalid = loaded.invalid();
    let layers = loaded.layers;
    let first = layers
        .first()
        .ok_or_else(|| errors::InputError::new_err(format!("{}: no image", path.display())))?;
    let (w, h, c) = (first.width(), first.height(), first.channels());
    let info = PyDict::new(py);
    let (projection, layout, decided): (Option<String>, Option<String>, String) =
        match (&loaded.recorded, layers.len()) {
            (Some(Ok(r)), _) => {
                let n = r.projection.layer_count();
                let layout = match (layers.len(), r.layout) {
                    (6, _) => Some(Layout::Separate),
                    (_, Some(l)) => Some(l),
                    _ => Layout::from_extent(w, h, n).map(|g| g.0),
                };
                if r.stereo != Stereo::Mono {
                    info.set_item("stereo", r.stereo.to_string())?;
                }
                (
                    Some(r.projection.to_string()),
                    layout.map(|l| l.to_string()),
                    "recorded in the file".into(),
                )
            }
            (Some(Err(e)), _) => (None, None, format!("unreadable record: {e}")),
            (None, 6) => (
                Some("cube".into()),
                Some(Layout::Separate.to_string()),
                "six faces in the container".into(),
            ),
            (None, _) => match guess(w, h, loaded.declared) {
                Some(g) => {
                    let tag = match (loaded.declared, loaded.format) {
                        (Some(k), Format::Exr) => format!("; the file's envmap={k} tag (OpenEXR's convention, which the CLI turns into mirrorball's) is not followed here"),
                        _ => String::new(),
                    };
                    (
                        Some(g.kind.to_string()),
                        Some(g.layout.to_string()),
                        format!("guessed {} {}: {}{tag}", g.kind, g.layout, g.reason),
                    )
                }
                None => (None, None, format!("cannot tell the projection of a {w}x{h} picture")),
            },
        };
    info.set_item("projection", projection)?;
    info.set_item("layout", layout)?;
    info.set_item("decided", decided)?;
    info.set_item("format", loaded.format.name())?;
    info.set_item("description", loaded.description)?;
    info.set_item("invalid", invalid)?;
    // Every layer the same channels (a cube container's are).
    let layers: Vec<Image> = layers.iter().map(|l| l.with_channels(c)).collect();
    let parts: Vec<&[f32]> = layers.iter().map(|l| l.data()).collect();
    let mut shape = vec![h as usize, w as usize, c];
    if layers.len() > 1 {
        shape.insert(0, layers.len());
    }
    let array = arrays::to_numpy(py, &parts, &shape, c, dtype, linear)?;
    Ok((array, info))
}

/// write(path, array, *, projection=None, layout=None, precision=None, compression=None, quality=92, linear=False, invalid="raise")
/// --
///
/// Writes `array` to `path` (the extension picks the container, as the CLI's), atomically.
/// H×W×C is one picture; 6×H×W×C is a cube's faces in OpenGL order (KTX2/DDS hold them as
/// a cube; other containers pack them by `layout`, default "hcross"); a paraboloid's
/// 2×H×W×C likewise ("hstrip"). `projection` (the text `convert` takes) and the layout are
/// recorded in the file where the container has a place. `precision`: "half", "float",
/// "8", "16" (default: the array's dtype where the container takes it, else the
/// container's own). `compression`: OpenEXR's ("zip" default, "none", "piz", …). uint8
/// and uint16 arrays are sRGB codes unless `linear=True`.
#[pyfunction]
#[pyo3(signature = (path, array, *, projection=None, layout=None, precision=None, compression=None, quality=92, linear=false, invalid="raise"))]
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
    linear: bool,
    invalid: &str,
) -> PyResult<Vec<String>> {
    let path = path_arg(path)?;
    let invalid = arrays::invalid_arg(invalid)?;
    let format = Format::from_path(&path).ok_or_else(|| {
        let exts: Vec<&str> = Format::ALL
            .iter()
            .filter(|f| f.is_written())
            .map(|f| f.extension())
            .collect();
        request(
            "path",
            format!("{}: unknown extension (use {})", path.display(), exts.join(" ")),
        )
    })?;
    if !format.is_written() {
        return Err(request(
            "path",
            format!("{}: {} is read-only here", path.display(), format.name()),
        ));
    }
    let precision = precision
        .map(|p| p.parse::<Precision>().map_err(|e| request("precision", e)))
        .transpose()?;
    if let Some(p) = precision {
        if !format.precisions().contains(&p) {
            return Err(request(
                "precision",
                format!("{} does not apply to {}", p.name(), format.name()),
            ));
        }
    }
    let exr_compression = compression
        .map(|c| c.parse::<ExrCompression>().map_err(|e| request("compression", e)))
        .transpose()?
        .unwrap_or_default();
    if compression.is_some() && format != Format::Exr {
        return Err(request("compression", "applies to .exr only"));
    }
    if !(1..=100).contains(&quality) {
        return Err(request("quality", format!("{quality} is outside 1..=100")));
    }
    let layout = layout_arg("layout", layout)?;
    let pics = arrays::pictures(array, "array", 0..=1, linear, invalid)?;
    let precision = precision.or_else(|| {
        let p = match pics.dtype {
            Dtype::F32 => Precision::Float,
            Dtype::F16 => Precision::Half,
            Dtype::U8 => Precision::U8,
            Dtype::U16 => Precision::U16,
        };
        format.precisions().contains(&p).then_some(p)
    });
    let (w, h) = (pics.width(), pics.height());
    let layers = pics.lead.first().copied().unwrap_or(1);
    let mut opts = WriteOptions {
        precision,
        exr_compression,
        jpeg_quality: quality as u8,
        declared: None,
    };
    let written = vec![path.display().to_string()];
    if format.is_cube_container() {
        if layers != 6 {
            return Err(request(
                "array",
                format!(
                    "{} holds a cube: give its six faces as 6×H×W×C, not {:?}",
                    format.name(),
                    [&pics.lead[..], &[h as usize, w as usize, pics.channels()]].concat()
                ),
            ));
        }
        if w != h {
            return Err(request("array", format!("cube faces must be square, not {w}x{h}")));
        }
        if let Some(p) = projection {
            let proj = spec_arg("projection", p)?.build(None).map_err(|e| request("projection", e))?;
            if proj.layer_count() != 6 {
                return Err(request("projection", format!("{p}: KTX2 and DDS hold cube maps only")));
            }
            opts.declared = Some(MapInfo {
                projection: proj,
                layout: None,
                stereo: Stereo::Mono,
            });
        }
        let faces = pics.images;
        py.detach(|| run(|| mirrorball_io::write_cube(&path, &[faces], &opts)))
            .map_err(errors::io)?;
        return Ok(written);
    }
    let (picture, declared) = if layers > 1 {
        let Some(p) = projection else {
            return Err(request(
                "projection",
                format!("{layers} layers are packed into one picture by their projection's layout: say it (\"cube\")"),
            ));
        };
        let proj = spec_arg("projection", p)?.build(None).map_err(|e| request("projection", e))?;
        if proj.layer_count() != layers {
            return Err(request(
                "array",
                format!("{layers} layers, but a {} map has {}", proj.kind(), proj.layer_count()),
            ));
        }
        let l = layout.unwrap_or_else(|| Layout::default_for(proj.kind()));
        if l == Layout::Separate {
            return Err(request(
                "layout",
                "'separate' is one file a layer: write each layer to its own file",
            ));
        }
        let env = EnvMap::new(proj, pics.images).map_err(|e| request("array", e))?;
        let picture = run(|| l.pack(&env)).ok_or_else(|| request("layout", format!("{l} does not fit {layers} layers")))?;
        (picture, Some((proj, l)))
    } else {
        let img = pics.images.into_iter().next().expect("one picture");
        let declared = projection
            .map(|p| -> PyResult<_> {
                let proj = spec_arg("projection", p)?;
                let n = proj.kind.default_projection().layer_count();
                let l = match layout {
                    Some(l) => l,
                    None => Layout::from_extent(w, h, n).map(|g| g.0).ok_or_else(|| {
                        request("array", format!("a {w}x{h} picture fits no layout of a {} map", proj.kind))
                    })?,
                };
                let proj = proj.build(Some((w, h))).map_err(|e| request("projection", e))?;
                Ok((proj, l))
            })
            .transpose()?;
        (img, declared)
    };
    opts.declared = declared.map(|(projection, layout)| MapInfo {
        projection,
        layout: Some(layout),
        stereo: Stereo::Mono,
    });
    py.detach(|| run(|| mirrorball_io::write_image(&path, &picture, &opts)))
        .map_err(errors::io)?;
    Ok(written)
}
