//! The one home of `core::arch` in mirrorball: safe lane types with named operations, each
//! in two implementations that give the same bits.
//!
//! - [`F32x4`], [`I32x4`], [`M32x4`] (four `f32`, four `i32`, a four-lane mask): SSE2 on
//!   x86-64 (part of its baseline, so always there), plain arrays elsewhere.
//! - [`F32x8`], [`I32x8`], [`M32x8`]: AVX2 on x86-64, chosen at run time: a value of these
//!   types can only be made through an [`X8`] token, which [`X8::get`] hands out only
//!   where the processor has AVX2, and code that uses them is a kernel defined with
//!   [`x8_kernel!`], whose body is compiled with AVX2 enabled (so that every operation is
//!   one instruction). Elsewhere plain arrays, and the token is always there.
//! - Byte kernels for file codecs ([`prefix_sum_biased`]) and a cache [`prefetch`] hint.
//!
//! Every operation is the IEEE operation lane by lane (no fused multiply-add, no
//! reassociation), so code written on these types gives, lane by lane, exactly what the
//! same scalar operations give. Conversions to `i32` truncate as x86's `cvttps2dq` does:
//! NaN and values outside the `i32` range become `i32::MIN`
//! ([`trunc_i32`] is the scalar form).
//!
//! The `portable` feature selects the array implementation on every target; the module
//! [`portable`] is always compiled, and the tests compare it with the x86-64 one bit for bit.
#![deny(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

#[cfg(target_arch = "x86_64")]
pub mod avx2;
pub mod portable;
#[cfg(target_arch = "x86_64")]
pub mod sse2;

#[cfg(all(target_arch = "x86_64", not(feature = "portable")))]
pub use avx2::{F32x8, I32x8, M32x8, X8};
#[cfg(not(all(target_arch = "x86_64", not(feature = "portable"))))]
pub use portable::{prefix_sum_biased, F32x4, I32x4, M32x4};
#[cfg(not(all(target_arch = "x86_64", not(feature = "portable"))))]
pub use portable::{F32x8, I32x8, M32x8, X8};
#[cfg(all(target_arch = "x86_64", not(feature = "portable")))]
pub use sse2::{prefix_sum_biased, F32x4, I32x4, M32x4};

/// Whether the lanes in use are the portable arrays (the `portable` feature, or a target
/// other than x86-64).
pub const PORTABLE: bool = !cfg!(all(target_arch = "x86_64", not(feature = "portable")));

/// `x` truncated towards zero, with NaN and values outside the `i32` range giving
/// `i32::MIN` (x86's `cvttss2si`, one instruction where Rust's saturating `as` needs four
/// more); the same as `x as i32` for every `x` in the `i32` range. The scalar form of
/// [`F32x4::trunc_i32`].
///
/// ```
/// use mirrorball_simd::trunc_i32;
/// assert_eq!((trunc_i32(-1.5), trunc_i32(2.9)), (-1, 2));
/// assert_eq!((trunc_i32(f32::NAN), trunc_i32(3e9)), (i32::MIN, i32::MIN));
/// ```
#[inline(always)]
pub fn trunc_i32(x: f32) -> i32 {
    #[cfg(all(target_arch = "x86_64", not(feature = "portable")))]
    {
        sse2::trunc_i32(x)
    }
    #[cfg(not(all(target_arch = "x86_64", not(feature = "portable"))))]
    {
        portable::trunc_i32(x)
    }
}

/// Asks for the cache line holding address `p` to be brought in ahead of its use: a hint
/// that reads nothing, never faults (whatever `p` is) and changes no result; nothing where
/// the target has no such hint.
#[inline(always)]
pub fn prefetch<T>(p: *const T) {
    #[cfg(all(target_arch = "x86_64", not(feature = "portable")))]
    sse2::prefetch(p);
    #[cfg(not(all(target_arch = "x86_64", not(feature = "portable"))))]
    let _ = p;
}

