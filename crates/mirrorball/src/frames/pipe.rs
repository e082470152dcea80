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

/// The sRGB encoding scaled to integer codes, fast, and exactly io's (`srgb8_code`,
/// `srgb16_code`: what PNG and JPEG files hold), so a raw frame and a file of one map carry
/// the same codes.
///
/// 8-bit codes: io's codes change at 255 thresholds (`srgb8_thresholds`). From 2⁻¹³ (below
/// the first threshold, 1.52·10⁻⁴) to 1 the `f32` bit pattern is cut into 2⁷ pieces per
/// octave; each piece holds at most one threshold (the thresholds are at least 3·10⁻⁴
/// apart below the knee and 8.9·10⁻³ near 1, wider than the pieces there; checked when the
/// table is made), so a value's code is its piece's first code, plus one at or past the
/// piece's threshold.
///
/// 16-bit codes: an estimate, piecewise linear in the bit pattern from 2⁻⁹ (2⁹ pieces per
/// octave: within a piece the curve bends by under 0.01 of a code) and linear below the
/// knee, is the nearest code or its neighbour; one step against the exact thresholds
/// between codes (each the smallest `f32` io encodes to the next code) makes it io's.
pub struct SrgbTable {
    /// 16-bit: the code value (scaled, not rounded) at the start of each 2⁹-per-octave
    /// piece from 2⁻⁹, and one past the end.
    at: Vec<f32>,
    /// 8-bit: each piece's first code (as `f32`, for the eight-lane lookup).
    first: Vec<f32>,
    /// 8-bit: the threshold after each piece's first code (infinite past 255); 16-bit: the
    /// threshold after each code, `thresholds[k]` the smallest value of code `k + 1`.
    thresholds: Vec<f32>,
    scale: f32,
}

/// The bit pattern of 2⁻⁹, where the 16-bit estimate's table starts.
const TABLE_FROM: u32 = 0x3b00_0000;
/// Mantissa bits below a 16-bit piece's index.
const PIECE_SHIFT: u32 = 14;
/// The bit pattern of 2⁻¹³, where the 8-bit table starts.
const TABLE8_FROM: u32 = 0x3900_0000;
/// Mantissa bits below an 8-bit piece's index.
const PIECE8_SHIFT: u32 = 16;

