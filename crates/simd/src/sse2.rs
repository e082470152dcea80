//! The four-lane types on SSE2, which every x86-64 processor has: each operation one
//! instruction (or a few), with the same results as [`crate::portable`]'s, bit for bit
//! (tested).

use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

// SAFETY (every `unsafe` block of this module): SSE2 is part of the x86-64 baseline, so
// its intrinsics are always available; those that touch memory are given pointers to
// arrays or slices checked to hold the lanes they read or write.

/// `x` truncated towards zero (`cvttss2si`: NaN and values outside the `i32` range give
/// `i32::MIN`).
#[inline(always)]
pub fn trunc_i32(x: f32) -> i32 {
    unsafe { _mm_cvttss_si32(_mm_set_ss(x)) }
}

/// A prefetch of the line holding `p` into all cache levels (never faults).
#[inline(always)]
pub fn prefetch<T>(p: *const T) {
    unsafe { _mm_prefetch::<_MM_HINT_T0>(p as *const i8) }
}

/// Four `f32` lanes.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32x4(__m128);

/// Four `i32` lanes.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct I32x4(__m128i);

/// A four-lane mask: each lane all ones (set) or all zeros.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct M32x4(__m128);

impl F32x4 {
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(x: f32) -> F32x4 {
        F32x4(unsafe { _mm_set1_ps(x) })
    }
    /// The lanes of `a`.
    #[inline(always)]
    pub fn from_array(a: [f32; 4]) -> F32x4 {
        F32x4(unsafe { _mm_loadu_ps(a.as_ptr()) })
    }
    /// The first four of `s` (panics when `s` is shorter).
    #[inline(always)]
    pub fn load(s: &[f32]) -> F32x4 {
        let s = &s[..4];
        F32x4(unsafe { _mm_loadu_ps(s.as_ptr()) })
    }
    /// The four floats from `s[i]` without a bounds check, for [`crate::Taps`].
    ///
    /// # Safety
    /// `i + 4 ≤ s.len()`.
    // Called only where these are the lanes in use.
    #[cfg_attr(feature = "portable", allow(dead_code))]
    #[inline(always)]
    pub(crate) unsafe fn load_at(s: &[f32], i: usize) -> F32x4 {
        debug_assert!(i + 4 <= s.len());
        // SAFETY: the caller's promise: the four floats are inside `s`.
        F32x4(unsafe { _mm_loadu_ps(s.as_ptr().add(i)) })
    }
    /// Two neighbouring floats at each of four places, as lanes: lane `j` of the first
    /// result is `s_j[i_j]`, of the second `s_j[i_j + 1]`, for [`crate::Pairs`].
    ///
    /// # Safety
    /// `i_j + 2 ≤ s_j.len()` for every `j`.
    // Called only where these are the lanes in use.
    #[cfg_attr(feature = "portable", allow(dead_code))]
    #[inline(always)]
    pub(crate) unsafe fn pairs_at(s: [&[f32]; 4], i: [usize; 4]) -> [F32x4; 2] {
        // SAFETY: the caller's promise: each pair of floats (eight bytes, read unaligned)
        // is inside its slice.
        unsafe {
            let q = |k: usize| {
                debug_assert!(i[k] + 2 <= s[k].len());
                std::ptr::read_unaligned(s[k].as_ptr().add(i[k]) as *const i64)
            };
            let p01 = _mm_castsi128_ps(_mm_set_epi64x(q(1), q(0)));
            let p23 = _mm_castsi128_ps(_mm_set_epi64x(q(3), q(2)));
            [
                F32x4(_mm_shuffle_ps::<0b10_00_10_00>(p01, p23)),
                F32x4(_mm_shuffle_ps::<0b11_01_11_01>(p01, p23)),
            ]
        }
    }
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f32; 4] {
        let mut a = [0.0; 4];
        unsafe { _mm_storeu_ps(a.as_mut_ptr(), self.0) };
        a
    }
    /// Writes the lanes to the start of `s` (panics when `s` is shorter).
    #[inline(always)]
    pub fn store(self, s: &mut [f32]) {
        let s = &mut s[..4];
        unsafe { _mm_storeu_ps(s.as_mut_ptr(), self.0) }
    }
    /// Writes the lanes as sixteen little-endian bytes to the start of `s` (panics when `s`
    /// is shorter).
    #[inline(always)]
    pub fn store_le_bytes(self, s: &mut [u8]) {
        let s = &mut s[..16];
        unsafe { _mm_storeu_ps(s.as_mut_ptr() as *mut f32, self.0) }
    }
    /// `|x|` (the sign bit cleared).
    #[inline(always)]
    pub fn abs(self) -> F32x4 {
        F32x4(unsafe { _mm_andnot_ps(_mm_set1_ps(-0.0), self.0) })
    }
    /// The lanes where `self ≥ o` (false for NaN).
    #[inline(always)]
    pub fn ge(self, o: F32x4) -> M32x4 {
        M32x4(unsafe { _mm_cmpge_ps(self.0, o.0) })
    }
    /// The lanes where `self > o` (false for NaN).
    #[inline(always)]
    pub fn gt(self, o: F32x4) -> M32x4 {
        M32x4(unsafe { _mm_cmpgt_ps(self.0, o.0) })
    }
    /// The lanes where `self < o` (false for NaN).
    #[inline(always)]
    pub fn lt(self, o: F32x4) -> M32x4 {
        M32x4(unsafe { _mm_cmplt_ps(self.0, o.0) })
    }
    /// The lanes where `self = o` (false for NaN).
    #[inline(always)]
    pub fn eq(self, o: F32x4) -> M32x4 {
        M32x4(unsafe { _mm_cmpeq_ps(self.0, o.0) })
    }
    /// Truncated towards zero (`cvttps2dq`: NaN, out of range: `i32::MIN`).
    #[inline(always)]
    pub fn trunc_i32(self) -> I32x4 {
        I32x4(unsafe { _mm_cvttps_epi32(self.0) })
    }
    /// The lanes' bits as `i32`.
    #[inline(always)]
    pub fn to_bits(self) -> I32x4 {
        I32x4(unsafe { _mm_castps_si128(self.0) })
    }
    /// `f32`s with the bits of `b`'s lanes.
    #[inline(always)]
    pub fn from_bits(b: I32x4) -> F32x4 {
        F32x4(unsafe { _mm_castsi128_ps(b.0) })
    }
    /// The 4×4 transpose of the rows `r`: lane `k` of output `j` is lane `j` of `r[k]`.
    #[inline(always)]
    pub fn transpose(r: [F32x4; 4]) -> [F32x4; 4] {
        let [mut a, mut b, mut c, mut d] = r.map(|v| v.0);
        unsafe { _MM_TRANSPOSE4_PS(&mut a, &mut b, &mut c, &mut d) };
        [a, b, c, d].map(F32x4)
    }
    /// Four RGB texels `[r0 g0 b0 r1] [g1 b1 r2 g2] [b2 r3 g3 b3]` as their channels
    /// `[r0 r1 r2 r3] [g…] [b…]`.
    #[inline(always)]
    pub fn deinterleave3(v: [F32x4; 3]) -> [F32x4; 3] {
        let [o0, o1, o2] = v.map(|v| v.0);
        unsafe {
            let rr = _mm_shuffle_ps::<0b01_01_10_10>(o1, o2); // r2 r2 r3 r3
            let r = _mm_shuffle_ps::<0b10_00_11_00>(o0, rr); // r0 r1 r2 r3
            let g01 = _mm_shuffle_ps::<0b00_00_01_01>(o0, o1); // g0 g0 g1 g1
            let g23 = _mm_shuffle_ps::<0b10_10_11_11>(o1, o2); // g2 g2 g3 g3
            let g = _mm_shuffle_ps::<0b10_00_10_00>(g01, g23); // g0 g1 g2 g3
            let b01 = _mm_shuffle_ps::<0b01_01_10_10>(o0, o1); // b0 b0 b1 b1
            let b23 = _mm_shuffle_ps::<0b11_11_00_00>(o2, o2); // b2 b2 b3 b3
            let b = _mm_shuffle_ps::<0b10_00_10_00>(b01, b23); // b0 b1 b2 b3
            [r, g, b].map(F32x4)
        }
    }
    /// The inverse of [`deinterleave3`](Self::deinterleave3): channels to RGB texels.
    #[inline(always)]
    pub fn interleave3(c: [F32x4; 3]) -> [F32x4; 3] {
        let [r, g, b] = c.map(|v| v.0);
        unsafe {
            let lo = _mm_unpacklo_ps(r, g); // r0 g0 r1 g1
            let hi = _mm_unpackhi_ps(r, g); // r2 g2 r3 g3
            let t0 = _mm_shuffle_ps::<0b10_10_00_00>(b, lo); // b0 b0 r1 r1
            let o0 = _mm_shuffle_ps::<0b10_00_01_00>(lo, t0); // r0 g0 b0 r1
            let t1 = _mm_shuffle_ps::<0b01_01_11_11>(lo, b); // g1 g1 b1 b1
            let o1 = _mm_shuffle_ps::<0b01_00_10_00>(t1, hi); // g1 b1 r2 g2
            let t2 = _mm_shuffle_ps::<0b10_10_10_10>(b, hi); // b2 b2 r3 r3
            let t3 = _mm_shuffle_ps::<0b11_11_11_11>(hi, b); // g3 g3 b3 b3
            let o2 = _mm_shuffle_ps::<0b10_00_10_00>(t2, t3); // b2 r3 g3 b3
            [o0, o1, o2].map(F32x4)
        }
    }
    /// Four little-endian `f32` whose bytes alternate between `evens` and `odds`: float `k`
    /// is made of `evens[2k], odds[2k], evens[2k + 1], odds[2k + 1]`.
    #[inline(always)]
    pub fn from_split_bytes(evens: &[u8; 8], odds: &[u8; 8]) -> F32x4 {
        unsafe {
            let e = _mm_loadl_epi64(evens.as_ptr() as *const __m128i);
            let o = _mm_loadl_epi64(odds.as_ptr() as *const __m128i);
            F32x4(_mm_castsi128_ps(_mm_unpacklo_epi8(e, o)))
        }
    }
}

