//! The lanes as plain arrays, one loop a lane, which LLVM vectorises where it can: the
//! implementation on targets other than x86-64 and under the `portable` feature, and the
//! reference the x86-64 implementation is tested against.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// `x` truncated as x86's `cvttss2si` does: NaN and values outside the `i32` range give
/// `i32::MIN`.
#[inline(always)]
pub fn trunc_i32(x: f32) -> i32 {
    // -2^31 ≤ x < 2^31: both bounds are exact in f32; NaN fails.
    if (-2_147_483_648.0..2_147_483_648.0).contains(&x) {
        x as i32
    } else {
        i32::MIN
    }
}

macro_rules! lanes {
    ($f:ident, $i:ident, $m:ident, $n:literal, $align:literal) => {
        /// Lanes of `f32`.
        #[derive(Clone, Copy, Debug, PartialEq)]
        #[repr(C, align($align))]
        pub struct $f(pub(crate) [f32; $n]);

        /// Lanes of `i32`.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        #[repr(C, align($align))]
        pub struct $i(pub(crate) [i32; $n]);

        /// A lane mask: each lane all ones (set) or all zeros.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        #[repr(C, align($align))]
        pub struct $m(pub(crate) [i32; $n]);

        impl $f {
            /// Every lane `x`.
            #[inline(always)]
            pub fn splat(x: f32) -> $f {
                $f([x; $n])
            }
            /// The lanes of `a`.
            #[inline(always)]
            pub fn from_array(a: [f32; $n]) -> $f {
                $f(a)
            }
            /// The first lanes' worth of `s` (panics when `s` is shorter).
            #[inline(always)]
            pub fn load(s: &[f32]) -> $f {
                $f(s[..$n].try_into().unwrap())
            }
            /// The lanes as an array.
            #[inline(always)]
            pub fn to_array(self) -> [f32; $n] {
                self.0
            }
            /// Writes the lanes to the start of `s` (panics when `s` is shorter).
            #[inline(always)]
            pub fn store(self, s: &mut [f32]) {
                s[..$n].copy_from_slice(&self.0);
            }
            #[inline(always)]
            fn map(self, f: impl Fn(f32) -> f32) -> $f {
                $f(self.0.map(f))
            }
            #[inline(always)]
            fn zip(self, o: $f, f: impl Fn(f32, f32) -> f32) -> $f {
                $f(std::array::from_fn(|k| f(self.0[k], o.0[k])))
            }
            #[inline(always)]
            fn test(self, o: $f, f: impl Fn(f32, f32) -> bool) -> $m {
                $m(std::array::from_fn(|k| -(f(self.0[k], o.0[k]) as i32)))
            }
            /// `|x|` (the sign bit cleared).
            #[inline(always)]
            pub fn abs(self) -> $f {
                self.map(f32::abs)
            }
            /// The lanes where `self ≥ o` (false for NaN).
            #[inline(always)]
            pub fn ge(self, o: $f) -> $m {
                self.test(o, |a, b| a >= b)
            }
            /// The lanes where `self > o` (false for NaN).
            #[inline(always)]
            pub fn gt(self, o: $f) -> $m {
                self.test(o, |a, b| a > b)
            }
            /// The lanes where `self < o` (false for NaN).
            #[inline(always)]
            pub fn lt(self, o: $f) -> $m {
                self.test(o, |a, b| a < b)
            }
            /// The lanes where `self = o` (false for NaN).
            #[inline(always)]
            pub fn eq(self, o: $f) -> $m {
                self.test(o, |a, b| a == b)
            }
            /// Truncated towards zero as [`trunc_i32`] (NaN, out of range: `i32::MIN`).
            #[inline(always)]
            pub fn trunc_i32(self) -> $i {
                $i(self.0.map(trunc_i32))
            }
            /// The lanes' bits as `i32`.
            #[inline(always)]
            pub fn to_bits(self) -> $i {
                $i(self.0.map(|x| x.to_bits() as i32))
            }
            /// `f32`s with the bits of `b`'s lanes.
            #[inline(always)]
            pub fn from_bits(b: $i) -> $f {
                $f(b.0.map(|x| f32::from_bits(x as u32)))
            }
        }

        impl Add for $f {
            type Output = $f;
            #[inline(always)]
            fn add(self, o: $f) -> $f {
                self.zip(o, |a, b| a + b)
            }
        }
        impl Sub for $f {
            type Output = $f;
            #[inline(always)]
            fn sub(self, o: $f) -> $f {
                self.zip(o, |a, b| a - b)
            }
        }
        impl Mul for $f {
            type Output = $f;
            #[inline(always)]
            fn mul(self, o: $f) -> $f {
                self.zip(o, |a, b| a * b)
            }
        }
        impl Div for $f {
            type Output = $f;
            #[inline(always)]
            fn div(self, o: $f) -> $f {
                self.zip(o, |a, b| a / b)
            }
        }
        impl Neg for $f {
            type Output = $f;
            /// The sign bit flipped.
            #[inline(always)]
            fn neg(self) -> $f {
                self.map(|x| -x)
            }
        }

        impl $i {
            /// Every lane `x`.
            #[inline(always)]
            pub fn splat(x: i32) -> $i {
                $i([x; $n])
            }
            /// The lanes of `a`.
            #[inline(always)]
            pub fn from_array(a: [i32; $n]) -> $i {
                $i(a)
            }
            /// The lanes as an array.
            #[inline(always)]
            pub fn to_array(self) -> [i32; $n] {
                self.0
            }
            /// Each lane as the nearest `f32` (round to nearest even).
            #[inline(always)]
            pub fn to_f32(self) -> $f {
                $f(self.0.map(|x| x as f32))
            }
            /// The lanes where `self > o`.
            #[inline(always)]
            pub fn gt(self, o: $i) -> $m {
                $m(std::array::from_fn(|k| -((self.0[k] > o.0[k]) as i32)))
            }
            /// The lanes where `self < o`.
            #[inline(always)]
            pub fn lt(self, o: $i) -> $m {
                o.gt(self)
            }
            /// The lanes where `self = o`.
            #[inline(always)]
            pub fn eq(self, o: $i) -> $m {
                $m(std::array::from_fn(|k| -((self.0[k] == o.0[k]) as i32)))
            }
        }

        impl Add for $i {
            type Output = $i;
            /// Wrapping.
            #[inline(always)]
            fn add(self, o: $i) -> $i {
                $i(std::array::from_fn(|k| self.0[k].wrapping_add(o.0[k])))
            }
        }
        impl Sub for $i {
            type Output = $i;
            /// Wrapping.
            #[inline(always)]
            fn sub(self, o: $i) -> $i {
                $i(std::array::from_fn(|k| self.0[k].wrapping_sub(o.0[k])))
            }
        }

        impl $m {
            /// Lane `k` set where `b[k]`.
            #[inline(always)]
            pub fn from_bools(b: [bool; $n]) -> $m {
                $m(b.map(|x| -(x as i32)))
            }
            /// Lane `k` set where bit `k` of `bits` is.
            #[inline(always)]
            pub fn from_bitmask(bits: u32) -> $m {
                $m(std::array::from_fn(|k| -(((bits >> k) & 1) as i32)))
            }
            /// Bit `k` set where lane `k` is.
            #[inline(always)]
            pub fn bitmask(self) -> u32 {
                let mut b = 0;
                for k in 0..$n {
                    b |= ((self.0[k] < 0) as u32) << k;
                }
                b
            }
            /// Whether every lane is set.
            #[inline(always)]
            pub fn all(self) -> bool {
                self.bitmask() == (1 << $n) - 1
            }
            /// Whether any lane is set.
            #[inline(always)]
            pub fn any(self) -> bool {
                self.bitmask() != 0
            }
            /// Each lane as an `i32`: −1 where set, else 0.
            #[inline(always)]
            pub fn to_i32(self) -> $i {
                $i(self.0)
            }
            /// `self & !o`.
            #[inline(always)]
            pub fn and_not(self, o: $m) -> $m {
                $m(std::array::from_fn(|k| self.0[k] & !o.0[k]))
            }
            /// `a` where set, else `b`, lane by lane.
            #[inline(always)]
            pub fn select(self, a: $f, b: $f) -> $f {
                $f(std::array::from_fn(|k| if self.0[k] != 0 { a.0[k] } else { b.0[k] }))
            }
            /// [`select`](Self::select) of `i32` lanes.
            #[inline(always)]
            pub fn select_i32(self, a: $i, b: $i) -> $i {
                $i(std::array::from_fn(|k| if self.0[k] != 0 { a.0[k] } else { b.0[k] }))
            }
        }

        impl BitAnd for $m {
            type Output = $m;
            #[inline(always)]
            fn bitand(self, o: $m) -> $m {
                $m(std::array::from_fn(|k| self.0[k] & o.0[k]))
            }
        }
        impl BitOr for $m {
            type Output = $m;
            #[inline(always)]
            fn bitor(self, o: $m) -> $m {
                $m(std::array::from_fn(|k| self.0[k] | o.0[k]))
            }
        }
        impl Not for $m {
            type Output = $m;
            #[inline(always)]
            fn not(self) -> $m {
                $m(self.0.map(|x| !x))
            }
        }
    };
}

