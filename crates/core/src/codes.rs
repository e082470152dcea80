//! [`Codes`]: a layer of RGB texels held as the caller has them: integer codes read through
//! a table of linear values, as a raw video frame arrives (ffmpeg's `rgb24` and `rgb48le`),
//! or `f32` values borrowed from the caller (a numpy array), so that a planned
//! [`Remap`](crate::Remap) reads the layer as it is, with no float copy of it
//! ([`Remap::rows_coded`](crate::Remap::rows_coded)).
//!
//! Every read goes through the table, so a texel read here is, to the bit, the texel of the
//! float image the same table decodes the codes into: the conversion's results are the
//! same bits either way (tested), only the memory read differs (a 4096×2048 frame is 25 MB
//! of 8-bit codes, where its `f32` copy is 100 MB written and then gathered from).

use crate::Image;
use rayon::prelude::*;

/// One layer of `width`×`height` texels, R, G, B interleaved, each channel one integer code
/// (one byte, or two bytes little-endian; a code `k` is the linear value `table[k]`) or one
/// `f32` read as it is.
#[derive(Clone, Copy, Debug)]
pub struct Codes<'a> {
    bytes: &'a [u8],
    table: &'a [f32],
    /// The texels as floats, for [`CodeKind::Float`] (empty otherwise).
    floats: &'a [f32],
    kind: CodeKind,
    width: u32,
    height: u32,
}

/// How [`Codes`] hold a channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CodeKind {
    /// One byte through a table of 256 values.
    Narrow,
    /// Two bytes, little-endian, through a table of 65536 values.
    Wide,
    /// One `f32`, its own value.
    Float,
}

/// Why bytes cannot be read as [`Codes`]: the caller's mistake.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CodesError {
    /// The bytes are not `width × height × 3` codes.
    Length {
        /// Bytes a layer of this size holds.
        expected: usize,
        /// Bytes given.
        found: usize,
    },
    /// The table does not have an entry for every code (256, or 65536).
    Table {
        /// Entries needed.
        expected: usize,
        /// Entries given.
        found: usize,
    },
}

impl std::fmt::Display for CodesError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CodesError::Length { expected, found } => {
                write!(f, "{found} bytes of codes, where the layer has {expected}")
            }
            CodesError::Table { expected, found } => {
                write!(
                    f,
                    "a table of {found} values, where the codes need {expected}"
                )
            }
        }
    }
}

impl std::error::Error for CodesError {}

impl<'a> Codes<'a> {
    /// 8-bit codes (`rgb24`): `bytes` holds `width × height × 3` of them, `table` 256 values.
    pub fn u8(
        bytes: &'a [u8],
        table: &'a [f32],
        (width, height): (u32, u32),
    ) -> Result<Codes<'a>, CodesError> {
        Codes::new(bytes, table, false, (width, height))
    }

    /// 16-bit little-endian codes (`rgb48le`): `bytes` holds `width × height × 6` bytes,
    /// `table` 65536 values.
    pub fn u16le(
        bytes: &'a [u8],
        table: &'a [f32],
        (width, height): (u32, u32),
    ) -> Result<Codes<'a>, CodesError> {
        Codes::new(bytes, table, true, (width, height))
    }

    /// Floats (`rgbf32`, a float32 array): `floats` holds `width × height × 3` values,
    /// each read as it is (no table). The conversion reads the caller's floats where a
    /// float image of them would be copied first: the same bits either way.
    pub fn f32(floats: &'a [f32], (width, height): (u32, u32)) -> Result<Codes<'a>, CodesError> {
        let expected = width as usize * height as usize * 3;
        if floats.len() != expected {
            return Err(CodesError::Length {
                expected: expected * 4,
                found: floats.len() * 4,
            });
        }
        // SAFETY: the bytes of the floats, read only, for as long as the floats are
        // borrowed; `u8` has no alignment and every byte is a valid `u8`.
        let bytes =
            unsafe { std::slice::from_raw_parts(floats.as_ptr().cast::<u8>(), floats.len() * 4) };
        Ok(Codes {
            bytes,
            table: &[],
            floats,
            kind: CodeKind::Float,
            width,
            height,
        })
    }

    fn new(
        bytes: &'a [u8],
        table: &'a [f32],
        wide: bool,
        (width, height): (u32, u32),
    ) -> Result<Codes<'a>, CodesError> {
        let size = if wide { 2 } else { 1 };
        let expected = width as usize * height as usize * 3 * size;
        if bytes.len() != expected {
            return Err(CodesError::Length {
                expected,
                found: bytes.len(),
            });
        }
        let entries = 1usize << (8 * size);
        if table.len() != entries {
            return Err(CodesError::Table {
                expected: entries,
                found: table.len(),
            });
        }
        Ok(Codes {
            bytes,
            table,
            floats: &[],
            kind: if wide {
                CodeKind::Wide
            } else {
                CodeKind::Narrow
            },
            width,
            height,
        })
    }

    /// The layer's width and height.
    pub fn extent(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// How a channel is held.
    pub(crate) fn kind(&self) -> CodeKind {
        self.kind
    }

    /// The texels as floats ([`CodeKind::Float`]; empty for integer codes).
    pub(crate) fn floats(&self) -> &'a [f32] {
        self.floats
    }

    /// The codes' bytes.
    pub(crate) fn bytes(&self) -> &'a [u8] {
        self.bytes
    }

    /// The table.
    pub(crate) fn table(&self) -> &'a [f32] {
        self.table
    }

    /// The linear R, G, B of texel `i` (row-major).
    ///
    /// # Panics
    /// If `i` is outside the layer.
    #[inline(always)]
    pub fn texel(&self, i: usize) -> [f32; 3] {
        match self.kind {
            CodeKind::Wide => Wide::texel(self.bytes, Wide::table(self.table), i),
            CodeKind::Narrow => Narrow::texel(self.bytes, Narrow::table(self.table), i),
            CodeKind::Float => Float::texel(self.bytes, (), i),
        }
    }

    /// The float image the table decodes the codes into (what the coded reads are equal to,
    /// texel for texel).
    pub fn to_image(&self) -> Image {
        let mut img = Image::new(self.width, self.height, 3);
        let w = self.width as usize;
        img.data_mut()
            .par_chunks_mut(w * 3)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, t) in row.chunks_exact_mut(3).enumerate() {
                    t.copy_from_slice(&self.texel(y * w + x));
                }
            });
        img
    }
}

