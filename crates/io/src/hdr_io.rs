//! Radiance RGBE (`.hdr`): read with the `image` crate's decoder, written here with the
//! standard new-style run-length encoding.

use crate::input::Input;
use crate::ldr_io::{check_limits, check_writable_size, decode_error, guard_decoder};
use crate::{atomic::Dest, atomic::Written, Error, Format, Limits, Loaded, WriteOptions};
use image::codecs::hdr::HdrDecoder;
use image::{DynamicImage, ImageDecoder};
use mirrorball_core::Image;
use mirrorball_encode::{Range, Storage};
use rayon::prelude::*;
use std::io::BufRead;

/// Rows encoded per parallel work item.
const ROWS_PER_BAND: usize = 16;

/// What RGBE holds (its largest value: mantissa 255 with the largest exponent, byte 255).
const RGBE: Range = Storage::Rgbe.range();

/// Smallest value written as non-zero (as in Ward's reference encoder).
const RGBE_MIN: f32 = 1e-32;

/// Bytes read ahead to check the signature and header.
const PEEK: usize = 1 << 16;

/// Reads a Radiance RGBE file as linear `f32` RGB.
///
/// Accepts the `#?RADIANCE` and `#?RGBE` signatures and the standard `-Y H +X W`
/// orientation; the declared size is checked against `limits` before decoding. Header lines
/// `mirrorball:projection=…` and `mirrorball:layout=…` become [`Loaded::recorded`].
pub fn read(input: &Input, limits: &Limits) -> Result<Loaded, Error> {
    let path = input.path();
    guard_decoder(path, "Radiance HDR", || {
        let mut reader = input
            .reader_with_capacity(PEEK)
            .map_err(|e| Error::io(path, e))?;
        let head = reader.fill_buf().map_err(|e| Error::io(path, e))?;
        if !head.starts_with(b"#?") {
            return Err(Error::input(
                path,
                "not a Radiance HDR file (it does not start with the #?RADIANCE signature)".into(),
            ));
        }
        // A file shorter than the peek holds its whole header: check it ends properly, so a
        // cut-off header is reported as such rather than as a strange attribute.
        if (head.len() as u64) == input.len() && !header_is_complete(head) {
            return Err(Error::input(
                path,
                "file is truncated (the header ends before the image size line)".into(),
            ));
        }
        // Non-strict: also accepts other signatures such as #?RGBE, which some tools write.
        let decoder =
            HdrDecoder::new_nonstrict(reader).map_err(|e| decode_error(path, "Radiance HDR", e))?;
        let (width, height) = decoder.dimensions();
        check_limits(path, width as u64, height as u64, limits)?;
        crate::bounds::check_lines_fit(input, height as u64)?;
        // A new-style run-length line costs at least 2 bytes a channel per 127 texels (16
        // texels a byte); old-style runs can chain repeat counts further, and files that
        // use them are rare: 64 texels a byte (and any file up to the floor) covers them.
        crate::bounds::check_texels_fit(
            input,
            width as u64,
            height as u64,
            crate::bounds::Density::Most(64),
            "Radiance HDR",
        )?;
        let lines = decoder.metadata().custom_attributes;
        let get = |key: &str| lines.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
        let recorded = crate::recorded(path, get, width, height);
        let decoded = DynamicImage::from_decoder(decoder)
            .map_err(|e| decode_error(path, "Radiance HDR", e))?;
        let data = match decoded {
            DynamicImage::ImageRgb32F(b) => b.into_raw(),
            other => other.to_rgb32f().into_raw(),
        };
        let image = Image::from_vec(width, height, 3, data).ok_or_else(|| {
            Error::input(path, "the decoded image has an inconsistent size".into())
        })?;
        Ok(Loaded {
            layers: vec![image],
            declared: None,
            recorded,
            format: Format::Hdr,
            description: "Radiance RGBE".to_string(),
            // RGBE holds no NaN, infinite or negative values.
            invalid: Some(0),
        })
    })
}

/// Whether `head` holds the header lines, the blank line and the whole size line.
fn header_is_complete(head: &[u8]) -> bool {
    match head.windows(2).position(|w| w == b"\n\n") {
        Some(blank) => head[blank + 2..].contains(&b'\n'),
        None => false,
    }
}

/// The work of writing `texels` texels as Radiance RGBE (encoded and run-length coded), in
/// [`mirrorball_core::work`]'s units: what [`write`] counts.
pub fn rgbe_work(texels: u64) -> u64 {
    texels * 15
}

