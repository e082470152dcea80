//! What `render` writes: each frame (PNG/JPEG through the tone curve, which io encodes as
//! sRGB; EXR/HDR linear, times 2^exposure), the diagnostic channels and the texture-space
//! diagram beside it, and a turntable's frames as one animated PNG.

use super::plan::{MeshSource, RenderPlan};
use crate::error::Error;
use crate::guard::Files;
use crate::hooks::Hooks;
use mirrorball_core::Image;
use mirrorball_io::{Format, Precision, WriteOptions};
use mirrorball_render::tone;
use mirrorball_render::{Rendered, Scene};
use std::path::{Path, PathBuf};

/// The diagnostic channels' file tags, in the order `--aovs` documents them.
const AOV_TAGS: [&str; 4] = ["st", "reflect", "normal", "depth"];

/// `out.png` → `out-{tag}.exr`.
fn sibling(path: &Path, tag: &str, ext: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    path.with_file_name(format!("{stem}-{tag}.{ext}"))
}

fn ext_of(f: Format) -> &'static str {
    match f {
        Format::Exr => "exr",
        Format::Hdr => "hdr",
        Format::Jpeg => "jpg",
        _ => "png",
    }
}

impl RenderPlan {
    /// The file of frame `i`: the output itself, or `NAME-0000.EXT`… for a turntable.
    pub fn frame_path(&self, i: usize) -> PathBuf {
        if self.frames > 1 {
            sibling(&self.output, &format!("{i:04}"), ext_of(self.format))
        } else {
            self.output.clone()
        }
    }

    /// Whether the frames are also written as one animated PNG.
    pub fn animated(&self) -> bool {
        self.frames > 1 && self.format == Format::Png
    }

    /// The animated PNG's file.
    fn animation_path(&self) -> PathBuf {
        sibling(&self.output, "turntable", "png")
    }

    /// Says that `p` was written.
    fn wrote(&self, p: &Path, hooks: &dyn Hooks) {
        hooks.note(&format!("wrote {}", p.display()));
    }
}

/// Every file the render reads and writes, checked so that no output is an input or
/// another output.
pub fn files(plan: &RenderPlan) -> Files {
    let mut f = Files::new();
    if let Some(e) = &plan.env_file {
        f.input_arg("the environment", e);
    }
    if let Some(s) = &plan.scene {
        f.input("the scene", s);
    }
    for o in &plan.objects {
        if let MeshSource::File(p) = &o.source {
            f.input("the mesh", p);
        }
    }
    f.named("the output", &plan.output);
    for i in 0..plan.frames as usize {
        let path = plan.frame_path(i);
        if plan.diagnostics {
            f.output("the diagnostics", sibling(&path, "diag", "png"));
        }
        if plan.aovs {
            for tag in AOV_TAGS {
                f.output("a diagnostic channel", sibling(&path, tag, "exr"));
            }
        }
        f.output("the output", path);
    }
    if plan.animated() {
        f.output("the animation", plan.animation_path());
    }
    f
}

/// About how many bytes the render writes: each frame (four channels, before compression),
/// its diagnostic channels (four RGB `f32` EXRs) and diagram, and the animated PNG.
pub fn bytes(plan: &RenderPlan) -> u64 {
    let pixels = plan.camera.width as u64 * plan.camera.height as u64;
    let mut frame = plan.format.bytes_estimate(pixels, 4, None);
    if plan.aovs {
        frame += 4 * Format::Exr.bytes_estimate(pixels, 3, Some(Precision::Float));
    }
    if plan.diagnostics {
        frame += Format::Png.bytes_estimate(1024 * 1024, 4, None);
    }
    if plan.animated() {
        frame += Format::Png.bytes_estimate(pixels, 4, None);
    }
    frame.saturating_mul(plan.frames as u64)
}

/// A frame's colour in the output's format: for PNG and JPEG exposed and tone-mapped, for
/// EXR and HDR linear times 2^exposure; JPEG and HDR without alpha.
fn write_colour(
    path: &Path,
    img: &Image,
    plan: &RenderPlan,
    hooks: &dyn Hooks,
) -> Result<(), Error> {
    let img = match plan.format {
        Format::Png | Format::Jpeg => tone::to_display(img, plan.exposure, plan.tone),
        _ => {
            let mut i = img.clone();
            let k = plan.exposure.exp2();
            if k != 1.0 {
                i.scale(k);
            }
            i
        }
    };
    let img = if matches!(plan.format, Format::Jpeg | Format::Hdr) {
        img.with_channels(3)
    } else {
        img
    };
    let report = crate::fit::measure_picture(&img, plan.format.storage(None));
    let keep = [crate::fit::exposure_advice(
        "--exposure",
        plan.exposure,
        &report,
    )];
    if let Some(line) = report.line(&path.display().to_string(), &keep) {
        hooks.note(&line);
    }
    mirrorball_io::write_image(path, &img, &WriteOptions::default())?;
    Ok(())
}

/// Frame `i` and, as the plan asks, its diagram and diagnostic channels.
pub fn write_frame(
    plan: &RenderPlan,
    scene: &Scene,
    i: usize,
    f: &Rendered,
    hooks: &dyn Hooks,
) -> Result<(), Error> {
    let path = plan.frame_path(i);
    write_colour(&path, &f.color, plan, hooks)?;
    plan.wrote(&path, hooks);
    if plan.diagnostics {
        let cam = plan.frame_camera(i);
        let d = mirrorball_render::texture_space_diagram(scene, &cam, &plan.settings, f, 512)
            .map_err(|e| Error::from(e).context("--diagnostics"))?;
        let p = sibling(&path, "diag", "png");
        mirrorball_io::write_image(&p, &d, &WriteOptions::default())?;
        plan.wrote(&p, hooks);
    }
    if let Some(aovs) = f.aovs.as_ref().filter(|_| plan.aovs) {
        let opts = WriteOptions {
            precision: Some(Precision::Float),
            ..WriteOptions::default()
        };
        let images = [&aovs.st_face, &aovs.reflected, &aovs.normal, &aovs.depth];
        for (tag, img) in AOV_TAGS.into_iter().zip(images) {
            let p = sibling(&path, tag, "exr");
            mirrorball_io::write_image(&p, img, &opts)?;
            plan.wrote(&p, hooks);
        }
    }
    Ok(())
}

/// The turntable's frames, tone-mapped, as one animated PNG at 24 frames a second.
pub fn write_animation(
    plan: &RenderPlan,
    frames: &[Image],
    hooks: &dyn Hooks,
) -> Result<(), Error> {
    if frames.is_empty() {
        return Ok(());
    }
    let p = plan.animation_path();
    mirrorball_io::write_apng(&p, frames, 24)?;
    hooks.note(&format!(
        "wrote {} (animated PNG, {} frames)",
        p.display(),
        frames.len()
    ));
    Ok(())
}
