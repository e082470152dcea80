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