/// Writes `image` as Radiance RGBE (alpha is dropped), run-length encoded for widths from
/// 8 to 32767 and flat otherwise, rows encoded on all cores. Negative and NaN values are
/// written as 0, values beyond the RGBE range as its largest value. Written to a temporary
/// file that the returned [`Written`] renames into place, or to memory (`dest`). The map's projection and layout
/// ([`WriteOptions::declared`]) go into the header as `mirrorball:projection=…` and
/// `mirrorball:layout=…` lines (Radiance headers hold `NAME=value` lines).
pub fn write(dest: Dest, image: &Image, opts: &WriteOptions) -> Result<Written, Error> {
    let path = dest.path();
    check_writable_size(path, image)?;
    let (w, h) = (image.width() as usize, image.height() as usize);
    let c = image.channels();
    let mut header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n".to_string();
    if let Some(info) = &opts.declared {
        let (projection, layout) = info.texts();
        header += &format!("{}={projection}\n", crate::PROJECTION_KEY);
        if let Some(l) = layout {
            header += &format!("{}={l}\n", crate::LAYOUT_KEY);
        }
    }
    header += &format!("\n-Y {h} +X {w}\n");
    let bands: Vec<Vec<u8>> = image
        .data()
        .par_chunks(w * c * ROWS_PER_BAND)
        .map(|band| {
            let mut out = Vec::with_capacity(band.len() / c * 4 + 64);
            let mut rgbe = vec![[0u8; 4]; w];
            for row in band.chunks_exact(w * c) {
                for (dst, src) in rgbe.iter_mut().zip(row.chunks_exact(c)) {
                    *dst = to_rgbe(src[0], src[1], src[2]);
                }
                encode_scanline(&rgbe, &mut out);
            }
            mirrorball_core::work::add(rgbe_work((band.len() / c) as u64));
            out
        })
        .collect();
    dest.emit(|out| {
        out.write_all(header.as_bytes())
            .map_err(|e| Error::io(path, e))?;
        for band in &bands {
            out.write_all(band).map_err(|e| Error::io(path, e))?;
        }
        Ok(())
    })
}

/// One texel as RGBE, rounding each mantissa to nearest (readers compute `m · 2^(e-136)`).
/// The largest mantissa is always at least 128, so a texel never looks like a run-length
/// marker (`1 1 1 e`) or a new-style scan-line header (`2 2 <128 e`).
fn to_rgbe(r: f32, g: f32, b: f32) -> [u8; 4] {
    // NaN and negatives become 0, values past the range its largest.
    let (r, g, b) = (RGBE.fit(0, r), RGBE.fit(1, g), RGBE.fit(2, b));
    let max = r.max(g).max(b);
    if max < RGBE_MIN {
        return [0; 4];
    }
    // max = 1.f · 2^e2 (a normal float); the mantissas scale by 2^(7 - e2) so max lands in
    // [128, 256).
    let mut e2 = ((max.to_bits() >> 23) & 0xff) as i32 - 127;
    let scale_for = |e2: i32| f32::from_bits(((7 - e2 + 127) as u32) << 23);
    let mut scale = scale_for(e2);
    if (max * scale + 0.5) as u32 >= 256 {
        e2 += 1;
        scale = scale_for(e2);
    }
    let q = |v: f32| (v * scale + 0.5) as u8;
    [q(r), q(g), q(b), (e2 + 129) as u8]
}

/// Appends one scan line: new-style run-length encoded (per component) when the width
/// allows it, flat otherwise.
fn encode_scanline(texels: &[[u8; 4]], out: &mut Vec<u8>) {
    let w = texels.len();
    if !(8..=0x7fff).contains(&w) {
        for t in texels {
            out.extend_from_slice(t);
        }
        return;
    }
    out.extend_from_slice(&[2, 2, (w >> 8) as u8, (w & 0xff) as u8]);
    let mut component = Vec::with_capacity(w);
    for k in 0..4 {
        component.clear();
        component.extend(texels.iter().map(|t| t[k]));
        encode_runs(&component, out);
    }
}

/// Run-length encodes one component: runs of at least 4 equal bytes as `128 + n, byte`
/// (n ≤ 127), everything else as literals `n, bytes…` (n ≤ 128).
fn encode_runs(data: &[u8], out: &mut Vec<u8>) {
    const MIN_RUN: usize = 4;
    let run_at = |i: usize| {
        data[i..]
            .iter()
            .take(127)
            .take_while(|&&b| b == data[i])
            .count()
    };
    let mut i = 0;
    while i < data.len() {
        let run = run_at(i);
        if run >= MIN_RUN {
            out.extend_from_slice(&[128 + run as u8, data[i]]);
            i += run;
            continue;
        }
        // A literal stretch up to the next worthwhile run (or 128 bytes).
        let start = i;
        while i < data.len() && i - start < 128 && run_at(i) < MIN_RUN {
            i += 1;
        }
        out.push((i - start) as u8);
        out.extend_from_slice(&data[start..i]);
    }
}