impl Add for F32x4 {
    type Output = F32x4;
    #[inline(always)]
    fn add(self, o: F32x4) -> F32x4 {
        F32x4(unsafe { _mm_add_ps(self.0, o.0) })
    }
}
impl Sub for F32x4 {
    type Output = F32x4;
    #[inline(always)]
    fn sub(self, o: F32x4) -> F32x4 {
        F32x4(unsafe { _mm_sub_ps(self.0, o.0) })
    }
}
impl Mul for F32x4 {
    type Output = F32x4;
    #[inline(always)]
    fn mul(self, o: F32x4) -> F32x4 {
        F32x4(unsafe { _mm_mul_ps(self.0, o.0) })
    }
}
impl Div for F32x4 {
    type Output = F32x4;
    #[inline(always)]
    fn div(self, o: F32x4) -> F32x4 {
        F32x4(unsafe { _mm_div_ps(self.0, o.0) })
    }
}
impl Neg for F32x4 {
    type Output = F32x4;
    /// The sign bit flipped.
    #[inline(always)]
    fn neg(self) -> F32x4 {
        F32x4(unsafe { _mm_xor_ps(_mm_set1_ps(-0.0), self.0) })
    }
}

impl I32x4 {
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(x: i32) -> I32x4 {
        I32x4(unsafe { _mm_set1_epi32(x) })
    }
    /// The lanes of `a`.
    #[inline(always)]
    pub fn from_array(a: [i32; 4]) -> I32x4 {
        I32x4(unsafe { _mm_loadu_si128(a.as_ptr() as *const __m128i) })
    }
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [i32; 4] {
        let mut a = [0; 4];
        unsafe { _mm_storeu_si128(a.as_mut_ptr() as *mut __m128i, self.0) };
        a
    }
    /// Each lane as the nearest `f32` (round to nearest even).
    #[inline(always)]
    pub fn to_f32(self) -> F32x4 {
        F32x4(unsafe { _mm_cvtepi32_ps(self.0) })
    }
    /// The lanes where `self > o`.
    #[inline(always)]
    pub fn gt(self, o: I32x4) -> M32x4 {
        M32x4(unsafe { _mm_castsi128_ps(_mm_cmpgt_epi32(self.0, o.0)) })
    }
    /// The lanes where `self < o`.
    #[inline(always)]
    pub fn lt(self, o: I32x4) -> M32x4 {
        M32x4(unsafe { _mm_castsi128_ps(_mm_cmplt_epi32(self.0, o.0)) })
    }
    /// The lanes where `self = o`.
    #[inline(always)]
    pub fn eq(self, o: I32x4) -> M32x4 {
        M32x4(unsafe { _mm_castsi128_ps(_mm_cmpeq_epi32(self.0, o.0)) })
    }
}

