//! Raw video frames on standard input and output, back to back with no header, as ffmpeg's
//! `-f rawvideo` reads and writes them; the pixel formats keep ffmpeg's names.
//!
//! Integer formats carry sRGB-coded values (as mirrorball reads and writes 8- and 16-bit
//! PNG), so that a frame through a pipe and the same frame through a PNG file convert
//! alike; float formats carry linear light.

#[cfg(test)]
use super::packing::Packing;
use crate::error::Error;
use mirrorball_core::color::linear_to_srgb;
use mirrorball_core::{choice_traits, count_invalid, Choice, Codes, Image};
use mirrorball_simd::{x8_kernel, F32x8, I32x8, X8};
use rayon::prelude::*;
use std::io::{ErrorKind, Read, Write};
use std::sync::OnceLock;

/// A raw frame's pixel format, named as ffmpeg's `-pix_fmt`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixFmt {
    /// 8-bit sRGB R, G, B interleaved.
    Rgb24,
    /// 16-bit little-endian sRGB R, G, B interleaved.
    Rgb48le,
    /// 32-bit little-endian float linear R, G, B interleaved (FFmpeg 6 and later).
    Rgbf32le,
    /// 32-bit little-endian float linear planes G, B, R (FFmpeg 5's float RGB).
    Gbrpf32le,
}

impl Choice for PixFmt {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (PixFmt::Rgb24, &["rgb24"]),
        (PixFmt::Rgb48le, &["rgb48le", "rgb48"]),
        (PixFmt::Rgbf32le, &["rgbf32le", "rgbf32"]),
        (PixFmt::Gbrpf32le, &["gbrpf32le", "gbrpf32"]),
    ];
}
choice_traits!(PixFmt);

/// Texels encoded or decoded per parallel task.
const CHUNK: usize = 1 << 14;

impl PixFmt {
    /// The channel (0 red, 1 green, 2 blue) each plane of a planar `gbrpf32le` frame holds,
    /// in the frame's order: ffmpeg's G, B, R.
    pub const PLANES: [usize; 3] = [1, 2, 0];

    /// Bytes of one pixel.
    pub fn pixel_bytes(self) -> usize {
        match self {
            PixFmt::Rgb24 => 3,
            PixFmt::Rgb48le => 6,
            PixFmt::Rgbf32le | PixFmt::Gbrpf32le => 12,
        }
    }

    /// Bytes of a `w`×`h` frame.
    pub fn frame_bytes(self, w: u32, h: u32) -> usize {
        w as usize * h as usize * self.pixel_bytes()
    }

    /// Whether a frame of this format can be read as it is by a planned `Remap`
    /// ([`PixFmt::codes`]): the integer formats.
    pub fn has_codes(self) -> bool {
        matches!(self, PixFmt::Rgb24 | PixFmt::Rgb48le)
    }

