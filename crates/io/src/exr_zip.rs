//! OpenEXR's ZIP and ZIPS block compression, done with libdeflate on all cores.
//!
//! The `exr` crate would read these blocks with `zune-inflate` and write them with
//! `miniz_oxide`; libdeflate inflates and deflates them faster, and here every block is its
//! own task on all cores (BENCHMARKS.md has the end-to-end figures). The `exr` crate still
//! reads and writes everything around the blocks: headers, offset tables, chunk order.
//! Files come out the size OpenEXR's own ZIP makes them.
//!
//! The block format (OpenEXR's `ImfZip.cpp`): a block's lines, each line its channels in
//! the header's (alphabetical) order, each channel its samples in little-endian order; then
//! the bytes are split, those at even offsets first and those at odd offsets after them;
//! then each byte but the first is replaced by its difference from the one before, plus 128
//! (modulo 256); then the whole is one zlib stream. A block whose stream would not be
//! smaller than its raw bytes is stored raw, and a reader tells the two apart by size.

use libdeflater::{CompressionLvl, Compressor, Decompressor};

/// The libdeflate level ZIP blocks are written with: 4, as `exr` writes with miniz.
const LEVEL: i32 = 4;

/// Compresses one block's raw little-endian bytes as a ZIP/ZIPS block into `out`
/// (replacing its contents), using `scratch` for the reordered bytes. Stores `raw` as it is
/// where deflating would not make it smaller.
pub(crate) fn compress(raw: &[u8], scratch: &mut Vec<u8>, comp: &mut Zip, out: &mut Vec<u8>) {
    let n = raw.len();
    // Every byte is overwritten below: resizing a reused buffer writes nothing.
    scratch.resize(n, 0);
    let half = n.div_ceil(2);
    // Even offsets first, then odd ones.
    let (evens, odds) = scratch.split_at_mut(half);
    let pairs = n / 2;
    for ((pair, e), d) in raw
        .chunks_exact(2)
        .zip(evens.iter_mut())
        .zip(odds.iter_mut())
    {
        *e = pair[0];
        *d = pair[1];
    }
    if n % 2 == 1 {
        evens[pairs] = raw[n - 1];
    }
    // Differences: each byte less the one before it (as it was), plus 128.
    let mut prev = scratch.first().copied().unwrap_or(0);
    for v in scratch.iter_mut().skip(1) {
        let cur = *v;
        *v = cur.wrapping_sub(prev).wrapping_add(128);
        prev = cur;
    }
    let compressor = comp.compressor.get_or_insert_with(|| {
        Compressor::new(CompressionLvl::new(LEVEL).expect("level 4 is valid"))
    });
    out.resize(compressor.zlib_compress_bound(n), 0);
    match compressor.zlib_compress(scratch, out) {
        Ok(len) if len < n => out.truncate(len),
        // Not smaller (or no room, which the bound rules out): the raw bytes.
        _ => {
            out.clear();
            out.extend_from_slice(raw);
        }
    }
}

/// A block's raw line bytes after [`inflate`]: stored as they are, or split into the bytes
/// at even offsets and those at odd offsets (how ZIP blocks keep them), which a reader can
/// interleave as it converts (or have [`Lines::to_bytes`] do it).
pub(crate) enum Lines<'a> {
    /// The raw bytes (a block stored uncompressed).
    Raw(&'a [u8]),
    /// Raw byte `2i` is `evens[i]`, byte `2i + 1` is `odds[i]`.
    Split {
        /// Bytes at even offsets (`⌈len/2⌉` of them).
        evens: &'a [u8],
        /// Bytes at odd offsets (`⌊len/2⌋`).
        odds: &'a [u8],
    },
}

impl Lines<'_> {
    /// The raw bytes, interleaved into `out` where they were split.
    pub(crate) fn to_bytes<'o>(&'o self, out: &'o mut Vec<u8>) -> &'o [u8] {
        match *self {
            Lines::Raw(b) => b,
            Lines::Split { evens, odds } => {
                // Overwritten whole: resizing a reused buffer writes nothing.
                out.resize(evens.len() + odds.len(), 0);
                interleave(evens, odds, out);
                out
            }
        }
    }
}