impl Add for I32x4 {
    type Output = I32x4;
    /// Wrapping.
    #[inline(always)]
    fn add(self, o: I32x4) -> I32x4 {
        I32x4(unsafe { _mm_add_epi32(self.0, o.0) })
    }
}
impl Sub for I32x4 {
    type Output = I32x4;
    /// Wrapping.
    #[inline(always)]
    fn sub(self, o: I32x4) -> I32x4 {
        I32x4(unsafe { _mm_sub_epi32(self.0, o.0) })
    }
}

impl M32x4 {
    /// Lane `k` set where `b[k]`.
    #[inline(always)]
    pub fn from_bools(b: [bool; 4]) -> M32x4 {
        let a = b.map(|x| -(x as i32));
        M32x4(unsafe { _mm_castsi128_ps(_mm_loadu_si128(a.as_ptr() as *const __m128i)) })
    }
    /// Lane `k` set where bit `k` of `bits` is.
    #[inline(always)]
    pub fn from_bitmask(bits: u32) -> M32x4 {
        unsafe {
            let b = _mm_setr_epi32(1, 2, 4, 8);
            let m = _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(bits as i32), b), b);
            M32x4(_mm_castsi128_ps(m))
        }
    }
    /// Bit `k` set where lane `k` is.
    #[inline(always)]
    pub fn bitmask(self) -> u32 {
        unsafe { _mm_movemask_ps(self.0) as u32 }
    }
    /// Whether every lane is set.
    #[inline(always)]
    pub fn all(self) -> bool {
        self.bitmask() == 0xF
    }
    /// Whether any lane is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.bitmask() != 0
    }
    /// Each lane as an `i32`: −1 where set, else 0.
    #[inline(always)]
    pub fn to_i32(self) -> I32x4 {
        I32x4(unsafe { _mm_castps_si128(self.0) })
    }
    /// `self & !o`.
    #[inline(always)]
    pub fn and_not(self, o: M32x4) -> M32x4 {
        M32x4(unsafe { _mm_andnot_ps(o.0, self.0) })
    }
    /// `a` where set, else `b`, lane by lane.
    #[inline(always)]
    pub fn select(self, a: F32x4, b: F32x4) -> F32x4 {
        F32x4(unsafe { _mm_or_ps(_mm_and_ps(self.0, a.0), _mm_andnot_ps(self.0, b.0)) })
    }
    /// [`select`](Self::select) of `i32` lanes.
    #[inline(always)]
    pub fn select_i32(self, a: I32x4, b: I32x4) -> I32x4 {
        unsafe {
            let m = _mm_castps_si128(self.0);
            I32x4(_mm_or_si128(
                _mm_and_si128(m, a.0),
                _mm_andnot_si128(m, b.0),
            ))
        }
    }
}

