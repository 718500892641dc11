//! The few vector operations the block's watertight and sphere tests need, over a register of 4
//! (SSE) or 8 (AVX2) floats, so that one generic kernel serves both widths and each
//! lane performs the very operations of the scalar test: plain IEEE add, subtract,
//! multiply and divide (never fused) and ordered comparisons.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// A register of `LANES` floats. Comparisons give all-ones lanes where true.
///
/// # Safety
/// Every method requires the CPU to support the type's instructions; the AVX2 one's are
/// compiled for AVX2 and inline only into functions that are too.
#[cfg(target_arch = "x86_64")]
pub trait Wide: Copy {
    const LANES: usize;
    unsafe fn load(p: *const f32) -> Self;
    unsafe fn store(self, p: *mut f32);
    unsafe fn splat(x: f32) -> Self;
    unsafe fn add(self, o: Self) -> Self;
    unsafe fn sub(self, o: Self) -> Self;
    unsafe fn mul(self, o: Self) -> Self;
    unsafe fn div(self, o: Self) -> Self;
    /// The correctly rounded square root, as `f32::sqrt`.
    unsafe fn sqrt(self) -> Self;
    /// `minps`/`maxps`: `o` where either is NaN.
    unsafe fn min(self, o: Self) -> Self;
    unsafe fn max(self, o: Self) -> Self;
    unsafe fn and(self, o: Self) -> Self;
    unsafe fn or(self, o: Self) -> Self;
    unsafe fn xor(self, o: Self) -> Self;
    /// `!self & o`.
    unsafe fn andnot(self, o: Self) -> Self;
    unsafe fn lt(self, o: Self) -> Self;
    unsafe fn gt(self, o: Self) -> Self;
    unsafe fn ge(self, o: Self) -> Self;
    /// Bit `i` set where lane `i` is true.
    unsafe fn bits(self) -> u32;
    /// All-ones lanes where bit `i` of `bits` is set: the inverse of [`Wide::bits`].
    unsafe fn from_bits(bits: u32) -> Self;
    /// `a` in the lanes where `self` is all ones, `b` where it is zero.
    #[inline(always)]
    unsafe fn select(self, a: Self, b: Self) -> Self {
        self.and(a).or(self.andnot(b))
    }
}

#[cfg(target_arch = "x86_64")]
impl Wide for __m128 {
    const LANES: usize = 4;
    #[inline(always)]
    unsafe fn load(p: *const f32) -> Self {
        _mm_loadu_ps(p)
    }
    #[inline(always)]
    unsafe fn store(self, p: *mut f32) {
        _mm_storeu_ps(p, self)
    }
    #[inline(always)]
    unsafe fn splat(x: f32) -> Self {
        _mm_set1_ps(x)
    }
    #[inline(always)]
    unsafe fn add(self, o: Self) -> Self {
        _mm_add_ps(self, o)
    }
    #[inline(always)]
    unsafe fn sub(self, o: Self) -> Self {
        _mm_sub_ps(self, o)
    }
    #[inline(always)]
    unsafe fn mul(self, o: Self) -> Self {
        _mm_mul_ps(self, o)
    }
    #[inline(always)]
    unsafe fn div(self, o: Self) -> Self {
        _mm_div_ps(self, o)
    }
    #[inline(always)]
    unsafe fn sqrt(self) -> Self {
        _mm_sqrt_ps(self)
    }
    #[inline(always)]
    unsafe fn min(self, o: Self) -> Self {
        _mm_min_ps(self, o)
    }
    #[inline(always)]
    unsafe fn max(self, o: Self) -> Self {
        _mm_max_ps(self, o)
    }
    #[inline(always)]
    unsafe fn and(self, o: Self) -> Self {
        _mm_and_ps(self, o)
    }
    #[inline(always)]
    unsafe fn or(self, o: Self) -> Self {
        _mm_or_ps(self, o)
    }
    #[inline(always)]
    unsafe fn xor(self, o: Self) -> Self {
        _mm_xor_ps(self, o)
    }
    #[inline(always)]
    unsafe fn andnot(self, o: Self) -> Self {
        _mm_andnot_ps(self, o)
    }
    #[inline(always)]
    unsafe fn lt(self, o: Self) -> Self {
        _mm_cmplt_ps(self, o)
    }
    #[inline(always)]
    unsafe fn gt(self, o: Self) -> Self {
        _mm_cmpgt_ps(self, o)
    }
    #[inline(always)]
    unsafe fn ge(self, o: Self) -> Self {
        _mm_cmpge_ps(self, o)
    }
    #[inline(always)]
    unsafe fn bits(self) -> u32 {
        _mm_movemask_ps(self) as u32
    }
    #[inline(always)]
    unsafe fn from_bits(bits: u32) -> Self {
        let lane = _mm_setr_epi32(1, 2, 4, 8);
        let set = _mm_and_si128(_mm_set1_epi32(bits as i32), lane);
        _mm_castsi128_ps(_mm_cmpeq_epi32(set, lane))
    }
}

/// Declares AVX2 methods: `#[inline]` with the feature enabled, as the box kernel's.
#[cfg(target_arch = "x86_64")]
macro_rules! avx2 {
    ($(fn $name:ident($($arg:ident: $ty:ty),*) -> $ret:ty $body:block)*) => {
        $(
            #[inline]
            #[target_feature(enable = "avx2")]
            unsafe fn $name($($arg: $ty),*) -> $ret $body
        )*
    };
}

#[cfg(target_arch = "x86_64")]
impl Wide for __m256 {
    const LANES: usize = 8;
    avx2! {
        fn load(p: *const f32) -> Self { _mm256_loadu_ps(p) }
        fn store(self: Self, p: *mut f32) -> () { _mm256_storeu_ps(p, self) }
        fn splat(x: f32) -> Self { _mm256_set1_ps(x) }
        fn add(self: Self, o: Self) -> Self { _mm256_add_ps(self, o) }
        fn sub(self: Self, o: Self) -> Self { _mm256_sub_ps(self, o) }
        fn mul(self: Self, o: Self) -> Self { _mm256_mul_ps(self, o) }
        fn div(self: Self, o: Self) -> Self { _mm256_div_ps(self, o) }
        fn sqrt(self: Self) -> Self { _mm256_sqrt_ps(self) }
        fn min(self: Self, o: Self) -> Self { _mm256_min_ps(self, o) }
        fn max(self: Self, o: Self) -> Self { _mm256_max_ps(self, o) }
        fn and(self: Self, o: Self) -> Self { _mm256_and_ps(self, o) }
        fn or(self: Self, o: Self) -> Self { _mm256_or_ps(self, o) }
        fn xor(self: Self, o: Self) -> Self { _mm256_xor_ps(self, o) }
        fn andnot(self: Self, o: Self) -> Self { _mm256_andnot_ps(self, o) }
        fn lt(self: Self, o: Self) -> Self { _mm256_cmp_ps::<_CMP_LT_OQ>(self, o) }
        fn gt(self: Self, o: Self) -> Self { _mm256_cmp_ps::<_CMP_GT_OQ>(self, o) }
        fn ge(self: Self, o: Self) -> Self { _mm256_cmp_ps::<_CMP_GE_OQ>(self, o) }
        fn bits(self: Self) -> u32 { _mm256_movemask_ps(self) as u32 }
        fn from_bits(bits: u32) -> Self {
            let lane = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
            let set = _mm256_and_si256(_mm256_set1_epi32(bits as i32), lane);
            _mm256_castsi256_ps(_mm256_cmpeq_epi32(set, lane))
        }
    }
}