lanes!(F32x4, I32x4, M32x4, 4, 16);
lanes!(F32x8, I32x8, M32x8, 8, 32);

impl F32x4 {
    /// The four floats from `s[i]` (checked here: the portable lanes keep every bounds
    /// check), for [`crate::Taps`].
    ///
    /// # Safety
    /// None needed; `unsafe` to match the SSE2 form, which needs `i + 4 ≤ s.len()`.
    // Called only where these are the lanes in use.
    #[cfg_attr(
        all(target_arch = "x86_64", not(feature = "portable")),
        allow(dead_code)
    )]
    #[inline(always)]
    pub(crate) unsafe fn load_at(s: &[f32], i: usize) -> F32x4 {
        F32x4::load(&s[i..])
    }

    /// Two neighbouring floats at each of four places, as lanes (checked here), for
    /// [`crate::Pairs`].
    ///
    /// # Safety
    /// None needed; `unsafe` to match the SSE2 form, which needs `i_j + 2 ≤ s_j.len()`.
    #[cfg_attr(
        all(target_arch = "x86_64", not(feature = "portable")),
        allow(dead_code)
    )]
    #[inline(always)]
    pub(crate) unsafe fn pairs_at(s: [&[f32]; 4], i: [usize; 4]) -> [F32x4; 2] {
        [
            F32x4(std::array::from_fn(|j| s[j][i[j]])),
            F32x4(std::array::from_fn(|j| s[j][i[j] + 1])),
        ]
    }

    /// Writes the lanes as sixteen little-endian bytes to the start of `s` (panics when `s`
    /// is shorter).
    #[inline(always)]
    pub fn store_le_bytes(self, s: &mut [u8]) {
        for (o, x) in s[..16].chunks_exact_mut(4).zip(self.0) {
            o.copy_from_slice(&x.to_le_bytes());
        }
    }

    /// The 4×4 transpose of the rows `r`: lane `k` of output `j` is lane `j` of `r[k]`.
    #[inline(always)]
    pub fn transpose(r: [F32x4; 4]) -> [F32x4; 4] {
        std::array::from_fn(|j| F32x4(std::array::from_fn(|k| r[k].0[j])))
    }

    /// Four RGB texels `[r0 g0 b0 r1] [g1 b1 r2 g2] [b2 r3 g3 b3]` as their channels
    /// `[r0 r1 r2 r3] [g…] [b…]`.
    #[inline(always)]
    pub fn deinterleave3(v: [F32x4; 3]) -> [F32x4; 3] {
        let s: [f32; 12] = std::array::from_fn(|i| v[i / 4].0[i % 4]);
        std::array::from_fn(|c| F32x4(std::array::from_fn(|k| s[3 * k + c])))
    }

    /// The inverse of [`deinterleave3`](Self::deinterleave3): channels to RGB texels.
    #[inline(always)]
    pub fn interleave3(c: [F32x4; 3]) -> [F32x4; 3] {
        let s: [f32; 12] = std::array::from_fn(|i| c[i % 3].0[i / 3]);
        std::array::from_fn(|j| F32x4(std::array::from_fn(|k| s[4 * j + k])))
    }

    /// Four little-endian `f32` whose bytes alternate between `evens` and `odds`: float `k`
    /// is made of `evens[2k], odds[2k], evens[2k + 1], odds[2k + 1]`.
    #[inline(always)]
    pub fn from_split_bytes(evens: &[u8; 8], odds: &[u8; 8]) -> F32x4 {
        F32x4(std::array::from_fn(|k| {
            f32::from_le_bytes([evens[2 * k], odds[2 * k], evens[2 * k + 1], odds[2 * k + 1]])
        }))
    }
}

