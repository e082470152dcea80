//! `mirrorball render`: the flags become the library's `RenderRequest`
//! (`mirrorball::render`), which plans, renders and writes.

use crate::error::CliError;
use crate::progress::Printer;
use crate::RenderArgs;
use mirrorball::render::RenderRequest;

/// `a`'s flags as the library's request.
pub fn request(a: &RenderArgs) -> Result<RenderRequest, CliError> {
    Ok(RenderRequest {
        scene: a.scene.clone(),
        output: a.output.clone(),
        object: a.object.clone(),
        tessellation: a.tessellation,
        env: a.env.clone(),
        input: crate::commands::input_plan(&a.input_args)?,
        env_as: a.env_as.clone(),
        env_size: a.env_size,
        mode: a.mode.clone(),
        attach: a.attach.clone(),
        filter: a.filter.clone(),
        material: a.material.clone(),
        tint: a.tint.clone(),
        f0: a.f0,
        eye: a.eye.clone(),
        target: a.target.clone(),
        up: a.up.clone(),
        fov: a.fov,
        ortho: a.ortho,
        fisheye: a.fisheye,
        fisheye_lens: a.fisheye_lens.clone(),
        near: a.near,
        far: a.far,
        size: a.size.clone(),
        ss: a.ss,
        exposure: a.exposure,
        tone: a.tone.clone(),
        no_background: a.no_background,
        pan_blur: a.pan_blur,
        aovs: a.aovs,
        diagnostics: a.diagnostics,
        turntable: a.turntable,
        given: a.given.clone(),
    })
}

pub fn run(a: RenderArgs) -> Result<(), CliError> {
    mirrorball::render::run(&request(&a)?, &Printer { quiet: a.quiet })
}