/// Four-lane reads at the corners of a 2×2 grid, `i`, `i + dx`, `i + dy` and `i + dy + dx`,
/// from one base index `i` in any of `N` slices of one length, made safe by construction
/// rather than by a bounds check a read: [`Taps::new`] checks once that the reads from base
/// [`Taps::last`] stay inside, and [`Taps::get`] clamps its base to `last` (one
/// comparison), so every read it makes is in bounds. A bilinear footprint's two rows of two
/// texels are `dx = c` (channels), `dy = stride` (`mirrorball_core::bilinear_taps`).
///
/// ```
/// use mirrorball_simd::Taps;
/// let a: Vec<f32> = (0..16).map(|i| i as f32).collect();
/// let t = Taps::new([&a[..], &a[..]], 2, 8).unwrap();
/// assert_eq!(t.last(), 2); // 2 + 8 + 2 + 4 = 16
/// let [p, q, _, s] = t.get(1, 1);
/// assert_eq!((p.to_array(), q.to_array()), ([1.0, 2.0, 3.0, 4.0], [3.0, 4.0, 5.0, 6.0]));
/// assert_eq!(s.to_array(), [11.0, 12.0, 13.0, 14.0]);
/// assert_eq!(t.get(0, 99)[3].to_array(), t.get(0, 2)[3].to_array()); // clamped
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Taps<'a, const N: usize> {
    slices: [&'a [f32]; N],
    dx: usize,
    dy: usize,
    last: usize,
}