impl I32x8 {
    /// The lanes of eight `u32` (their bits).
    #[inline(always)]
    pub fn from_u32s(a: &[u32; 8]) -> I32x8 {
        I32x8(a.map(|x| x as i32))
    }
    /// Each lane's bits shifted right by `n`, zeros shifted in (0 from `n` ≥ 32).
    #[inline(always)]
    pub fn shift_right(self, n: u32) -> I32x8 {
        I32x8(
            self.0
                .map(|x| (x as u32).checked_shr(n).unwrap_or(0) as i32),
        )
    }
}

impl BitAnd for I32x8 {
    type Output = I32x8;
    #[inline(always)]
    fn bitand(self, o: I32x8) -> I32x8 {
        I32x8(std::array::from_fn(|k| self.0[k] & o.0[k]))
    }
}

impl Mul for I32x8 {
    type Output = I32x8;
    /// Wrapping (the low 32 bits of the product).
    #[inline(always)]
    fn mul(self, o: I32x8) -> I32x8 {
        I32x8(std::array::from_fn(|k| self.0[k].wrapping_mul(o.0[k])))
    }
}

impl F32x8 {
    /// Eight `[c0, c1, c2, c3]` of four channels' lanes: pixel `k` is lane `k` of each.
    #[inline(always)]
    pub fn interleave4(c: [F32x8; 4]) -> [[f32; 4]; 8] {
        std::array::from_fn(|k| c.map(|v| v.0[k]))
    }
}