    /// One `w`×`h` frame's bytes as the codes a `Remap` reads through the same table
    /// [`PixFmt::decode`] decodes them with (so the same linear values, to the bit); `None`
    /// for a float format, or bytes that are not one frame.
    pub fn codes(self, bytes: &[u8], w: u32, h: u32) -> Option<Codes<'_>> {
        match self {
            PixFmt::Rgb24 => Codes::u8(bytes, mirrorball_io::srgb8_to_linear(), (w, h)).ok(),
            PixFmt::Rgb48le => Codes::u16le(bytes, mirrorball_io::srgb16_to_linear(), (w, h)).ok(),
            PixFmt::Rgbf32le | PixFmt::Gbrpf32le => None,
        }
    }

    /// Decodes `bytes` (one `w`×`h` frame) into `img`, linear RGB. Returns how many values
    /// are NaN, infinite or negative (`mirrorball_core::count_invalid`, counted as each
    /// block is decoded): only a float format can hold one.
    pub fn decode(self, bytes: &[u8], img: &mut Image) -> u64 {
        let n = img.width() as usize * img.height() as usize;
        debug_assert_eq!(img.channels(), 3);
        debug_assert_eq!(bytes.len(), n * self.pixel_bytes());
        let data = img.data_mut();
        match self {
            PixFmt::Rgb24 => {
                let lut = mirrorball_io::srgb8_to_linear();
                data.par_chunks_mut(CHUNK * 3)
                    .zip(bytes.par_chunks(CHUNK * 3))
                    .for_each(|(d, s)| {
                        for (d, s) in d.iter_mut().zip(s) {
                            *d = lut[*s as usize];
                        }
                    });
                0
            }
            PixFmt::Rgb48le => {
                let lut = mirrorball_io::srgb16_to_linear();
                data.par_chunks_mut(CHUNK * 3)
                    .zip(bytes.par_chunks(CHUNK * 6))
                    .for_each(|(d, s)| {
                        for (d, s) in d.iter_mut().zip(s.chunks_exact(2)) {
                            *d = lut[u16::from_le_bytes([s[0], s[1]]) as usize];
                        }
                    });
                0
            }
            PixFmt::Rgbf32le => data
                .par_chunks_mut(CHUNK * 3)
                .zip(bytes.par_chunks(CHUNK * 12))
                .map(|(d, s)| {
                    for (d, s) in d.iter_mut().zip(s.chunks_exact(4)) {
                        *d = f32::from_le_bytes([s[0], s[1], s[2], s[3]]);
                    }
                    count_invalid(d, false)
                })
                .sum(),
            PixFmt::Gbrpf32le => {
                // Each channel's plane, in R, G, B order, found through ffmpeg's plane order.
                let plane = n * 4;
                let mut planes: [&[u8]; 3] = [&[]; 3];
                for (i, channel) in Self::PLANES.into_iter().enumerate() {
                    planes[channel] = &bytes[i * plane..(i + 1) * plane];
                }
                data.par_chunks_mut(CHUNK * 3)
                    .enumerate()
                    .map(|(k, d)| {
                        let at = k * CHUNK * 4;
                        for (i, t) in d.chunks_exact_mut(3).enumerate() {
                            let o = at + i * 4;
                            for (t, p) in t.iter_mut().zip(planes) {
                                *t = f32::from_le_bytes([p[o], p[o + 1], p[o + 2], p[o + 3]]);
                            }
                        }
                        count_invalid(d, false)
                    })
                    .sum()
            }
        }
    }

    /// Encodes `img` (RGB or RGBA; alpha is dropped) as one frame into `out`.
    #[cfg(test)]
    pub fn encode(self, img: &Image, out: &mut Vec<u8>) {
        Packing::single(img.width(), img.height()).encode_layers(
            self,
            std::slice::from_ref(img),
            out,
        );
    }

    /// Encodes texels (`c` channels each, the first three R, G, B) into `dst`, this
    /// interleaved format's bytes for as many pixels; `table`: the format's sRGB codes.
    #[inline]
    pub fn encode_texels(self, table: Option<&SrgbTable>, src: &[f32], c: usize, dst: &mut [u8]) {
        let px = self.pixel_bytes();
        // RGB texels are their values in order, each one code: eight at a time, the few
        // left over one by one (the same codes: `SrgbTable::codes_x8`).
        if let (PixFmt::Rgb24 | PixFmt::Rgb48le, Some(t), 3, Some(x8)) = (self, table, c, X8::get())
        {
            let bytes = px / 3;
            let done = encode_x8(x8, t, src, dst, bytes);
            for (d, &s) in dst[done * bytes..]
                .chunks_exact_mut(bytes)
                .zip(&src[done..])
            {
                if bytes == 1 {
                    d[0] = t.code8(s) as u8;
                } else {
                    d.copy_from_slice(&(t.code16(s) as u16).to_le_bytes());
                }
            }
            return;
        }
        match (self, table) {
            (PixFmt::Rgb24, Some(t)) => {
                for (d, s) in dst.chunks_exact_mut(px).zip(src.chunks_exact(c)) {
                    for k in 0..3 {
                        d[k] = t.code8(s[k]) as u8;
                    }
                }
            }
            (PixFmt::Rgb48le, Some(t)) => {
                for (d, s) in dst.chunks_exact_mut(px).zip(src.chunks_exact(c)) {
                    for k in 0..3 {
                        d[2 * k..2 * k + 2].copy_from_slice(&(t.code16(s[k]) as u16).to_le_bytes());
                    }
                }
            }
            (PixFmt::Rgbf32le, _) => {
                for (d, s) in dst.chunks_exact_mut(px).zip(src.chunks_exact(c)) {
                    for k in 0..3 {
                        d[4 * k..4 * k + 4].copy_from_slice(&s[k].to_le_bytes());
                    }
                }
            }
            _ => unreachable!("an interleaved format with its table"),
        }
    }
}