impl BitAnd for M32x4 {
    type Output = M32x4;
    #[inline(always)]
    fn bitand(self, o: M32x4) -> M32x4 {
        M32x4(unsafe { _mm_and_ps(self.0, o.0) })
    }
}
impl BitOr for M32x4 {
    type Output = M32x4;
    #[inline(always)]
    fn bitor(self, o: M32x4) -> M32x4 {
        M32x4(unsafe { _mm_or_ps(self.0, o.0) })
    }
}
impl Not for M32x4 {
    type Output = M32x4;
    #[inline(always)]
    fn not(self) -> M32x4 {
        M32x4(unsafe { _mm_xor_ps(self.0, _mm_castsi128_ps(_mm_set1_epi32(-1))) })
    }
}

/// `b[i] = b[i − 1] + b[i] − bias` (modulo 256) for every byte but the first, sixteen bytes
/// a step: the sum within the sixteen in four shift-and-add steps, then the carry of the
/// bytes before, kept in a vector register (its last byte broadcast in three shuffles) so
/// that the dependency chain from step to step is one addition long.
pub fn prefix_sum_biased(b: &mut [u8], bias: u8) {
    if b.len() < 2 {
        return;
    }
    let mut prev = b[0];
    let mut i = 1;
    // Every load and store covers `b[i..i + 16]`, inside the slice by the loop condition.
    unsafe {
        let bias = _mm_set1_epi8(bias.wrapping_neg() as i8);
        // Every byte: the running value before the step.
        let mut carry = _mm_set1_epi8(prev as i8);
        while i + 16 <= b.len() {
            let p = b.as_mut_ptr().add(i) as *mut __m128i;
            let mut x = _mm_add_epi8(_mm_loadu_si128(p), bias);
            x = _mm_add_epi8(x, _mm_slli_si128::<1>(x));
            x = _mm_add_epi8(x, _mm_slli_si128::<2>(x));
            x = _mm_add_epi8(x, _mm_slli_si128::<4>(x));
            x = _mm_add_epi8(x, _mm_slli_si128::<8>(x));
            x = _mm_add_epi8(x, carry);
            _mm_storeu_si128(p, x);
            // Byte 15 to all sixteen: bytes 8..16 doubled into words 4..8, word 7 to
            // words 4..8, then dword 3 to all four.
            let hi = _mm_unpackhi_epi8(x, x);
            carry = _mm_shuffle_epi32::<0xFF>(_mm_shufflehi_epi16::<0xFF>(hi));
            i += 16;
        }
    }
    if i > 1 {
        prev = b[i - 1];
    }
    for v in &mut b[i..] {
        prev = prev.wrapping_add(*v).wrapping_sub(bias);
        *v = prev;
    }
}
