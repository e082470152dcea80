//! Texel encodings for GPU containers (KTX2, KTX1, DDS): how one face of one mip level,
//! linear `f32` RGB(A), becomes the bytes a GPU samples, and back.
//!
//! | [`Encoding`] | bytes | what it holds | error | module |
//! | --- | --- | --- | --- | --- |
//! | `Rgba16F` | 8 a texel | binary16 R G B A, ≤ 65504 | ½ ulp of half (2⁻¹¹ relative) | here |
//! | `Rgba32F` | 16 a texel | binary32 R G B A | none | here |
//! | `Rgb9E5` | 4 a texel | 9-bit mantissas, shared 5-bit exponent, ≤ 65408 | 2⁻¹⁰ of the texel's largest channel | [`shared_exp`] |
//! | `B10G11R11` | 4 a texel | unsigned 11/11/10-bit floats, ≤ 65024/64512 | 2⁻⁷ (R, G), 2⁻⁶ (B) relative | [`packed_float`] |
//! | `Rgbd` | 4 a texel | Babylon.js RGBD, ≤ 255 | 8-bit, gamma 2.2 | [`ldr8`] |
//! | `Rgbm` | 4 a texel | three.js RGBM, range 6 | 8-bit linear | [`ldr8`] |
//! | `Bc6hUnsigned` | 16 a 4×4 block | BC6H UF16 (Intel ISPC encoder), ≤ 65504 | lossy, see BENCHMARKS | [`bc6h`] |
//! | `Bc6hSigned` | 16 a 4×4 block | BC6H SF16 (mode 11 encoder here), ≤ ±65504 | lossy | [`bc6h`] |
//!
//! What each encoding (and each flat file's code) can hold is one table, [`range`]: every
//! encoder writes a value through [`Range::fit`], so no finite value becomes an infinity.
//!
//! No file I/O: the containers live in `mirrorball-io`, which calls [`Encoding::encode`]
//! per face and level and [`Encoding::decode`] when reading.

#![warn(missing_docs)]

pub mod bc6h;
pub mod ldr8;
pub mod packed_float;
pub mod range;
pub mod shared_exp;

pub use bc6h::Effort;
use half::f16;
use mirrorball_core::Image;
pub use range::{Clipped, Range, Storage};
use std::fmt;

/// How the texels of one image are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Encoding {
    /// Four binary16 floats, R G B A (alpha 1 for RGB images).
    #[default]
    Rgba16F,
    /// Four binary32 floats, R G B A.
    Rgba32F,
    /// `E5B9G9R9_UFLOAT_PACK32`: shared-exponent RGB in 32 bits.
    Rgb9E5,
    /// `B10G11R11_UFLOAT_PACK32`: unsigned 11-, 11- and 10-bit floats in 32 bits.
    B10G11R11,
    /// RGBD in 8-bit RGBA (Babylon.js).
    Rgbd,
    /// RGBM in 8-bit RGBA, range [`ldr8::RGBM_RANGE`] (three.js, PlayCanvas).
    Rgbm,
    /// BC6H, unsigned (UF16): no negative values.
    Bc6hUnsigned,
    /// BC6H, signed (SF16).
    Bc6hSigned,
}

impl mirrorball_core::Choice for Encoding {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Encoding::Rgba16F, &["rgba16f", "half", "f16"]),
        (Encoding::Rgba32F, &["rgba32f", "float", "f32"]),
        (Encoding::Rgb9E5, &["rgb9e5", "e5b9g9r9", "shared-exponent"]),
        (Encoding::B10G11R11, &["b10g11r11", "r11g11b10", "rg11b10"]),
        (Encoding::Rgbd, &["rgbd"]),
        (Encoding::Rgbm, &["rgbm"]),
        (
            Encoding::Bc6hUnsigned,
            &["bc6h", "bc6h-uf16", "bc6h-unsigned"],
        ),
        (Encoding::Bc6hSigned, &["bc6h-sf16", "bc6h-signed"]),
    ];
}
mirrorball_core::choice_traits!(Encoding);