/// Inflates one ZIP/ZIPS block that holds `expected` raw bytes into `scratch` and undoes
/// its predictor, leaving the bytes split (see [`Lines`]); a block of exactly `expected`
/// bytes is raw. Errors say what is wrong with the block.
pub(crate) fn inflate<'a>(
    block: &'a [u8],
    expected: usize,
    scratch: &'a mut Vec<u8>,
    dec: &mut Zip,
) -> Result<Lines<'a>, String> {
    if block.len() == expected {
        return Ok(Lines::Raw(block));
    }
    // Overwritten whole below: resizing a reused buffer writes nothing.
    scratch.resize(expected, 0);
    let got = dec
        .decompressor
        .get_or_insert_with(Decompressor::new)
        .zlib_decompress(block, scratch)
        .map_err(|e| format!("a ZIP block does not inflate ({e:?})"))?;
    if got != expected {
        return Err(format!(
            "a ZIP block inflates to {got} bytes where its lines need {expected}"
        ));
    }
    // Undo the differences (a running sum); even and odd offsets stay apart.
    running_sum(scratch);
    let (evens, odds) = scratch.split_at(expected.div_ceil(2));
    Ok(Lines::Split { evens, odds })
}

/// `b[i] = b[i − 1] + b[i] − 128` for every byte but the first (modulo 256): the running
/// sum that undoes OpenEXR's ZIP predictor.
fn running_sum(b: &mut [u8]) {
    mirrorball_core::simd::prefix_sum_biased(b, 128);
}

/// `out[2k] = evens[k]`, `out[2k + 1] = odds[k]` (`evens` may be one longer).
fn interleave(evens: &[u8], odds: &[u8], out: &mut [u8]) {
    let pairs = odds.len().min(out.len() / 2);
    for ((o, &e), &d) in out[..2 * pairs]
        .chunks_exact_mut(2)
        .zip(&evens[..pairs])
        .zip(&odds[..pairs])
    {
        o[0] = e;
        o[1] = d;
    }
    if let (Some(&e), true) = (evens.get(pairs), out.len() > 2 * pairs) {
        out[2 * pairs] = e;
    }
}

/// A thread's libdeflate state. The compressor and decompressor are made on first use and
/// kept: each allocates its tables (hundreds of KiB for the compressor) when made, which
/// per block, or for a reader that never compresses, would cost more than the work.
#[derive(Default)]
pub(crate) struct Zip {
    compressor: Option<Compressor>,
    decompressor: Option<Decompressor>,
}

impl Zip {
    pub(crate) fn new() -> Zip {
        Zip::default()
    }
}

thread_local! {
    /// Each thread's libdeflate state, for the EXR reader and writer, whose work is split
    /// among rayon's threads in pieces of any size.
    pub(crate) static THREAD_ZIP: std::cell::RefCell<Zip> = std::cell::RefCell::new(Zip::new());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_running_sum_matches_the_byte_at_a_time_definition() {
        // Every length around the 16-byte steps, and a long one, of noise.
        let mut s = 7u32;
        for len in (0..70).chain([1000, 4097]) {
            let bytes: Vec<u8> = (0..len)
                .map(|_| {
                    s = s.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                    (s >> 16) as u8
                })
                .collect();
            let mut want = bytes.clone();
            for i in 1..want.len() {
                want[i] = want[i - 1].wrapping_add(want[i]).wrapping_sub(128);
            }
            let mut got = bytes;
            running_sum(&mut got);
            assert_eq!(got, want, "length {len}");
        }
    }

    #[test]
    fn blocks_round_trip_through_zip_and_raw_storage() {
        let mut zip = Zip::new();
        let (mut scratch, mut packed, mut back) = (Vec::new(), Vec::new(), Vec::new());
        // Compressible (a ramp), incompressible (noise, stored raw), odd length, empty.
        let ramp: Vec<u8> = (0..10_000u32).map(|i| (i / 7) as u8).collect();
        let mut s = 12345u32;
        let noise: Vec<u8> = (0..4_001)
            .map(|_| {
                s = s.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                (s >> 16) as u8
            })
            .collect();
        for raw in [&ramp[..], &noise[..], &ramp[..9_999], &[][..]] {
            compress(raw, &mut scratch, &mut zip, &mut packed);
            if raw == &noise[..] {
                assert_eq!(packed, raw, "noise is stored raw");
            } else if !raw.is_empty() {
                assert!(packed.len() < raw.len() / 4, "a ramp compresses");
            }
            let lines = inflate(&packed, raw.len(), &mut scratch, &mut zip).unwrap();
            assert_eq!(lines.to_bytes(&mut back), raw);
        }
        // A corrupt stream and one of the wrong length are errors, not panics.
        compress(&ramp, &mut scratch, &mut zip, &mut packed);
        let mut bad = packed.clone();
        bad[5] ^= 0xff;
        bad.truncate(bad.len() / 2);
        assert!(inflate(&bad, ramp.len(), &mut scratch, &mut zip).is_err());
        assert!(inflate(&packed, ramp.len() + 10, &mut scratch, &mut zip).is_err());
    }
}
