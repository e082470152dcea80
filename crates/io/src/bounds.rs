//! Declared sizes against the file's real length.
//!
//! [`crate::Limits`] bound what any file may declare; these checks bound what *this* file
//! can hold, so that a few kilobytes cannot make a reader allocate gigabytes. Each format
//! packs at most so many texels into a byte of its file (deflate expands at most 1032:1,
//! every JPEG block costs at least a bit, every Radiance scan line at least 4 bytes); a
//! file declaring more is corrupt, and is refused before anything is allocated. Where a
//! rare but valid coding can pack more (Radiance's old-style chained runs), the bound is
//! set well above the common coding's (64 texels a byte where new-style runs reach 16), and
//! every file may declare [`FLOOR_TEXELS`]. WebP's coding has no such bound, so it is held
//! to a plausible density instead ([`Density::Plausible`]); DWA's DCT with deflated DC
//! values is bounded by checking each block's counters (`exr_io`).

use crate::input::Input;
use crate::Error;

/// Texels any file may declare whatever its length: tiny files of a constant colour are
/// fine up to this (16 MiB as `f32` RGBA).
pub(crate) const FLOOR_TEXELS: u64 = 1 << 20;

/// How a format's texels-a-byte bound is known.
#[derive(Clone, Copy)]
pub(crate) enum Density {
    /// The coding cannot pack more: a file declaring more is corrupt or truncated.
    Most(u64),
    /// The coding has no hard bound, but no real picture comes near this: a file declaring
    /// more is corrupt or hostile (a few bytes would allocate gigabytes).
    Plausible(u64),
}

/// Refuses a `width × height` image declared by a `format` file of more texels than its
/// length allows at `density` texels a byte (and more than [`FLOOR_TEXELS`]).
pub(crate) fn check_texels_fit(
    input: &Input,
    width: u64,
    height: u64,
    density: Density,
    format: &str,
) -> Result<(), Error> {
    let len = input.len();
    let per_byte = match density {
        Density::Most(n) | Density::Plausible(n) => n,
    };
    let most = len.saturating_mul(per_byte).max(FLOOR_TEXELS);
    let texels = width.saturating_mul(height);
    if texels <= most {
        return Ok(());
    }
    let problem = match density {
        Density::Most(_) => format!(
            "declares a {width}×{height} image ({texels} texels), but a {format} file of \
             {len} bytes holds at most {most}: the file is corrupt or truncated"
        ),
        Density::Plausible(_) => format!(
            "declares a {width}×{height} image ({texels} texels) in {len} bytes: more than \
             {per_byte} texels a byte, which no real {format} picture reaches (mirrorball \
             reads {format} files up to {most} texels at this length); the file is corrupt \
             or hostile"
        ),
    };
    Err(Error::input(input.path(), problem))
}

/// Refuses an image whose raw samples (`raw_bytes`, as the file's header declares them)
/// are more than `ratio` times the file's length (and more than [`FLOOR_TEXELS`] × 16
/// bytes): for a compression that expands a byte into at most `ratio`.
pub(crate) fn check_raw_bytes_fit(
    input: &Input,
    raw_bytes: u64,
    ratio: u64,
    what: &str,
) -> Result<(), Error> {
    let len = input.len();
    let most = len.saturating_mul(ratio).max(FLOOR_TEXELS * 16);
    if raw_bytes > most {
        return Err(Error::input(
            input.path(),
            format!(
                "declares {raw_bytes} bytes of samples, but {what} expands a file of {len} \
                 bytes to at most {most}: the file is corrupt or truncated"
            ),
        ));
    }
    Ok(())
}

/// Refuses a Radiance file declaring more scan lines than it has room for: every scan
/// line takes at least 4 bytes (a flat or old-style run-length line starts with a whole
/// RGBE texel; a new-style one with its 4-byte marker).
pub(crate) fn check_lines_fit(input: &Input, height: u64) -> Result<(), Error> {
    let len = input.len();
    if height > len / 4 {
        return Err(Error::input(
            input.path(),
            format!(
                "declares {height} scan lines, but a file of {len} bytes holds at most {} (each \
                 takes at least 4 bytes): the file is corrupt or truncated",
                len / 4
            ),
        ));
    }
    Ok(())
}
