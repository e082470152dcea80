//! The eight-lane types on AVX2, chosen at run time: with the same results as
//! [`crate::portable`]'s, bit for bit (tested where the processor has AVX2).
//!
//! A value of [`F32x8`], [`I32x8`] or [`M32x8`] is made only through an [`X8`] token, and
//! [`X8::get`] hands one out only where the processor has AVX2: so every operation on a
//! value that exists is safe to run. The operations are `#[inline(always)]` and meant to be
//! used inside a kernel defined with [`crate::x8_kernel!`], whose body is compiled with AVX2
//! enabled, so that they become single instructions; elsewhere (in a closure, even one
//! written inside a kernel) they still give the same results, a call each.

use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

// SAFETY (every `unsafe` block of this module): AVX2 is available, since a value of the
// module's types or an `X8` exists only once `X8::get` has found it; the intrinsics that
// touch memory are given pointers to arrays or slices checked to hold the lanes they read
// or write.

/// The proof that the processor has AVX2, and the way to make eight-lane values.
#[derive(Clone, Copy, Debug)]
pub struct X8(());

impl X8 {
    /// The token, where the processor has AVX2 (asked once, then cached by the standard
    /// library).
    #[inline]
    pub fn get() -> Option<X8> {
        std::is_x86_feature_detected!("avx2").then_some(X8(()))
    }
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(self, x: f32) -> F32x8 {
        F32x8(unsafe { _mm256_set1_ps(x) })
    }
    /// The lanes of `a`.
    #[inline(always)]
    pub fn f32s(self, a: [f32; 8]) -> F32x8 {
        F32x8(unsafe { _mm256_loadu_ps(a.as_ptr()) })
    }
    /// The first eight of `s` (panics when `s` is shorter).
    #[inline(always)]
    pub fn load(self, s: &[f32]) -> F32x8 {
        let s = &s[..8];
        F32x8(unsafe { _mm256_loadu_ps(s.as_ptr()) })
    }
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat_i32(self, x: i32) -> I32x8 {
        I32x8(unsafe { _mm256_set1_epi32(x) })
    }
    /// The lanes of eight `u32` (their bits).
    #[inline(always)]
    pub fn u32s(self, a: &[u32; 8]) -> I32x8 {
        I32x8(unsafe { _mm256_loadu_si256(a.as_ptr() as *const __m256i) })
    }
    /// Lane `k` is `table[idx[k]]`, each index clamped to the table (`0..table.len()`):
    /// a table lookup of eight lanes at once (one `vpgatherdps`).
    ///
    /// # Panics
    /// If `table` is empty or longer than `i32::MAX`.
    #[inline(always)]
    pub fn gather(self, table: &[f32], idx: I32x8) -> F32x8 {
        assert!(!table.is_empty() && table.len() <= i32::MAX as usize);
        unsafe {
            let last = _mm256_set1_epi32(table.len() as i32 - 1);
            let i = _mm256_min_epi32(_mm256_max_epi32(idx.0, _mm256_setzero_si256()), last);
            // Every index is now inside `table`.
            F32x8(_mm256_i32gather_ps::<4>(table.as_ptr(), i))
        }
    }
    /// Lane `k` set where bit `k` of `bits` is.
    #[inline(always)]
    pub fn mask(self, bits: u32) -> M32x8 {
        unsafe {
            let b = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
            let m = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(bits as i32), b), b);
            M32x8(_mm256_castsi256_ps(m))
        }
    }
}

/// Eight `f32` lanes.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32x8(__m256);

/// Eight `i32` lanes.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct I32x8(__m256i);

/// An eight-lane mask: each lane all ones (set) or all zeros.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct M32x8(__m256);