/// The sRGB encoding scaled to integer codes, fast: linear on the standard's linear
/// segment, and above it by the `f32` bit pattern from 2⁻⁹ (below the knee, 0.0031308) to 1.
///
/// 16-bit codes are piecewise linear in the bit pattern, 2⁹ pieces per octave (4609
/// entries): within a piece the curve `1.055 L^(1/2.4)` bends by at most `h²/8 · |f''|`,
/// with `h = L/2⁹`: `0.243/(8·2¹⁸) ≈ 1.2·10⁻⁷` of the value, under 0.01 of a code.
///
/// 8-bit codes are read straight off a table of 2¹² pieces per octave (36864 bytes), each
/// the code at its piece's centre: the code's slope is at most `255 · 1.055/2.4 · ln 2 ≈
/// 77.7` codes per octave, so a piece spans under 0.019 of a code and its centre is within
/// 0.0095 of every value in it.
///
/// Either way a code is the nearest one, or its neighbour for values within 0.01 of a code
/// of a rounding boundary (the exact encoder, a `powf` per value, is io's, for files).
pub struct SrgbTable {
    /// Code value (scaled, not rounded) at the start of each 2⁹-per-octave piece, and one
    /// past the end.
    at: Vec<f32>,
    /// For 8-bit codes: the code of each 2¹²-per-octave piece (as `f32`, for the eight-lane
    /// table lookup).
    direct: Vec<f32>,
    scale: f32,
}

/// The bit pattern of 2⁻⁹, where the tables start.
const TABLE_FROM: u32 = 0x3b00_0000;
/// Mantissa bits below a piece's index.
const PIECE_SHIFT: u32 = 14;
/// Mantissa bits below a direct 8-bit piece's index.
const DIRECT_SHIFT: u32 = 11;