/// The proof that eight-lane types can be made, and the way to make them: on this
/// implementation always there.
#[derive(Clone, Copy, Debug)]
pub struct X8(());

impl X8 {
    /// The token (always, here).
    #[inline]
    pub fn get() -> Option<X8> {
        Some(X8(()))
    }
    /// [`F32x8::splat`].
    #[inline(always)]
    pub fn splat(self, x: f32) -> F32x8 {
        F32x8::splat(x)
    }
    /// [`F32x8::from_array`].
    #[inline(always)]
    pub fn f32s(self, a: [f32; 8]) -> F32x8 {
        F32x8::from_array(a)
    }
    /// [`F32x8::load`].
    #[inline(always)]
    pub fn load(self, s: &[f32]) -> F32x8 {
        F32x8::load(s)
    }
    /// [`I32x8::splat`].
    #[inline(always)]
    pub fn splat_i32(self, x: i32) -> I32x8 {
        I32x8::splat(x)
    }
    /// [`I32x8::from_u32s`].
    #[inline(always)]
    pub fn u32s(self, a: &[u32; 8]) -> I32x8 {
        I32x8::from_u32s(a)
    }
    /// [`M32x8::from_bitmask`].
    #[inline(always)]
    pub fn mask(self, bits: u32) -> M32x8 {
        M32x8::from_bitmask(bits)
    }
    /// Lane `k` is `table[idx[k]]`, each index clamped to the table (`0..table.len()`).
    ///
    /// # Panics
    /// If `table` is empty or longer than `i32::MAX`.
    #[inline(always)]
    pub fn gather(self, table: &[f32], idx: I32x8) -> F32x8 {
        assert!(!table.is_empty() && table.len() <= i32::MAX as usize);
        let last = table.len() as i32 - 1;
        F32x8(idx.0.map(|i| table[i.clamp(0, last) as usize]))
    }
}

/// `b[i] = b[i − 1] + b[i] − bias` (modulo 256) for every byte but the first: a running sum
/// of `b[i] − bias` (the predictor that OpenEXR's ZIP and RLE compressions undo).
pub fn prefix_sum_biased(b: &mut [u8], bias: u8) {
    let Some((&mut first, rest)) = b.split_first_mut() else {
        return;
    };
    let mut prev = first;
    for v in rest {
        prev = prev.wrapping_add(*v).wrapping_sub(bias);
        *v = prev;
    }
}