impl SrgbTable {
    /// The table for codes `0..=scale` (255 or 65535).
    pub fn get(scale: f32) -> &'static SrgbTable {
        static T8: OnceLock<SrgbTable> = OnceLock::new();
        static T16: OnceLock<SrgbTable> = OnceLock::new();
        if scale <= 255.0 {
            T8.get_or_init(SrgbTable::eight)
        } else {
            T16.get_or_init(SrgbTable::sixteen)
        }
    }

    fn eight() -> SrgbTable {
        let t = mirrorball_io::srgb8_thresholds();
        assert!(
            t[0] > f32::from_bits(TABLE8_FROM),
            "no code above 0 below the table"
        );
        let pieces = (1.0f32.to_bits() - TABLE8_FROM) >> PIECE8_SHIFT;
        let (mut first, mut thresholds) = (Vec::new(), Vec::new());
        for k in 0..pieces {
            let start = f32::from_bits(TABLE8_FROM + (k << PIECE8_SHIFT));
            let end = f32::from_bits(TABLE8_FROM + ((k + 1) << PIECE8_SHIFT));
            let c = mirrorball_io::srgb8_code(start, t) as usize;
            let next = t.get(c).copied().unwrap_or(f32::INFINITY);
            assert!(
                t.get(c + 1).is_none_or(|&after| after >= end),
                "two 8-bit thresholds in the piece from {start}"
            );
            first.push(c as f32);
            thresholds.push(next);
        }
        SrgbTable {
            at: Vec::new(),
            first,
            thresholds,
            scale: 255.0,
        }
    }

    fn sixteen() -> SrgbTable {
        let code = |bits: u32| linear_to_srgb(f32::from_bits(bits) as f64) * 65535.0;
        let pieces = ((1.0f32.to_bits() - TABLE_FROM) >> PIECE_SHIFT) as usize;
        let at = (0..=pieces)
            .map(|k| code(TABLE_FROM + ((k as u32) << PIECE_SHIFT)) as f32)
            .collect();
        // The smallest value io encodes to code k + 1, found from its real threshold by
        // stepping one `f32` at a time.
        let enc = |l: f32| mirrorball_io::srgb16_code(l) as u32;
        let thresholds = (0..65535u32)
            .map(|k| {
                let mut g =
                    mirrorball_core::color::srgb_to_linear((k as f64 + 0.5) / 65535.0) as f32;
                while enc(g) > k {
                    g = f32::from_bits(g.to_bits() - 1);
                }
                while enc(g) <= k {
                    g = f32::from_bits(g.to_bits() + 1);
                }
                g
            })
            .collect();
        SrgbTable {
            at,
            first: Vec::new(),
            thresholds,
            scale: 65535.0,
        }
    }

    /// The code of linear `l`, clamped to `[0, scale]` (NaN gives 0).
    #[cfg(test)]
    pub fn code(&self, l: f32) -> u32 {
        if self.first.is_empty() {
            self.code16(l)
        } else {
            self.code8(l)
        }
    }

    /// [`SrgbTable::code`] of an 8-bit table.
    #[inline(always)]
    pub fn code8(&self, l: f32) -> u32 {
        if l >= 1.0 {
            return 255;
        }
        if l.is_nan() || l < f32::from_bits(TABLE8_FROM) {
            return 0; // NaN, negatives and values under the first threshold
        }
        let k = ((l.to_bits() - TABLE8_FROM) >> PIECE8_SHIFT) as usize;
        self.first[k] as u32 + u32::from(l >= self.thresholds[k])
    }

    /// The 16-bit estimate of `l` in `(0, 1)`: the nearest code or a neighbour.
    #[inline(always)]
    fn estimate16(&self, l: f32) -> u32 {
        if l <= mirrorball_core::color::SRGB_LINEAR_KNEE as f32 {
            return (l * (mirrorball_core::color::SRGB_SLOPE as f32 * self.scale) + 0.5) as u32;
        }
        let rel = l.to_bits() - TABLE_FROM;
        let k = (rel >> PIECE_SHIFT) as usize;
        let t = (rel & ((1 << PIECE_SHIFT) - 1)) as f32 * (1.0 / (1 << PIECE_SHIFT) as f32);
        let (a, b) = (self.at[k], self.at[k + 1]);
        (a + (b - a) * t + 0.5) as u32
    }

    /// [`SrgbTable::code`] of a 16-bit table.
    #[inline(always)]
    pub fn code16(&self, l: f32) -> u32 {
        if l >= 1.0 {
            return 65535;
        }
        if l.is_nan() || l <= 0.0 {
            return 0; // NaN and negatives
        }
        let e = self.estimate16(l).min(65535);
        let down = e > 0 && l < self.thresholds[e as usize - 1];
        let up = e < 65535 && l >= self.thresholds[e as usize];
        e - u32::from(down) + u32::from(up)
    }

    /// [`SrgbTable::code8`] or [`SrgbTable::code16`] (the table's) of eight values at once:
    /// the same arithmetic lane by lane, so the same codes (tested).
    #[inline(always)]
    fn codes_x8(&self, x8: X8, l: F32x8) -> I32x8 {
        let one = x8.splat(1.0);
        let (zero_i, scale_i) = (x8.splat_i32(0), x8.splat_i32(self.scale as i32));
        if !self.first.is_empty() {
            let inside = l.ge(x8.splat(f32::from_bits(TABLE8_FROM))) & l.lt(one);
            let rel = l.to_bits() - x8.splat_i32(TABLE8_FROM as i32);
            let k = inside.select_i32(rel.shift_right(PIECE8_SHIFT), zero_i);
            let (first, next) = (x8.gather(&self.first, k), x8.gather(&self.thresholds, k));
            let code = (first - l.ge(next).to_i32().to_f32()).trunc_i32();
            let code = inside.select_i32(code, zero_i);
            return l.ge(one).select_i32(scale_i, code);
        }
        let zero = x8.splat(0.0);
        let knee = x8.splat(mirrorball_core::color::SRGB_LINEAR_KNEE as f32);
        let slope = x8.splat(mirrorball_core::color::SRGB_SLOPE as f32 * self.scale);
        let linear = (l * slope + x8.splat(0.5)).trunc_i32();
        let inside = l.gt(zero) & l.lt(one);
        let above = inside & l.gt(knee);
        let rel = l.to_bits() - x8.splat_i32(TABLE_FROM as i32);
        let k = above.select_i32(rel.shift_right(PIECE_SHIFT), zero_i);
        let t = (rel & x8.splat_i32((1 << PIECE_SHIFT) - 1)).to_f32()
            * x8.splat(1.0 / (1 << PIECE_SHIFT) as f32);
        let (a, b) = (
            x8.gather(&self.at, k),
            x8.gather(&self.at, k + x8.splat_i32(1)),
        );
        let table = (a + (b - a) * t + x8.splat(0.5)).trunc_i32();
        let e = above.select_i32(table, linear);
        let e = inside.select_i32(e, zero_i);
        // One step against the exact thresholds (`code16`).
        let top = x8.splat_i32(65535);
        let has_below = e.gt(zero_i);
        let has_above = e.lt(top);
        let below = x8.gather(
            &self.thresholds,
            has_below.select_i32(e - x8.splat_i32(1), zero_i),
        );
        let at = x8.gather(&self.thresholds, has_above.select_i32(e, zero_i));
        let down = has_below & l.lt(below);
        let up = has_above & !l.lt(at);
        let e = e + down.to_i32() - up.to_i32();
        let e = inside.select_i32(e, zero_i);
        l.ge(one).select_i32(scale_i, e)
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

    /// Values where codes change (each threshold and its neighbours a few `f32` steps
    /// away), the ends of every table piece, the classes NaN, infinities, negatives,
    /// zero and denormals, and a dense sweep of [0, 1.01].
    fn probes(thresholds: &[f32]) -> Vec<f32> {
        let mut v = vec![
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
            f32::from_bits(1.0f32.to_bits() - 1),
            1.0,
            7.0,
        ];
        for &t in thresholds {
            let b = t.to_bits();
            v.extend((b.saturating_sub(3)..=b + 3).map(f32::from_bits));
        }
        for (from, shift) in [(TABLE8_FROM, PIECE8_SHIFT), (TABLE_FROM, PIECE_SHIFT)] {
            let mut b = from;
            while b < 1.0f32.to_bits() {
                v.extend([b - 1, b, b + 1].map(f32::from_bits));
                b += 1 << shift;
            }
        }
        v.extend((0..=300_000).map(|i| (i as f32 / 300_000.0).powi(2) * 1.01));
        v
    }

    #[test]
    fn the_fast_srgb_codes_are_the_files_codes() {
        let t8 = SrgbTable::get(255.0);
        let exact8 = mirrorball_io::srgb8_thresholds();
        for l in probes(exact8) {
            assert_eq!(
                t8.code(l),
                mirrorball_io::srgb8_code(l, exact8) as u32,
                "8-bit code of {l:e}"
            );
        }
        let t16 = SrgbTable::get(65535.0);
        for l in probes(&t16.thresholds) {
            assert_eq!(
                t16.code(l),
                mirrorball_io::srgb16_code(l) as u32,
                "16-bit code of {l:e}"
            );
        }
        // Each 16-bit threshold is the first value of its code.
        for (k, &t) in t16.thresholds.iter().enumerate() {
            assert_eq!(mirrorball_io::srgb16_code(t) as usize, k + 1);
            assert_eq!(
                mirrorball_io::srgb16_code(f32::from_bits(t.to_bits() - 1)) as usize,
                k
            );
        }
    }

    #[test]
    fn the_eight_lane_codes_are_the_scalar_ones() {
        // Every value class (`probes`), a dense sweep of [0, 1.1] and a stride through the
        // 16-bit estimate's table.
        let mut values: Vec<f32> = (0..=400_000)
            .map(|i| (i as f32 / 400_000.0).powi(2) * 1.1)
            .collect();
        values.extend(
            (TABLE_FROM..1.0f32.to_bits())
                .step_by(4093)
                .map(f32::from_bits),
        );
        values.extend(probes(mirrorball_io::srgb8_thresholds()));
        values.extend(probes(&SrgbTable::get(65535.0).thresholds));
        while !values.len().is_multiple_of(8) {
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