/// A request an encoding cannot carry out, found before any work.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EncodeError(pub String);

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for EncodeError {}

impl Encoding {
    /// Texels on a side of one block: 4 for BC6H, 1 otherwise.
    pub fn block_size(self) -> u32 {
        match self {
            Encoding::Bc6hUnsigned | Encoding::Bc6hSigned => 4,
            _ => 1,
        }
    }

    /// Bytes of one block (of one texel when [`Encoding::block_size`] is 1).
    pub fn block_bytes(self) -> usize {
        match self {
            Encoding::Rgba16F => 8,
            Encoding::Rgba32F | Encoding::Bc6hUnsigned | Encoding::Bc6hSigned => 16,
            _ => 4,
        }
    }

    /// Whether the encoding is block-compressed.
    pub fn is_block_compressed(self) -> bool {
        self.block_size() > 1
    }

    /// Bytes of one `width`×`height` image: whole blocks, partial ones padded.
    pub fn image_bytes(self, width: u32, height: u32) -> usize {
        let b = self.block_size();
        width.div_ceil(b) as usize * height.div_ceil(b) as usize * self.block_bytes()
    }

    /// Channels of a decoded image: 4 for RGBA16F/RGBA32F, 3 otherwise (RGBD's and RGBM's
    /// alpha is part of the colour).
    pub fn channels(self) -> usize {
        match self {
            Encoding::Rgba16F | Encoding::Rgba32F => 4,
            _ => 3,
        }
    }

