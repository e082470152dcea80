//! Exposure and tone curves, for pictures meant for screens (PNG). The result stays linear
//! light in `[0, 1]`; `mirrorball-io` applies the sRGB encoding when it writes 8- or 16-bit
//! files. EXR output skips this and keeps the linear radiance.

use mirrorball_core::{Choice, Image};

/// How linear radiance is squeezed into `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tone {
    /// Clip at 1.
    Clamp,
    /// Reinhard's `x / (1 + x)` on each channel.
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve,
    /// `x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`, clipped to `[0, 1]`.
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
            Tone::Reinhard => x / (1.0 + x),
            Tone::Aces => (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0),
        }
    }
}

/// `image × 2^exposure` through `tone`, colour channels only (alpha is kept).
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
