//! Exposure and tone curves, for pictures meant for screens (PNG). The result stays linear
//! light in `[0, 1]`; `mirrorball-io` applies the sRGB encoding when it writes 8- or 16-bit
//! files. EXR output skips this and keeps the linear radiance.

use mirrorball_core::{color, Choice, Image};

/// How linear radiance is squeezed into `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tone {
    /// Clip at 1.
    Clamp,
    /// Reinhard's `x / (1 + x)` on each channel ([`color::reinhard`]).
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve ([`color::aces_narkowicz`]).
    #[default]
    Aces,
}

impl Choice for Tone {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Tone::Aces, &["aces", "filmic"]),
        (Tone::Reinhard, &["reinhard"]),
        (Tone::Clamp, &["clamp", "none", "linear", "clip"]),
    ];
}
mirrorball_core::choice_traits!(Tone);

impl Tone {
    /// The curve at `x ≥ 0`.
    #[inline]
    pub fn apply(self, x: f32) -> f32 {
        let x = if x.is_finite() { x.max(0.0) } else { 0.0 };
        match self {
            Tone::Clamp => x.min(1.0),
            Tone::Reinhard => color::reinhard(x),
            Tone::Aces => color::aces_narkowicz(x),
        }
    }
}

/// `image × 2^exposure` through `tone`, colour channels only (alpha is kept).
///
/// ```
/// use mirrorball_core::Image;
/// use mirrorball_render::tone::{to_display, Tone};
/// let mut img = Image::new(1, 1, 4);
/// img.data_mut().copy_from_slice(&[0.25, 2.0, 0.5, 0.5]);
/// // One stop up doubles the light; clamping clips at 1; alpha is kept.
/// assert_eq!(to_display(&img, 1.0, Tone::Clamp).get(0, 0), &[0.5, 1.0, 1.0, 0.5]);
/// // Reinhard's x/(1 + x) takes 1 to ½.
/// assert_eq!(to_display(&img, 2.0, Tone::Reinhard).get(0, 0)[0], 0.5);
/// ```
pub fn to_display(image: &Image, exposure: f32, tone: Tone) -> Image {
    let k = exposure.exp2();
    let mut out = image.clone();
    let c = out.channels();
    for px in out.data_mut().chunks_exact_mut(c) {
        for v in &mut px[..3] {
            *v = tone.apply(*v * k);
        }
    }
    out
}
