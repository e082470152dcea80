//! `views`: a panorama cut into a rig of perspective views with the camera files COLMAP and
//! nerfstudio read, through the library's `views` (the CLI's `mirrorball views`, the same
//! files, byte for byte).

use crate::convert::{layout_arg, spec_arg};
use crate::errors::{self, request};
use crate::files::{lib_error, path_arg, path_text};
use crate::threads::run;
use mirrorball::load::InputPlan;
use mirrorball::views::{ViewsPlan, ViewsRequest};
use pyo3::prelude::*;

/// `size`: an int (the width) or a `(width, height)` pair.
fn size_arg(size: Option<&Bound<'_, PyAny>>) -> PyResult<Option<(i64, Option<i64>)>> {
    let Some(size) = size else {
        return Ok(None);
    };
    if let Ok(w) = size.extract::<i64>() {
        return Ok(Some((w, None)));
    }
    size.extract::<(i64, i64)>()
        .map(|(w, h)| Some((w, Some(h))))
        .map_err(|_| {
            request(
                "size",
                "an int (the width) or a (width, height) pair is needed",
            )
        })
}

/// Cuts the panorama at `src` (a file, or a sequence's pattern: `frames/%04d.jpg`,
/// `frames/*.jpg`) into a rig of views written into the folder `out_dir`, as the CLI's
/// `mirrorball views SRC OUT_DIR` does (the same files, byte for byte): `images/VIEW/`,
/// `masks/VIEW/`, `sparse/0/` (the COLMAP model), `rig_config.json`, `transforms.json`.
/// `rig`: a preset ("cube", "cube-96", "ringN", …) or a .json file of views; `size`: each
/// view's width, or `(width, height)`; `format`: "png", "png16", "jpg" or "exr"; `masks`:
/// every view's mask, even when all valid; `mask`: a mask drawn on the panorama;
/// `projection`/`layout`: the CLI's --from/--in-layout. A file in `out_dir` that
/// mirrorball did not write is refused unless `overwrite`. Returns the files written.
#[pyfunction]
#[pyo3(signature = (src, out_dir, *, rig="cube", size=None, format="png", masks=false, mask=None, max_samples=None, overwrite=false, projection=None, layout=None))]
#[allow(clippy::too_many_arguments)]
pub fn views(
    py: Python<'_>,
    src: &Bound<'_, PyAny>,
    out_dir: &Bound<'_, PyAny>,
    rig: &str,
    size: Option<&Bound<'_, PyAny>>,
    format: &str,
    masks: bool,
    mask: Option<&Bound<'_, PyAny>>,
    max_samples: Option<u32>,
    overwrite: bool,
    projection: Option<&str>,
    layout: Option<&str>,
) -> PyResult<Vec<String>> {
    let src = path_text(&path_arg(src)?)?;
    let out_dir = path_text(&path_arg(out_dir)?)?;
    let mask = mask
        .map(|m| path_arg(m).and_then(|p| path_text(&p)))
        .transpose()?;
    // A missing file raises Python's own FileNotFoundError (a pattern is the library's).
    let plain = !src.contains(['%', '*', '?', '[']) && !src.contains(mirrorball::load::FACE);
    if plain {
        errors::check_readable(std::path::Path::new(&src))?;
    }
    let mut request = ViewsRequest::new(&src, &out_dir);
    request.input_plan = InputPlan {
        from: projection.map(|p| spec_arg("projection", p)).transpose()?,
        layout: layout_arg("layout", layout)?,
        keep_invalid: false,
    };
    request.rig = rig.to_string();
    request.size = size_arg(size)?;
    request.format = format.to_string();
    request.masks = masks;
    request.mask = mask;
    if let Some(n) = max_samples {
        request.max_samples = n;
    }
    request.overwrite = overwrite;
    let plan = ViewsPlan::new(&request).map_err(lib_error)?;
    let written = py
        .detach(|| run(|| mirrorball::views::run(&plan, &mirrorball::Quiet)))
        .map_err(lib_error)?;
    Ok(written
        .files
        .iter()
        .map(|p| p.display().to_string())
        .collect())
}

/// Cuts a panorama held as an array (H×W×C, or L×H×W×C with `src_layout="separate"`; its
/// projection `src`) into the rig's views in memory, as `views` makes the files' pictures
/// (the same rig, sizes and antialiasing): a list, one dict a view, in the rig's order:
/// "name", "image" (H×W×C of `dtype`, default the array's), "model" ("PINHOLE" or
/// "OPENCV_FISHEYE", k1..k4 = 0), "K" (3×3 intrinsics, pixel centres at half-integers) and
/// "R" (3×3 `cam_from_world` in COLMAP's world, mirrorball's (x, −y, −z); every view at
/// the panorama's centre).
#[pyfunction]
#[pyo3(signature = (array, *, src="latlong", rig="cube", size=None, max_samples=None, src_layout=None, dtype=None, linear=false, invalid="raise"))]
#[allow(clippy::too_many_arguments)]
pub fn cut_views<'py>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    src: &str,
    rig: &str,
    size: Option<&Bound<'py, PyAny>>,
    max_samples: Option<u32>,
    src_layout: Option<&str>,
    dtype: Option<&Bound<'py, PyAny>>,
    linear: bool,
    invalid: &str,
) -> PyResult<Vec<Bound<'py, pyo3::types::PyDict>>> {
    use numpy::{PyArray1, PyArrayMethods};
    let source = crate::convert::Source::new(src, src_layout)?;
    let want = crate::arrays::dtype_arg(py, dtype)?;
    // The array's own dtype unless `dtype` asks for another (float32 for any other).
    let dtype = want
        .or_else(|| {
            let name = array
                .getattr("dtype")
                .and_then(|d| d.getattr("name"))
                .ok()?;
            crate::arrays::Dtype::of_name(&name.extract::<String>().ok()?)
        })
        .unwrap_or(crate::arrays::Dtype::F32);
    let env = crate::lighting::one_map(array, &source, linear, invalid)?;
    let mut request = ViewsRequest::new("", "");
    request.rig = rig.to_string();
    request.size = size_arg(size)?;
    if let Some(n) = max_samples {
        request.max_samples = n;
    }
    let views = py
        .detach(|| run(|| mirrorball::views::cut(&env, &request)))
        .map_err(lib_error)?;
    let matrix = |m: [f64; 9]| -> PyResult<Bound<'py, PyAny>> {
        Ok(PyArray1::from_vec(py, m.to_vec())
            .reshape([3, 3])?
            .into_any())
    };
    views
        .into_iter()
        .map(|(cam, image)| {
            let c = image.channels();
            let shape = [image.height() as usize, image.width() as usize, c];
            let picture = crate::arrays::to_numpy(py, &[image.data()], &shape, c, dtype, linear)?;
            let (fx, fy) = cam.focal;
            let (cx, cy) = cam.centre;
            let r = cam.colmap_cam_from_world();
            let d = pyo3::types::PyDict::new(py);
            d.set_item("name", &cam.name)?;
            d.set_item("image", picture)?;
            d.set_item("model", cam.model.name())?;
            d.set_item("K", matrix([fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0])?)?;
            let rows = r.transpose().to_cols_array(); // row-major
            d.set_item("R", matrix(rows)?)?;
            Ok(d)
        })
        .collect()
}