impl F32x8 {
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f32; 8] {
        let mut a = [0.0; 8];
        unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) };
        a
    }
    /// Writes the lanes to the start of `s` (panics when `s` is shorter).
    #[inline(always)]
    pub fn store(self, s: &mut [f32]) {
        let s = &mut s[..8];
        unsafe { _mm256_storeu_ps(s.as_mut_ptr(), self.0) }
    }
    /// `|x|` (the sign bit cleared).
    #[inline(always)]
    pub fn abs(self) -> F32x8 {
        F32x8(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
    }
    /// The lanes where `self ≥ o` (false for NaN).
    #[inline(always)]
    pub fn ge(self, o: F32x8) -> M32x8 {
        M32x8(unsafe { _mm256_cmp_ps::<_CMP_GE_OQ>(self.0, o.0) })
    }
    /// The lanes where `self > o` (false for NaN).
    #[inline(always)]
    pub fn gt(self, o: F32x8) -> M32x8 {
        M32x8(unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0) })
    }
    /// The lanes where `self < o` (false for NaN).
    #[inline(always)]
    pub fn lt(self, o: F32x8) -> M32x8 {
        M32x8(unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0) })
    }
    /// The lanes where `self = o` (false for NaN).
    #[inline(always)]
    pub fn eq(self, o: F32x8) -> M32x8 {
        M32x8(unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0) })
    }
    /// Truncated towards zero (`cvttps2dq`: NaN, out of range: `i32::MIN`).
    #[inline(always)]
    pub fn trunc_i32(self) -> I32x8 {
        I32x8(unsafe { _mm256_cvttps_epi32(self.0) })
    }
    /// The lanes' bits as `i32`.
    #[inline(always)]
    pub fn to_bits(self) -> I32x8 {
        I32x8(unsafe { _mm256_castps_si256(self.0) })
    }
    /// `f32`s with the bits of `b`'s lanes.
    #[inline(always)]
    pub fn from_bits(b: I32x8) -> F32x8 {
        F32x8(unsafe { _mm256_castsi256_ps(b.0) })
    }
    /// Eight `[c0, c1, c2, c3]` of four channels' lanes: pixel `k` is lane `k` of each.
    #[inline(always)]
    pub fn interleave4(c: [F32x8; 4]) -> [[f32; 4]; 8] {
        let [r, g, b, a] = c.map(|v| v.0);
        let mut out = [[0.0f32; 4]; 8];
        let o = out.as_mut_ptr() as *mut f32;
        // `out` holds 32 floats.
        unsafe {
            let (rg_lo, rg_hi) = (_mm256_unpacklo_ps(r, g), _mm256_unpackhi_ps(r, g));
            let (ba_lo, ba_hi) = (_mm256_unpacklo_ps(b, a), _mm256_unpackhi_ps(b, a));
            // Pixels 0|4, 1|5, 2|6, 3|7, then their halves put in order.
            let p04 = _mm256_shuffle_ps::<0x44>(rg_lo, ba_lo);
            let p15 = _mm256_shuffle_ps::<0xEE>(rg_lo, ba_lo);
            let p26 = _mm256_shuffle_ps::<0x44>(rg_hi, ba_hi);
            let p37 = _mm256_shuffle_ps::<0xEE>(rg_hi, ba_hi);
            _mm256_storeu_ps(o, _mm256_permute2f128_ps::<0x20>(p04, p15));
            _mm256_storeu_ps(o.add(8), _mm256_permute2f128_ps::<0x20>(p26, p37));
            _mm256_storeu_ps(o.add(16), _mm256_permute2f128_ps::<0x31>(p04, p15));
            _mm256_storeu_ps(o.add(24), _mm256_permute2f128_ps::<0x31>(p26, p37));
        }
        out
    }
}

impl Add for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn add(self, o: F32x8) -> F32x8 {
        F32x8(unsafe { _mm256_add_ps(self.0, o.0) })
    }
}
impl Sub for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn sub(self, o: F32x8) -> F32x8 {
        F32x8(unsafe { _mm256_sub_ps(self.0, o.0) })
    }
}
impl Mul for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn mul(self, o: F32x8) -> F32x8 {
        F32x8(unsafe { _mm256_mul_ps(self.0, o.0) })
    }
}
impl Div for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn div(self, o: F32x8) -> F32x8 {
        F32x8(unsafe { _mm256_div_ps(self.0, o.0) })
    }
}
impl Neg for F32x8 {
    type Output = F32x8;
    /// The sign bit flipped.
    #[inline(always)]
    fn neg(self) -> F32x8 {
        F32x8(unsafe { _mm256_xor_ps(_mm256_set1_ps(-0.0), self.0) })
    }
}

