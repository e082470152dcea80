//! `prefilter`, `sh9` and `bake`: the library's in-memory chain (`mirrorball::prefilter`'s
//! `shape` and `chain`, what the CLI's `prefilter` makes its files of), `sh::project`, and
//! the bake crate's `Bake`, the same calls in the same order as the CLI's `bake` makes them.

use crate::arrays::{self, Dtype};
use crate::convert::{spec_arg, Source};
use crate::errors::{by_fault, request};
use crate::files::lib_error;
use crate::threads::run;
use mirrorball::prefilter::{chain, shape, ChainRequest};
use mirrorball::Quiet;
use mirrorball_bake::{Bake, BakeOptions, Engine};
use mirrorball_core::{EnvMap, Layout, WorldProjection};
use mirrorball_filter::{sh, IrradianceMethod, LobeKind, PrefilterOptions, RoughnessMapping};
use mirrorball_io::{Effort, Encoding};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use std::path::PathBuf;

/// One map from an array argument (no batch).
pub fn one_map(
    array: &Bound<'_, PyAny>,
    source: &Source,
    linear: bool,
    invalid: &str,
) -> PyResult<EnvMap> {
    let invalid = arrays::invalid_arg(invalid)?;
    let lead = match source.separate_layers() {
        true => 1..=1,
        false => 0..=0,
    };
    let pics = arrays::pictures(array, "array", lead, linear, invalid)?;
    Ok(source.maps("array", pics)?.remove(0))
}

/// Prefiltered lighting as a mip chain: the CLI's `mirrorball prefilter`, bit for bit, one
/// array per level (laid out by `layout` as `convert` does: "hcross" for cubes by default,
/// "separate" for L×H×W×C). `lobe`: "lambert" (irradiance E/π), "phong" or "ggx".
/// `size`: level 0's (default: 32 for lambert, else the source's resolution, at most 512).
/// `levels`: how many (default: down to 1×1). `mapping`: roughness per level ("linear",
/// "ue4", "filament", or a comma-separated list). `samples`: importance samples per texel.
/// `cube_size`: the working cube's face. `irradiance`: "exact" or "sh" (lambert).
#[pyfunction]
#[pyo3(signature = (array, lobe, *, src="latlong", dst="cube", size=None, levels=None, mapping="linear", samples=128, cube_size=None, irradiance="exact", layout=None, src_layout=None, dtype=None, linear=false, invalid="raise"))]
#[allow(clippy::too_many_arguments)]
pub fn prefilter<'py>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    lobe: &str,
    src: &str,
    dst: &str,
    size: Option<i64>,
    levels: Option<usize>,
    mapping: &str,
    samples: u32,
    cube_size: Option<u32>,
    irradiance: &str,
    layout: Option<&str>,
    src_layout: Option<&str>,
    dtype: Option<&Bound<'py, PyAny>>,
    linear: bool,
    invalid: &str,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let source = Source::new(src, src_layout)?;
    let req = chain_request(
        lobe,
        dst,
        (size, levels, mapping),
        (samples, cube_size),
        irradiance,
    )?;
    let out = req.to;
    let layout = crate::convert::layout_arg("layout", layout)?
        .unwrap_or_else(|| Layout::default_for(out.kind()));
    if !layout.fits(out.layer_count()) {
        return Err(request(
            "layout",
            format!("{layout} does not fit a {} map", out.kind()),
        ));
    }
    let want = arrays::dtype_arg(py, dtype)?;
    let pics_dtype = array
        .getattr("dtype")
        .and_then(|d| d.getattr("name"))
        .and_then(|n| n.extract::<String>())
        .ok();
    let env = one_map(array, &source, linear, invalid)?;
    let dtype = want.unwrap_or(match pics_dtype.as_deref() {
        Some("float16") => Dtype::F16,
        Some("uint8") => Dtype::U8,
        Some("uint16") => Dtype::U16,
        _ => Dtype::F32,
    });
    let chain = py
        .detach(|| {
            run(|| {
                let shape = shape(&env, &req)?;
                chain(&env, &req, &shape, &Quiet)
            })
        })
        .map_err(lib_error)?
        .levels;
    chain
        .iter()
        .map(|level| arrays::map_to_numpy(py, level, layout, dtype, linear))
        .collect()
}