/// One plane of a planar picture (a YUV frame's Y, U or V) held as its integer codes, one
/// byte or two little-endian a texel, each read as the value `code − offset` (computed in
/// `f32`), so that a planned [`Remap`](crate::Remap) reads the plane as it arrives
/// ([`Remap::rows_plane`](crate::Remap::rows_plane)) with the same bits as from the
/// one-channel float image of those values ([`Plane::to_image`]).
#[derive(Clone, Copy, Debug)]
pub struct Plane<'a> {
    bytes: &'a [u8],
    wide: bool,
    offset: f32,
    width: u32,
    height: u32,
}

impl<'a> Plane<'a> {
    /// 8-bit codes: `bytes` holds `width × height` of them.
    pub fn u8(
        bytes: &'a [u8],
        offset: f32,
        (width, height): (u32, u32),
    ) -> Result<Plane<'a>, CodesError> {
        Plane::new(bytes, false, offset, (width, height))
    }

    /// 16-bit little-endian codes (10-, 12- and 16-bit planes): `bytes` holds
    /// `width × height × 2` bytes.
    pub fn u16le(
        bytes: &'a [u8],
        offset: f32,
        (width, height): (u32, u32),
    ) -> Result<Plane<'a>, CodesError> {
        Plane::new(bytes, true, offset, (width, height))
    }

    fn new(
        bytes: &'a [u8],
        wide: bool,
        offset: f32,
        (width, height): (u32, u32),
    ) -> Result<Plane<'a>, CodesError> {
        let expected = width as usize * height as usize * (1 + wide as usize);
        if bytes.len() != expected {
            return Err(CodesError::Length {
                expected,
                found: bytes.len(),
            });
        }
        Ok(Plane {
            bytes,
            wide,
            offset,
            width,
            height,
        })
    }

    /// The plane's width and height.
    pub fn extent(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Whether a code takes two bytes.
    pub(crate) fn wide(&self) -> bool {
        self.wide
    }

    /// The codes' bytes.
    pub(crate) fn bytes(&self) -> &'a [u8] {
        self.bytes
    }

    /// What every code is read less.
    pub(crate) fn offset(&self) -> f32 {
        self.offset
    }

    /// Texels in the plane.
    pub(crate) fn len(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The value of texel `i` (row-major): its code less the offset.
    ///
    /// # Panics
    /// If `i` is outside the plane.
    #[inline(always)]
    pub fn value(&self, i: usize) -> f32 {
        let code = if self.wide {
            u16::from_le_bytes([self.bytes[2 * i], self.bytes[2 * i + 1]]) as f32
        } else {
            self.bytes[i] as f32
        };
        code - self.offset
    }

    /// The one-channel float image of the plane's values (what its reads are equal to,
    /// texel for texel).
    pub fn to_image(&self) -> Image {
        let mut img = Image::new(self.width, self.height, 1);
        let w = self.width as usize;
        img.data_mut()
            .par_chunks_mut(w.max(1))
            .enumerate()
            .for_each(|(y, row)| {
                for (x, v) in row.iter_mut().enumerate() {
                    *v = self.value(y * w + x);
                }
            });
        img
    }
}

