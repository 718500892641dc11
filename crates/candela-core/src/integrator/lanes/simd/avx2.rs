//! The AVX2 backend of the lane types: `__m256` and `std::arch`, for the x86-64-v3 copy of
//! the render loop only.

use std::arch::x86_64::*;

use super::{LaneIsa, Lanes32, LANES};

/// AVX2 through `std::arch`. Only the x86-64-v3 copy of the render loop names it: its
/// operations compile to AVX instructions, which other CPUs do not run.
#[derive(Clone, Copy, Debug)]
pub struct Avx2;

/// SAFETY (every `unsafe` below): `Avx2` is used only in the x86-64-v3 copy of the
/// render loop, whose callers checked that the CPU has AVX2; the loads and stores go
/// through arrays of eight f32.
impl LaneIsa for Avx2 {
    type F = __m256;
    type M = __m256;
    #[inline(always)]
    fn splat(v: f32) -> __m256 {
        unsafe { _mm256_set1_ps(v) }
    }
    #[inline(always)]
    fn load(a: &Lanes32) -> __m256 {
        unsafe { _mm256_loadu_ps(a.as_ptr()) }
    }
    #[inline(always)]
    fn store(v: __m256) -> Lanes32 {
        let mut a = [0.0; LANES];
        unsafe { _mm256_storeu_ps(a.as_mut_ptr(), v) };
        a
    }
    #[inline(always)]
    fn add(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_add_ps(a, b) }
    }
    #[inline(always)]
    fn sub(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_sub_ps(a, b) }
    }
    #[inline(always)]
    fn mul(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_mul_ps(a, b) }
    }
    #[inline(always)]
    fn div(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_div_ps(a, b) }
    }
    #[inline(always)]
    fn neg(a: __m256) -> __m256 {
        unsafe { _mm256_xor_ps(a, _mm256_set1_ps(-0.0)) }
    }
    #[inline(always)]
    fn abs(a: __m256) -> __m256 {
        unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), a) }
    }
    #[inline(always)]
    fn max(a: __m256, b: __m256) -> __m256 {
        // `maxps` returns its second operand where either is NaN; `f32::max` returns the
        // operand that is not NaN.
        unsafe {
            let m = _mm256_max_ps(a, b);
            _mm256_blendv_ps(m, a, _mm256_cmp_ps::<_CMP_UNORD_Q>(b, b))
        }
    }
    #[inline(always)]
    fn sqrt(a: __m256) -> __m256 {
        unsafe { _mm256_sqrt_ps(a) }
    }
    #[inline(always)]
    fn copysign(a: __m256, sign: __m256) -> __m256 {
        unsafe {
            let s = _mm256_set1_ps(-0.0);
            _mm256_or_ps(_mm256_andnot_ps(s, a), _mm256_and_ps(s, sign))
        }
    }
    #[inline(always)]
    fn lt(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(a, b) }
    }
    #[inline(always)]
    fn gt(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(a, b) }
    }
    #[inline(always)]
    fn eq(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(a, b) }
    }
    #[inline(always)]
    fn is_finite(a: __m256) -> __m256 {
        Self::lt(Self::abs(a), Self::splat(f32::INFINITY))
    }
    #[inline(always)]
    fn mask_from_bools(b: [bool; LANES]) -> __m256 {
        let words = b.map(|b| if b { u32::MAX } else { 0 });
        unsafe { _mm256_loadu_ps(words.as_ptr().cast()) }
    }
    #[inline(always)]
    fn mask_bits(m: __m256) -> u8 {
        unsafe { _mm256_movemask_ps(m) as u8 }
    }
    #[inline(always)]
    fn and(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_and_ps(a, b) }
    }
    #[inline(always)]
    fn or(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_or_ps(a, b) }
    }
    #[inline(always)]
    fn xor(a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_xor_ps(a, b) }
    }
    #[inline(always)]
    fn not(a: __m256) -> __m256 {
        unsafe { _mm256_xor_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) }
    }
    #[inline(always)]
    fn select(m: __m256, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_blendv_ps(b, a, m) }
    }
}