impl SrgbTable {
    /// The table for codes `0..=scale` (255 or 65535).
    pub fn get(scale: f32) -> &'static SrgbTable {
        static T8: OnceLock<SrgbTable> = OnceLock::new();
        static T16: OnceLock<SrgbTable> = OnceLock::new();
        let cell = if scale <= 255.0 { &T8 } else { &T16 };
        cell.get_or_init(|| {
            let code = |bits: u32| linear_to_srgb(f32::from_bits(bits) as f64) * scale as f64;
            let pieces = ((1.0f32.to_bits() - TABLE_FROM) >> PIECE_SHIFT) as usize;
            let at = (0..=pieces)
                .map(|k| code(TABLE_FROM + ((k as u32) << PIECE_SHIFT)) as f32)
                .collect();
            let direct = if scale <= 255.0 {
                let n = (1.0f32.to_bits() - TABLE_FROM) >> DIRECT_SHIFT;
                (0..n)
                    .map(|k| {
                        let centre = TABLE_FROM + (k << DIRECT_SHIFT) + (1 << (DIRECT_SHIFT - 1));
                        code(centre).round() as f32
                    })
                    .collect()
            } else {
                Vec::new()
            };
            SrgbTable { at, direct, scale }
        })
    }

    /// The code of linear `l`, clamped to `[0, scale]` (NaN gives 0).
    #[cfg(test)]
    pub fn code(&self, l: f32) -> u32 {
        if self.direct.is_empty() {
            self.code16(l)
        } else {
            self.code8(l)
        }
    }

    /// The linear segment's code of `l <= 0.0031308` (0 for NaN and negatives: `max`
    /// keeps 0 over NaN), or `None` above it; `scale` at and above 1.
    #[inline(always)]
    fn ends(&self, l: f32) -> Option<u32> {
        if l.is_nan() || l <= mirrorball_core::color::SRGB_LINEAR_KNEE as f32 {
            return Some(
                (l.max(0.0) * (mirrorball_core::color::SRGB_SLOPE as f32 * self.scale) + 0.5)
                    as u32,
            );
        }
        (l >= 1.0).then_some(self.scale as u32)
    }

    /// [`SrgbTable::code`] of an 8-bit table.
    #[inline(always)]
    pub fn code8(&self, l: f32) -> u32 {
        if let Some(c) = self.ends(l) {
            return c;
        }
        self.direct[((l.to_bits() - TABLE_FROM) >> DIRECT_SHIFT) as usize] as u32
    }

    /// [`SrgbTable::code8`] or [`SrgbTable::code16`] (the table's) of eight values at once:
    /// the same arithmetic lane by lane, so the same codes (tested).
    #[inline(always)]
    fn codes_x8(&self, x8: X8, l: F32x8) -> I32x8 {
        let zero = x8.splat(0.0);
        let knee = x8.splat(mirrorball_core::color::SRGB_LINEAR_KNEE as f32);
        let slope = x8.splat(mirrorball_core::color::SRGB_SLOPE as f32 * self.scale);
        // `ends`: NaN and negatives to 0 (`gt` is false for NaN).
        let linear = l.gt(zero).select(l, zero) * slope + x8.splat(0.5);
        let rel = l.to_bits() - x8.splat_i32(TABLE_FROM as i32);
        // Lanes outside the table's range read a clamped entry, and are not chosen.
        let table = if self.direct.is_empty() {
            let k = rel.shift_right(PIECE_SHIFT);
            let t = (rel & x8.splat_i32((1 << PIECE_SHIFT) - 1)).to_f32()
                * x8.splat(1.0 / (1 << PIECE_SHIFT) as f32);
            let (a, b) = (
                x8.gather(&self.at, k),
                x8.gather(&self.at, k + x8.splat_i32(1)),
            );
            a + (b - a) * t + x8.splat(0.5)
        } else {
            x8.gather(&self.direct, rel.shift_right(DIRECT_SHIFT))
        };
        let above = l.ge(x8.splat(1.0)).select(x8.splat(self.scale), table);
        l.gt(knee).select(above, linear).trunc_i32()
    }

    /// [`SrgbTable::code`] of a 16-bit table.
    #[inline(always)]
    pub fn code16(&self, l: f32) -> u32 {
        if let Some(c) = self.ends(l) {
            return c;
        }
        let rel = l.to_bits() - TABLE_FROM;
        let k = (rel >> PIECE_SHIFT) as usize;
        let t = (rel & ((1 << PIECE_SHIFT) - 1)) as f32 * (1.0 / (1 << PIECE_SHIFT) as f32);
        let (a, b) = (self.at[k], self.at[k + 1]);
        (a + (b - a) * t + 0.5) as u32
    }
}

x8_kernel! {
    /// Encodes the values of `src` eight at a time with `t` into `dst`, `bytes` (1 or 2,
    /// little-endian) a code, as far as whole groups of eight fit both; returns how many.
    fn encode_x8(x8: X8, t: &SrgbTable, src: &[f32], dst: &mut [u8], bytes: usize) -> usize {
        let n = src.len().min(dst.len() / bytes) / 8 * 8;
        for (s, d) in src[..n].chunks_exact(8).zip(dst.chunks_exact_mut(8 * bytes)) {
            let codes = t.codes_x8(x8, x8.load(s)).to_array();
            if bytes == 1 {
                for (d, c) in d.iter_mut().zip(codes) {
                    *d = c as u8;
                }
            } else {
                for (d, c) in d.chunks_exact_mut(2).zip(codes) {
                    d.copy_from_slice(&(c as u16).to_le_bytes());
                }
            }
        }
        n
    }
}