impl<'a, const N: usize> Taps<'a, N> {
    /// `None` unless there is a slice, every slice has the first one's length, and that
    /// length holds four floats from `dx + dy`.
    pub fn new(slices: [&'a [f32]; N], dx: usize, dy: usize) -> Option<Taps<'a, N>> {
        let len = slices.first()?.len();
        let reach = dx.checked_add(dy)?.checked_add(4)?;
        if len < reach || slices.iter().any(|s| s.len() != len) {
            return None;
        }
        Some(Taps {
            slices,
            dx,
            dy,
            last: len - reach,
        })
    }

    /// The largest base index whose reads all lie inside: `i + dx + dy + 4 ≤ len` exactly
    /// when `i ≤ last`.
    #[inline(always)]
    pub fn last(&self) -> usize {
        self.last
    }

    /// The four floats at `i`, `i + dx`, `i + dy` and `i + dy + dx` of slice `k`, with `i`
    /// clamped to [`last`](Self::last) (panics when `k ≥ N`).
    #[inline(always)]
    pub fn get(&self, k: usize, i: usize) -> [F32x4; 4] {
        let s = self.slices[k];
        let i = i.min(self.last);
        let (j, dx) = (i + self.dy, self.dx);
        // SAFETY: `i ≤ last = len − (dx + dy + 4)`, so each read's four floats end at most
        // at `i + dy + dx + 4 ≤ len`, and every slice has length `len` (`new`); the fields
        // are never changed.
        unsafe {
            [
                F32x4::load_at(s, i),
                F32x4::load_at(s, i + dx),
                F32x4::load_at(s, j),
                F32x4::load_at(s, j + dx),
            ]
        }
    }
}

/// Bilinear footprints of one-channel layers, four at a time: for four base indices, the
/// two floats at `i` and `i + 1` and the two at `i + dy` and `i + dy + 1` (a footprint's
/// top and bottom pairs, `dy` the row stride), each pair read at once and the four bases'
/// reads turned into lanes. As [`Taps`], safe by construction: [`Pairs::new`] checks once
/// that the reads from base [`Pairs::last`] stay inside, and [`Pairs::get`] clamps each
/// base to it.
///
/// ```
/// use mirrorball_simd::Pairs;
/// let a: Vec<f32> = (0..16).map(|i| i as f32).collect();
/// let p = Pairs::new([&a[..]], 8).unwrap();
/// assert_eq!(p.last(), 6); // 6 + 8 + 2 = 16
/// let [t0, t1, b0, b1] = p.get([0; 4], [0, 2, 5, 99]);
/// assert_eq!((t0.to_array(), t1.to_array()), ([0.0, 2.0, 5.0, 6.0], [1.0, 3.0, 6.0, 7.0]));
/// assert_eq!((b0.to_array(), b1.to_array()), ([8.0, 10.0, 13.0, 14.0], [9.0, 11.0, 14.0, 15.0]));
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Pairs<'a, const N: usize> {
    slices: [&'a [f32]; N],
    dy: usize,
    last: usize,
}

impl<'a, const N: usize> Pairs<'a, N> {
    /// `None` unless there is a slice, every slice has the first one's length, and that
    /// length holds two floats from `dy`.
    pub fn new(slices: [&'a [f32]; N], dy: usize) -> Option<Pairs<'a, N>> {
        let len = slices.first()?.len();
        let reach = dy.checked_add(2)?;
        if len < reach || slices.iter().any(|s| s.len() != len) {
            return None;
        }
        Some(Pairs {
            slices,
            dy,
            last: len - reach,
        })
    }

    /// The largest base index whose reads all lie inside: `i + dy + 2 ≤ len` exactly when
    /// `i ≤ last`.
    #[inline(always)]
    pub fn last(&self) -> usize {
        self.last
    }

    /// For lane `j`, the footprint at base `i[j]` (clamped to [`last`](Self::last)) of
    /// slice `k[j]`: `[s[i], s[i + 1], s[i + dy], s[i + dy + 1]]` as four lanes each
    /// (panics when a `k[j] ≥ N`).
    #[inline(always)]
    pub fn get(&self, k: [usize; 4], i: [usize; 4]) -> [F32x4; 4] {
        let s = k.map(|k| self.slices[k]);
        let i = i.map(|i| i.min(self.last));
        let j = i.map(|i| i + self.dy);
        // SAFETY: `i ≤ last = len − (dy + 2)`, so both pairs end at most at
        // `i + dy + 2 ≤ len`, and every slice has length `len` (`new`); the fields are never
        // changed.
        let ([a, b], [c, d]) = unsafe { (F32x4::pairs_at(s, i), F32x4::pairs_at(s, j)) };
        [a, b, c, d]
    }
}

/// [`Pairs`] of one channel of integer codes, `B` bytes each (1, or 2 little-endian): for
/// four base indices (in codes), the codes at `i`, `i + 1`, `i + dy` and `i + dy + 1` as
/// `i32` lanes, each pair read at once. Safe by construction as [`Pairs`]: [`CodePairs::new`]
/// checks once that the reads from base [`CodePairs::last`] stay inside, and
/// [`CodePairs::get`] clamps each base to it.
///
/// ```
/// use mirrorball_simd::CodePairs;
/// let a: Vec<u8> = (0..16).collect();
/// let p = CodePairs::<1>::new(&a, 8).unwrap();
/// assert_eq!(p.last(), 6);
/// let [t0, t1, b0, _] = p.get([0, 2, 5, 99]);
/// assert_eq!((t0.to_array(), t1.to_array()), ([0, 2, 5, 6], [1, 3, 6, 7]));
/// assert_eq!(b0.to_array(), [8, 10, 13, 14]);
/// let b: Vec<u8> = [1u16, 1023, 7, 300].iter().flat_map(|c| c.to_le_bytes()).collect();
/// let [t0, t1, b0, b1] = CodePairs::<2>::new(&b, 2).unwrap().get([0; 4]);
/// assert_eq!((t0.to_array()[0], t1.to_array()[0], b0.to_array()[0], b1.to_array()[0]), (1, 1023, 7, 300));
/// ```
#[derive(Clone, Copy, Debug)]
pub struct CodePairs<'a, const B: usize> {
    bytes: &'a [u8],
    dy: usize,
    last: usize,
}

impl<'a, const B: usize> CodePairs<'a, B> {
    /// `None` unless `B` is 1 or 2 and `bytes` holds two codes from `dy` (a trailing odd
    /// byte of 2-byte codes is not a code).
    pub fn new(bytes: &'a [u8], dy: usize) -> Option<CodePairs<'a, B>> {
        if B != 1 && B != 2 {
            return None;
        }
        let codes = bytes.len() / B;
        let reach = dy.checked_add(2)?;
        if codes < reach {
            return None;
        }
        Some(CodePairs {
            bytes,
            dy,
            last: codes - reach,
        })
    }

    /// The largest base index whose reads all lie inside: `i + dy + 2 ≤ codes` exactly when
    /// `i ≤ last`.
    #[inline(always)]
    pub fn last(&self) -> usize {
        self.last
    }

    /// For lane `j`, the codes at base `i[j]` (clamped to [`last`](Self::last)):
    /// `[c(i), c(i + 1), c(i + dy), c(i + dy + 1)]` as four lanes each.
    #[inline(always)]
    pub fn get(&self, i: [usize; 4]) -> [I32x4; 4] {
        let i = i.map(|i| i.min(self.last));
        let p = self.bytes.as_ptr();
        // Both codes of the pair at code `k`, the first in the low bits.
        let pair = |k: usize| -> u32 {
            // SAFETY: `k ≤ last + dy = codes − 2`, so the pair's `2·B` bytes end at most at
            // `codes · B ≤ len` (`new`); the fields are never changed; reads are unaligned.
            unsafe {
                if B == 1 {
                    u16::from_le(std::ptr::read_unaligned(p.add(k) as *const u16)) as u32
                } else {
                    u32::from_le(std::ptr::read_unaligned(p.add(2 * k) as *const u32))
                }
            }
        };
        let (bits, mask) = (8 * B as u32, (1u32 << (8 * B)) - 1);
        let top = i.map(pair);
        let bottom = i.map(|i| pair(i + self.dy));
        [
            I32x4::from_array(top.map(|p| (p & mask) as i32)),
            I32x4::from_array(top.map(|p| (p >> bits) as i32)),
            I32x4::from_array(bottom.map(|p| (p & mask) as i32)),
            I32x4::from_array(bottom.map(|p| (p >> bits) as i32)),
        ]
    }
}

/// Defines an eight-lane kernel: a safe function whose first argument is the [`X8`] token
/// and whose body is compiled with AVX2 enabled on x86-64 (with the portable lanes, an
/// ordinary function).
///
/// The lane operations are `#[inline(always)]` wrappers of AVX2 intrinsics; they become
/// single instructions only inside a function compiled with AVX2. A closure does not
/// inherit its caller's target features, so hot eight-lane code must be such a kernel,
/// not a closure. Everything the body calls that is
/// `#[inline(always)]` is compiled into it with AVX2 too. Generic parameters are not
/// supported; the signature's lifetimes may be elided.
///
/// ```
/// use mirrorball_simd::{x8_kernel, X8};
/// x8_kernel! {
///     /// Adds `b` to `a`, eight at a time (the rest one at a time).
///     fn add_into(x8: X8, a: &mut [f32], b: &[f32]) {
///         let n = a.len().min(b.len()) / 8 * 8;
///         for i in (0..n).step_by(8) {
///             let s = x8.load(&a[i..]) + x8.load(&b[i..]);
///             a[i..i + 8].copy_from_slice(&s.to_array());
///         }
///         for i in n..a.len().min(b.len()) {
///             a[i] += b[i];
///         }
///     }
/// }
/// if let Some(x8) = X8::get() {
///     let mut a = [1.0f32; 11];
///     add_into(x8, &mut a, &[2.0; 11]);
///     assert_eq!(a, [3.0; 11]);
/// }
/// ```
#[cfg(all(target_arch = "x86_64", not(feature = "portable")))]
#[macro_export]
macro_rules! x8_kernel {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($x8:ident: X8 $(, $arg:ident: $ty:ty)* $(,)?) $(-> $ret:ty)? $body:block) => {
        $(#[$meta])*
        #[inline]
        #[allow(clippy::too_many_arguments)]
        $vis fn $name($x8: $crate::X8 $(, $arg: $ty)*) $(-> $ret)? {
            #[target_feature(enable = "avx2")]
            #[allow(clippy::too_many_arguments)]
            fn kernel($x8: $crate::X8 $(, $arg: $ty)*) $(-> $ret)? $body
            // SAFETY: an `X8` exists only where the processor has AVX2 (`X8::get`).
            unsafe { kernel($x8 $(, $arg)*) }
        }
    };
}

/// Defines an eight-lane kernel (see the x86-64 form): with the portable lanes, an
/// ordinary function.
#[cfg(not(all(target_arch = "x86_64", not(feature = "portable"))))]
#[macro_export]
macro_rules! x8_kernel {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($x8:ident: X8 $(, $arg:ident: $ty:ty)* $(,)?) $(-> $ret:ty)? $body:block) => {
        $(#[$meta])*
        #[inline]
        #[allow(clippy::too_many_arguments)]
        $vis fn $name($x8: $crate::X8 $(, $arg: $ty)*) $(-> $ret)? $body
    };
}

#[cfg(test)]
mod tests;
