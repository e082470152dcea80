//! Animated PNG (APNG, the `acTL`/`fcTL`/`fdAT` chunks of the PNG 3rd edition), written
//! through the `png` crate: display-ready frames, looping.

use crate::Error;
use mirrorball_core::color::srgb8_f32;
use mirrorball_core::Image;
use std::path::Path;

/// Writes `frames` (linear light, display-ready: already in `[0, 1]`, RGB or RGBA, all one
/// size) to `path` as an 8-bit sRGB RGBA animated PNG that loops forever at `fps` frames
/// per second, atomically. Colour is encoded with
/// [`srgb8_f32`](mirrorball_core::color::srgb8_f32); alpha (1 for RGB frames) is clamped
/// and rounded to 8 bits.
///
/// # Panics
/// If `frames` is empty.
pub fn write_apng(path: &Path, frames: &[Image], fps: u16) -> Result<(), Error> {
    let (w, h) = (frames[0].width(), frames[0].height());
    let fail = |e: png::EncodingError| Error::input(path, e.to_string());
    crate::atomic_write(path, |out| {
        let mut enc = png::Encoder::new(out, w, h);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        enc.set_animated(frames.len() as u32, 0).map_err(fail)?;
        enc.set_frame_delay(1, fps).map_err(fail)?;
        let mut wr = enc.write_header().map_err(fail)?;
        let mut bytes = Vec::with_capacity(w as usize * h as usize * 4);
        for f in frames {
            let c = f.channels();
            bytes.clear();
            bytes.extend(f.data().chunks_exact(c).flat_map(|p| {
                let a = if c == 4 { p[3] } else { 1.0 };
                [
                    srgb8_f32(p[0]),
                    srgb8_f32(p[1]),
                    srgb8_f32(p[2]),
                    (a.clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
                ]
            }));
            wr.write_image_data(&bytes).map_err(fail)?;
        }
        wr.finish().map_err(fail)
    })
}