/// Reads one frame of `buf.len()` bytes: `Ok(false)` at the end of the stream before the
/// frame's first byte, an input error when it ends inside the frame.
pub fn read_frame(r: &mut impl Read, buf: &mut [u8], frame: u64) -> Result<bool, Error> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) if got == 0 => return Ok(false),
            Ok(0) => {
                return Err(Error::input(format!(
                    "standard input ended {got} bytes into frame {frame}, which needs {} (check --in-size and --pix-fmt against the stream)",
                    buf.len()
                )))
            }
            Ok(k) => got += k,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => {
                return Err(Error::system(format!(
                    "reading frame {frame} from standard input: {e}"
                )))
            }
        }
    }
    Ok(true)
}

/// Writes one encoded frame; a reader that has gone away is the system's fault, said so.
pub fn write_frame(w: &mut impl Write, bytes: &[u8], frame: u64) -> Result<(), Error> {
    w.write_all(bytes).and_then(|_| w.flush()).map_err(|e| {
        if e.kind() == ErrorKind::BrokenPipe {
            Error::system(format!(
                "standard output was closed by its reader before frame {frame}"
            ))
        } else {
            Error::system(format!("writing frame {frame} to standard output: {e}"))
        }
    })
}

/// A `WxH` size.
pub fn parse_size(flag: &str, s: &str) -> Result<(u32, u32), Error> {
    let bad = || {
        Error::request(format!(
            "{flag}: '{s}' is not WIDTHxHEIGHT (for example 4096x2048)"
        ))
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 || w > 65536 || h > 65536 {
        return Err(Error::request(format!(
            "{flag}: {w}x{h} is outside 1..=65536 on a side"
        )));
    }
    Ok((w, h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_srgb_codes_are_the_nearest_or_a_neighbour() {
        for scale in [255.0f32, 65535.0] {
            let t = SrgbTable::get(scale);
            let n = 1_000_000;
            let mut near_boundary = 0;
            for i in 0..=n {
                let l = (i as f32 / n as f32).powi(2) * 1.01;
                let real = linear_to_srgb(l.min(1.0) as f64) * scale as f64;
                let (exact, fast) = (real.round() as i64, t.code(l) as i64);
                if fast != exact {
                    // Only a neighbour, and only within 0.01 of a code of the boundary.
                    let off = (real - real.floor() - 0.5).abs();
                    assert!(
                        (fast - exact).abs() == 1 && off < 0.01,
                        "{l}: {fast} vs {exact} ({real}) of {scale}"
                    );
                    near_boundary += 1;
                }
            }
            assert!(near_boundary < n / 50, "{near_boundary} of {n} off by one");
            assert_eq!(t.code(f32::NAN), 0);
            assert_eq!(t.code(-1.0), 0);
            assert_eq!(t.code(7.0), scale as u32);
            assert_eq!(t.code(1.0), scale as u32);
            assert_eq!(t.code(0.0), 0);
        }
    }

    #[test]
    fn the_eight_lane_codes_are_the_scalar_ones() {
        // Every value class: NaN, infinities, negatives, zero, denormals, the linear
        // segment and its knee, each table piece's ends, and a dense sweep of [0, 1.1].
        let mut values = vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -1.0,
            -0.0,
            0.0,
            1e-40,
            f32::MIN_POSITIVE,
            0.0031308,
            f32::from_bits(0.0031308f32.to_bits() + 1),
            f32::from_bits(TABLE_FROM),
            f32::from_bits(TABLE_FROM - 1),
            f32::from_bits(1.0f32.to_bits() - 1),
            1.0,
            7.0,
        ];
        values.extend((0..=400_000).map(|i| (i as f32 / 400_000.0).powi(2) * 1.1));
        values.extend(
            (TABLE_FROM..1.0f32.to_bits())
                .step_by(4093)
                .map(f32::from_bits),
        );
        while values.len() % 8 != 0 {
            values.push(0.5);
        }
        for scale in [255.0f32, 65535.0] {
            let t = SrgbTable::get(scale);
            let x8 = X8::get();
            let Some(x8) = x8 else { return };
            for v in values.chunks_exact(8) {
                let got = t.codes_x8(x8, x8.load(v)).to_array();
                let want: [i32; 8] = std::array::from_fn(|k| t.code(v[k]) as i32);
                assert_eq!(got, want, "{v:?} at {scale}");
            }
            // And through the encoder, whose tail is scalar.
            let (fmt, bytes) = if scale > 255.0 {
                (PixFmt::Rgb48le, 2)
            } else {
                (PixFmt::Rgb24, 1)
            };
            let n = 3 * 1001;
            let mut dst = vec![0u8; n * bytes];
            fmt.encode_texels(Some(t), &values[..n], 3, &mut dst);
            for (k, &v) in values[..n].iter().enumerate() {
                let code = if bytes == 1 {
                    dst[k] as u32
                } else {
                    u16::from_le_bytes([dst[2 * k], dst[2 * k + 1]]) as u32
                };
                assert_eq!(code, t.code(v), "value {k}: {v}");
            }
        }
    }

    #[test]
    fn every_format_round_trips() {
        let mut img = Image::new(5, 3, 3);
        for (i, v) in img.data_mut().iter_mut().enumerate() {
            *v = mirrorball_core::color::srgb_to_linear((i % 17) as f64 / 16.0) as f32;
        }
        for f in [
            PixFmt::Rgb24,
            PixFmt::Rgb48le,
            PixFmt::Rgbf32le,
            PixFmt::Gbrpf32le,
        ] {
            let mut bytes = Vec::new();
            f.encode(&img, &mut bytes);
            assert_eq!(bytes.len(), f.frame_bytes(5, 3));
            let mut back = Image::new(5, 3, 3);
            f.decode(&bytes, &mut back);
            let tol = match f {
                PixFmt::Rgb24 => 1.0 / 255.0,
                PixFmt::Rgb48le => 1e-4,
                _ => 0.0,
            };
            for (a, b) in img.data().iter().zip(back.data()) {
                assert!((a - b).abs() <= tol, "{f}: {a} vs {b}");
            }
        }
        // gbrpf32le is planar: G, B, R (ffmpeg's order), each plane 15 texels of 4 bytes.
        let mut bytes = Vec::new();
        PixFmt::Gbrpf32le.encode(&img, &mut bytes);
        assert_eq!(&bytes[..4], &img.data()[1].to_le_bytes());
        assert_eq!(&bytes[60..64], &img.data()[2].to_le_bytes());
        assert_eq!(&bytes[120..124], &img.data()[0].to_le_bytes());
    }

    #[test]
    fn a_stream_that_ends_inside_a_frame_is_refused() {
        let mut buf = vec![0u8; 12];
        let mut whole: &[u8] = &[1u8; 24];
        assert!(read_frame(&mut whole, &mut buf, 0).unwrap());
        assert!(read_frame(&mut whole, &mut buf, 1).unwrap());
        assert!(!read_frame(&mut whole, &mut buf, 2).unwrap());
        let mut short: &[u8] = &[1u8; 18];
        assert!(read_frame(&mut short, &mut buf, 0).unwrap());
        let e = read_frame(&mut short, &mut buf, 1).unwrap_err();
        assert!(
            e.message.contains("ended 6 bytes into frame 1"),
            "{}",
            e.message
        );
        assert_eq!(parse_size("--in-size", "4096x2048").unwrap(), (4096, 2048));
        for bad in ["4096", "0x5", "ax2", "70000x2"] {
            assert!(parse_size("--in-size", bad).is_err(), "{bad}");
        }
    }
}