/// `prefilter`'s arguments as the library's chain request, each checked by its name.
fn chain_request(
    lobe: &str,
    dst: &str,
    (size, levels, mapping): (Option<i64>, Option<usize>, &str),
    (samples, cube_size): (u32, Option<u32>),
    irradiance: &str,
) -> PyResult<ChainRequest> {
    let kind = lobe.parse::<LobeKind>().map_err(|e| request("lobe", e))?;
    let out = spec_arg("dst", dst)?
        .build(None)
        .map_err(|e| request("dst", e))?;
    let mapping = RoughnessMapping::parse(mapping).ok_or_else(|| {
        request(
            "mapping",
            format!(
                "'{mapping}' is not linear, ue4, filament or a list of roughness values in [0, 1]"
            ),
        )
    })?;
    let method = irradiance
        .parse::<IrradianceMethod>()
        .map_err(|e| request("irradiance", e))?;
    if samples == 0 || samples > 65536 {
        return Err(request(
            "samples",
            format!("{samples} is outside 1..=65536"),
        ));
    }
    if let Some(c) = cube_size.filter(|c| !(1..=4096).contains(c)) {
        return Err(request("cube_size", format!("{c} is outside 1..=4096")));
    }
    if levels == Some(0) {
        return Err(request("levels", "0; give 1 or more"));
    }
    let size = match size {
        Some(s) if (1..=16384).contains(&s) => Some(s as u32),
        Some(s) => return Err(request("size", format!("{s} is outside 1..=16384"))),
        None => None,
    };
    Ok(ChainRequest {
        size,
        levels,
        mapping,
        irradiance: method,
        opts: PrefilterOptions {
            samples,
            cube_size,
            ..Default::default()
        },
        ..ChainRequest::new(kind, out)
    })
}

/// The radiance's nine spherical-harmonic coefficients (orthonormal real basis, world axes:
/// mirrorball_filter::sh), as a 9×3 float64 array, index l(l + 1) + m.
#[pyfunction]
#[pyo3(signature = (array, *, src="latlong", src_layout=None, linear=false, invalid="raise"))]
pub fn sh9<'py>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    src: &str,
    src_layout: Option<&str>,
    linear: bool,
    invalid: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let source = Source::new(src, src_layout)?;
    let env = one_map(array, &source, linear, invalid)?;
    let sh = py.detach(|| run(|| sh::project(&env)));
    let flat: Vec<f64> = sh.coeffs.iter().flatten().copied().collect();
    Ok(PyArray1::from_vec(py, flat).reshape([9, 3])?.into_any())
}

/// Image-based lighting baked for `engine` ("bevy", "three", "babylon", "gltf",
/// "filament", "unity", "unreal", "ktx2") into the folder `out_dir`: the CLI's
/// `mirrorball bake`, bit for bit (give `source` the name the CLI was given: it is recorded
/// in the files and the README). Returns the files written. `zstd`: the KTX2 level
/// (default 3 where the engine reads it; 0 turns it off).
#[pyfunction]
#[pyo3(signature = (array, engine, out_dir, *, src="latlong", size=256, encoding=None, effort="basic", zstd=None, background_size=None, samples=128, source="", overwrite=false, src_layout=None, linear=false, invalid="raise"))]
#[allow(clippy::too_many_arguments)]
pub fn bake(
    py: Python<'_>,
    array: &Bound<'_, PyAny>,
    engine: &str,
    out_dir: PathBuf,
    src: &str,
    size: i64,
    encoding: Option<&str>,
    effort: &str,
    zstd: Option<i32>,
    background_size: Option<u32>,
    samples: u32,
    source: &str,
    overwrite: bool,
    src_layout: Option<&str>,
    linear: bool,
    invalid: &str,
) -> PyResult<Vec<String>> {
    let src_source = Source::new(src, src_layout)?;
    let engine = engine.parse::<Engine>().map_err(|e| request("engine", e))?;
    let encoding = encoding
        .map(|e| e.parse::<Encoding>().map_err(|e| request("encoding", e)))
        .transpose()?;
    let effort = effort.parse::<Effort>().map_err(|e| request("effort", e))?;
    if !(1..=16384).contains(&size) {
        return Err(request("size", format!("{size} is outside 1..=16384")));
    }
    let takes_zstd = engine.describe().zstd;
    let zstd = match zstd {
        Some(0) => None,
        Some(l) if (1..=22).contains(&l) => Some(l),
        Some(l) => return Err(request("zstd", format!("{l} is outside 1..=22 (0: none)"))),
        None => takes_zstd.then_some(3),
    };
    if samples == 0 || samples > 65536 {
        return Err(request(
            "samples",
            format!("{samples} is outside 1..=65536"),
        ));
    }
    if out_dir.exists() && !out_dir.is_dir() {
        return Err(request(
            "out_dir",
            format!(
                "{}: a file; bake writes a folder of files",
                out_dir.display()
            ),
        ));
    }
    let opts = BakeOptions {
        size: size as u32,
        encoding,
        effort,
        zstd,
        mapping: None,
        source: source.to_string(),
        background_size,
        overwrite,
    };
    let bake_err = |e: mirrorball_bake::Error| by_fault(e.fault, e.message);
    let mut bake = Bake::new(engine, opts).map_err(bake_err)?;
    bake.check_folder(&out_dir).map_err(bake_err)?;
    let mut env = one_map(array, &src_source, linear, invalid)?;
    // As the CLI prepares a source: NaN, infinite and negative values set to 0.
    env.sanitize();
    bake.check(&env).map_err(bake_err)?;
    bake.fit(&env);
    let popts = PrefilterOptions {
        samples,
        ..Default::default()
    };
    let written = py
        .detach(|| {
            run(|| {
                let lighting = bake.lighting(&env, popts);
                bake.write_into(&lighting, &out_dir)
            })
        })
        .map_err(bake_err)?;
    Ok(written
        .files
        .iter()
        .map(|p| p.display().to_string())
        .collect())
}