impl I32x8 {
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [i32; 8] {
        let mut a = [0; 8];
        unsafe { _mm256_storeu_si256(a.as_mut_ptr() as *mut __m256i, self.0) };
        a
    }
    /// Each lane as the nearest `f32` (round to nearest even).
    #[inline(always)]
    pub fn to_f32(self) -> F32x8 {
        F32x8(unsafe { _mm256_cvtepi32_ps(self.0) })
    }
    /// The lanes where `self > o`.
    #[inline(always)]
    pub fn gt(self, o: I32x8) -> M32x8 {
        M32x8(unsafe { _mm256_castsi256_ps(_mm256_cmpgt_epi32(self.0, o.0)) })
    }
    /// The lanes where `self < o`.
    #[inline(always)]
    pub fn lt(self, o: I32x8) -> M32x8 {
        o.gt(self)
    }
    /// The lanes where `self = o`.
    #[inline(always)]
    pub fn eq(self, o: I32x8) -> M32x8 {
        M32x8(unsafe { _mm256_castsi256_ps(_mm256_cmpeq_epi32(self.0, o.0)) })
    }
    /// Each lane's bits shifted right by `n`, zeros shifted in (0 from `n` ≥ 32).
    #[inline(always)]
    pub fn shift_right(self, n: u32) -> I32x8 {
        I32x8(unsafe { _mm256_srl_epi32(self.0, _mm_cvtsi32_si128(n.min(32) as i32)) })
    }
}

impl BitAnd for I32x8 {
    type Output = I32x8;
    #[inline(always)]
    fn bitand(self, o: I32x8) -> I32x8 {
        I32x8(unsafe { _mm256_and_si256(self.0, o.0) })
    }
}

impl Add for I32x8 {
    type Output = I32x8;
    /// Wrapping.
    #[inline(always)]
    fn add(self, o: I32x8) -> I32x8 {
        I32x8(unsafe { _mm256_add_epi32(self.0, o.0) })
    }
}
impl Sub for I32x8 {
    type Output = I32x8;
    /// Wrapping.
    #[inline(always)]
    fn sub(self, o: I32x8) -> I32x8 {
        I32x8(unsafe { _mm256_sub_epi32(self.0, o.0) })
    }
}
impl Mul for I32x8 {
    type Output = I32x8;
    /// Wrapping (the low 32 bits of the product).
    #[inline(always)]
    fn mul(self, o: I32x8) -> I32x8 {
        I32x8(unsafe { _mm256_mullo_epi32(self.0, o.0) })
    }
}

impl M32x8 {
    /// Bit `k` set where lane `k` is.
    #[inline(always)]
    pub fn bitmask(self) -> u32 {
        unsafe { _mm256_movemask_ps(self.0) as u32 }
    }
    /// Whether every lane is set.
    #[inline(always)]
    pub fn all(self) -> bool {
        self.bitmask() == 0xFF
    }
    /// Whether any lane is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.bitmask() != 0
    }
    /// Each lane as an `i32`: −1 where set, else 0.
    #[inline(always)]
    pub fn to_i32(self) -> I32x8 {
        I32x8(unsafe { _mm256_castps_si256(self.0) })
    }
    /// `self & !o`.
    #[inline(always)]
    pub fn and_not(self, o: M32x8) -> M32x8 {
        M32x8(unsafe { _mm256_andnot_ps(o.0, self.0) })
    }
    /// `a` where set, else `b`, lane by lane.
    #[inline(always)]
    pub fn select(self, a: F32x8, b: F32x8) -> F32x8 {
        F32x8(unsafe { _mm256_blendv_ps(b.0, a.0, self.0) })
    }
    /// [`select`](Self::select) of `i32` lanes.
    #[inline(always)]
    pub fn select_i32(self, a: I32x8, b: I32x8) -> I32x8 {
        unsafe {
            let r = _mm256_blendv_ps(_mm256_castsi256_ps(b.0), _mm256_castsi256_ps(a.0), self.0);
            I32x8(_mm256_castps_si256(r))
        }
    }
}

impl BitAnd for M32x8 {
    type Output = M32x8;
    #[inline(always)]
    fn bitand(self, o: M32x8) -> M32x8 {
        M32x8(unsafe { _mm256_and_ps(self.0, o.0) })
    }
}
impl BitOr for M32x8 {
    type Output = M32x8;
    #[inline(always)]
    fn bitor(self, o: M32x8) -> M32x8 {
        M32x8(unsafe { _mm256_or_ps(self.0, o.0) })
    }
}
impl Not for M32x8 {
    type Output = M32x8;
    #[inline(always)]
    fn not(self) -> M32x8 {
        M32x8(unsafe { _mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) })
    }
}
