//! `mirrorball prefilter`: the flags become the library's `PrefilterRequest`
//! (`mirrorball::prefilter`), which plans, prefilters and writes.

use crate::error::CliError;
use crate::progress::Printer;
use crate::PrefilterArgs;
use mirrorball::prefilter::PrefilterRequest;

/// `a`'s flags as the library's request.
pub fn request(a: &PrefilterArgs) -> Result<PrefilterRequest, CliError> {
    Ok(PrefilterRequest {
        input: a.input.clone(),
        output: a.output.clone(),
        lobe: a.lobe.clone(),
        size: a.size,
        to: a.to.clone(),
        levels: a.levels,
        mapping: a.mapping.clone(),
        exponents: a.exponents.clone(),
        samples: a.samples,
        cube_size: a.cube_size,
        compress: a.compress.clone(),
        sh_window: a.sh_window.clone(),
        irradiance: a.irradiance.clone(),
        sh: a.sh.clone(),
        no_sh: a.no_sh,
        preview: a.preview.clone(),
        no_preview: a.no_preview,
        preview_exposure: a.preview_exposure,
        lut: a.lut.clone(),
        lut_size: a.lut_size,
        overwrite: a.overwrite,
        layout: a.layout.clone(),
        precision: a.precision.clone(),
        input_plan: crate::commands::input_plan(&a.input_args)?,
    })
}

pub fn run(a: PrefilterArgs) -> Result<(), CliError> {
    mirrorball::prefilter::run(&request(&a)?, &Printer { quiet: a.quiet })
}