/// How a code width reads a texel: monomorphised into the hot loops, so that they never
/// branch on the width, and the table's length is checked once, when it becomes a
/// [`CodeWidth::Table`].
pub(crate) trait CodeWidth {
    /// Bytes of one texel (three codes).
    const TEXEL_BYTES: usize;
    /// The table as the reads take it (an array: a code never passes its end).
    type Table<'t>: Copy;
    /// `table` as this width reads it.
    ///
    /// # Panics
    /// If `table` is not one value per code ([`Codes`] checks that when made).
    fn table(table: &[f32]) -> Self::Table<'_>;
    /// The linear R, G, B of texel `i` of `bytes` through `table`.
    fn texel(bytes: &[u8], table: Self::Table<'_>, i: usize) -> [f32; 3];
}

/// One byte a channel.
pub(crate) struct Narrow;
/// Two bytes a channel, little-endian.
pub(crate) struct Wide;
/// One `f32` a channel, in the machine's byte order (the bytes of a `&[f32]`).
pub(crate) struct Float;

impl CodeWidth for Float {
    const TEXEL_BYTES: usize = 12;
    type Table<'t> = ();
    fn table(_: &[f32]) {}
    #[inline(always)]
    fn texel(bytes: &[u8], _: (), i: usize) -> [f32; 3] {
        let b = &bytes[12 * i..12 * i + 12];
        let k = |j: usize| f32::from_ne_bytes([b[j], b[j + 1], b[j + 2], b[j + 3]]);
        [k(0), k(4), k(8)]
    }
}

impl CodeWidth for Narrow {
    const TEXEL_BYTES: usize = 3;
    type Table<'t> = &'t [f32; 256];
    fn table(table: &[f32]) -> &[f32; 256] {
        table.try_into().expect("a table of 256 values")
    }
    #[inline(always)]
    fn texel(bytes: &[u8], t: &[f32; 256], i: usize) -> [f32; 3] {
        let b = &bytes[3 * i..3 * i + 3];
        [t[b[0] as usize], t[b[1] as usize], t[b[2] as usize]]
    }
}

impl CodeWidth for Wide {
    const TEXEL_BYTES: usize = 6;
    type Table<'t> = &'t [f32; 65536];
    fn table(table: &[f32]) -> &[f32; 65536] {
        table.try_into().expect("a table of 65536 values")
    }
    #[inline(always)]
    fn texel(bytes: &[u8], t: &[f32; 65536], i: usize) -> [f32; 3] {
        let b = &bytes[6 * i..6 * i + 6];
        let k = |j: usize| u16::from_le_bytes([b[j], b[j + 1]]) as usize;
        [t[k(0)], t[k(2)], t[k(4)]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_are_the_table_of_their_codes() {
        let t8: Vec<f32> = (0..256).map(|k| k as f32 * 0.5).collect();
        let bytes = [0u8, 1, 255, 7, 8, 9];
        let c = Codes::u8(&bytes, &t8, (2, 1)).unwrap();
        assert_eq!(c.texel(0), [0.0, 0.5, 127.5]);
        assert_eq!(c.texel(1), [3.5, 4.0, 4.5]);
        assert_eq!(c.to_image().data(), &[0.0, 0.5, 127.5, 3.5, 4.0, 4.5]);
        let t16: Vec<f32> = (0..65536).map(|k| k as f32).collect();
        let bytes = [0x01u8, 0x02, 0xff, 0xff, 0, 0];
        let c = Codes::u16le(&bytes, &t16, (1, 1)).unwrap();
        assert_eq!(c.texel(0), [513.0, 65535.0, 0.0]);
        let floats = [1.5f32, -2.0, f32::NAN, 0.25, 1e30, 7.0];
        let c = Codes::f32(&floats, (2, 1)).unwrap();
        assert_eq!(c.texel(1), [0.25, 1e30, 7.0]);
        assert!(c.texel(0)[2].is_nan());
        assert_eq!(c.to_image().data()[..2], [1.5, -2.0]);
    }

    #[test]
    fn wrong_lengths_and_tables_are_refused() {
        let t8 = vec![0.0f32; 256];
        assert_eq!(
            Codes::u8(&[0; 5], &t8, (2, 1)).unwrap_err(),
            CodesError::Length {
                expected: 6,
                found: 5
            }
        );
        assert_eq!(
            Codes::u16le(&[0; 6], &t8, (1, 1)).unwrap_err(),
            CodesError::Table {
                expected: 65536,
                found: 256
            }
        );
        assert_eq!(
            Codes::f32(&[0.0; 5], (2, 1)).unwrap_err(),
            CodesError::Length {
                expected: 24,
                found: 20
            }
        );
        // A layer whose byte count overflows nothing: 0×0 holds no codes.
        assert!(Codes::u8(&[], &t8, (0, 0)).is_ok());
    }
}