    /// A short name for people: "RGBA16F", "BC6H (unsigned)".
    pub fn label(self) -> &'static str {
        match self {
            Encoding::Rgba16F => "RGBA16F",
            Encoding::Rgba32F => "RGBA32F",
            Encoding::Rgb9E5 => "RGB9E5",
            Encoding::B10G11R11 => "B10G11R11",
            Encoding::Rgbd => "RGBD 8-bit",
            Encoding::Rgbm => "RGBM 8-bit",
            Encoding::Bc6hUnsigned => "BC6H (unsigned)",
            Encoding::Bc6hSigned => "BC6H (signed)",
        }
    }

    /// Refuses what this encoding cannot hold, before any work: negative (or NaN) values as
    /// unsigned BC6H. The other unsigned encodings clamp negative values to 0 as their
    /// specifications say.
    pub fn check(self, image: &Image) -> Result<(), EncodeError> {
        if self == Encoding::Bc6hUnsigned {
            let c = image.channels();
            let bad = image
                .data()
                .chunks_exact(c)
                .flat_map(|px| &px[..3])
                .filter(|v| v.is_nan() || **v < 0.0)
                .count();
            if bad > 0 {
                return Err(EncodeError(format!(
                    "{bad} colour values are negative or NaN, which unsigned BC6H cannot hold; \
                     use signed BC6H (bc6h-sf16) or clamp the map first"
                )));
            }
        }
        Ok(())
    }

    /// The work of encoding `texels` texels, in [`mirrorball_core::work`]'s units: what
    /// [`Encoding::encode_with`] adds to its counter (`Effort::Basic` for unsigned BC6H;
    /// fitted with the prefilter's costs to the pace `bench/progress_eta.py --pace`
    /// measures).
    pub fn work(self, texels: u64) -> u64 {
        let per_texel = match self {
            Encoding::Bc6hUnsigned => 650,
            Encoding::Bc6hSigned => 500,
            _ => 20,
        };
        texels * per_texel
    }

    /// Encodes `image` (RGB or RGBA, linear) into `out`, replacing its contents with
    /// [`Encoding::image_bytes`] bytes: texels in rows, top row first, or 4×4 blocks in rows.
    /// Values are written as [`Range::fit`] of the encoding's range makes them: a finite
    /// value past the range as its end, never an infinity. Unsigned BC6H uses
    /// [`Effort::Basic`]; see [`Encoding::encode_with`].
    pub fn encode(self, image: &Image, out: &mut Vec<u8>) {
        self.encode_with(image, Effort::default(), out);
    }

    /// [`Encoding::encode`] with the unsigned BC6H encoder's effort chosen.
    pub fn encode_with(self, image: &Image, effort: Effort, out: &mut Vec<u8>) {
        match self {
            Encoding::Bc6hUnsigned => return bc6h::encode_unsigned(image, effort, out),
            Encoding::Bc6hSigned => return bc6h::encode_signed(image, out),
            _ => {}
        }
        out.clear();
        out.reserve(self.image_bytes(image.width(), image.height()));
        let c = image.channels();
        let range = Storage::Texels(self).range();
        for px in image.data().chunks_exact(c) {
            let rgb = [px[0], px[1], px[2]];
            match self {
                Encoding::Rgba16F | Encoding::Rgba32F => {
                    let rgba = [px[0], px[1], px[2], if c == 4 { px[3] } else { 1.0 }];
                    for (k, v) in rgba.into_iter().enumerate() {
                        if self == Encoding::Rgba16F {
                            let v = range.fit(k, v);
                            out.extend_from_slice(&f16::from_f32(v).to_le_bytes());
                        } else {
                            out.extend_from_slice(&v.to_le_bytes());
                        }
                    }
                }
                Encoding::Rgb9E5 => out.extend_from_slice(&shared_exp::encode(rgb).to_le_bytes()),
                Encoding::B10G11R11 => {
                    out.extend_from_slice(&packed_float::encode(rgb).to_le_bytes())
                }
                Encoding::Rgbd => out.extend_from_slice(&ldr8::rgbd_encode(rgb)),
                Encoding::Rgbm => out.extend_from_slice(&ldr8::rgbm_encode(rgb)),
                Encoding::Bc6hUnsigned | Encoding::Bc6hSigned => unreachable!("handled above"),
            }
        }
        mirrorball_core::work::add(self.work(image.width() as u64 * image.height() as u64));
    }

    /// Decodes one `width`×`height` image of [`Encoding::image_bytes`] bytes into linear
    /// `f32`s with [`Encoding::channels`] channels.
    ///
    /// # Panics
    /// If `bytes` is shorter than the image needs (callers check sizes against the file).
    pub fn decode(self, bytes: &[u8], width: u32, height: u32) -> Image {
        let n = width as usize * height as usize;
        let bytes = &bytes[..self.image_bytes(width, height)];
        let word = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        let rgba = |b: &[u8]| [b[0], b[1], b[2], b[3]];
        let data: Vec<f32> = match self {
            Encoding::Rgba16F => bytes
                .chunks_exact(2)
                .map(|b| f16::from_le_bytes([b[0], b[1]]).to_f32())
                .collect(),
            Encoding::Rgba32F => bytes
                .chunks_exact(4)
                .map(|b| f32::from_bits(word(b)))
                .collect(),
            Encoding::Rgb9E5 => bytes
                .chunks_exact(4)
                .flat_map(|b| shared_exp::decode(word(b)))
                .collect(),
            Encoding::B10G11R11 => bytes
                .chunks_exact(4)
                .flat_map(|b| packed_float::decode(word(b)))
                .collect(),
            Encoding::Rgbd => bytes
                .chunks_exact(4)
                .flat_map(|b| ldr8::rgbd_decode(rgba(b)))
                .collect(),
            Encoding::Rgbm => bytes
                .chunks_exact(4)
                .flat_map(|b| ldr8::rgbm_decode(rgba(b)))
                .collect(),
            Encoding::Bc6hUnsigned => bc6h::decode(bytes, width, height, false),
            Encoding::Bc6hSigned => bc6h::decode(bytes, width, height, true),
        };
        debug_assert_eq!(data.len(), n * self.channels());
        Image::from_vec(width, height, self.channels(), data)
            .expect("decoded length matches the image size")
    }
}
