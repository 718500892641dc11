//! A pixel's four exact sums (radiance r, g, b and filter weight) pending in 64-bit
//! limbs, for the splat's many small contributions: each contribution is the integer
//! [`ExactSum::of`] would add, held as `hi·2⁴⁸ + lo` with both limbs below 2⁴⁸ in
//! magnitude, and the limbs are summed in plain `i64`s (no carries between them), four
//! channels in two AVX2 registers. [`LimbSums::fold_into`] then adds `hi·2⁴⁸ + lo` to the
//! pixel's [`ExactSum`]s. Integer sums are exact, so the pixel gets the same bits as if
//! every contribution had gone through [`Pixel::add_weighted`].
//!
//! Capacity: each limb is below 2⁴⁸ in magnitude, so [`LimbSums::CAPACITY`] = 2¹⁵
//! contributions fit an `i64` (2⁶³) before a fold.

use glam::Vec3;

use crate::exact_sum::ExactSum;
use crate::film::Pixel;

/// Bits of the low limb.
const LO_BITS: u32 = 48;

/// Pending sums of one pixel's r, g, b and weight (lane order), in limbs.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub struct LimbSums {
    lo: [i64; 4],
    hi: [i64; 4],
}

impl LimbSums {
    /// Contributions a [`LimbSums`] takes before it must be folded.
    pub const CAPACITY: u64 = 1 << 15;

    /// Adds `weight` × `radiance` and `weight`, as [`Pixel::add_weighted`] would. The
    /// caller guarantees every term is accepted there (finite, below
    /// [`crate::exact_sum::MAX_CONTRIBUTION`]): a splatted share of an accepted sample,
    /// whose weight is at most 1.
    #[inline]
    pub fn add_weighted(&mut self, radiance: Vec3, weight: f32) {
        let w = weight as f64;
        let terms = [
            radiance.x as f64 * w,
            radiance.y as f64 * w,
            radiance.z as f64 * w,
            w,
        ];
        for (i, t) in terms.into_iter().enumerate() {
            debug_assert!(ExactSum::of(t).is_some(), "a share beyond the film's range");
            let v = ExactSum::of(t).unwrap_or(ExactSum::ZERO).to_bits();
            self.lo[i] += (v & ((1 << LO_BITS) - 1)) as i64;
            self.hi[i] += (v >> LO_BITS) as i64;
        }
    }

    /// Adds the pending sums to `pixel`'s and clears them.
    pub fn fold_into(&mut self, pixel: &mut Pixel) {
        let sum = |i: usize| {
            ExactSum::from_bits(((self.hi[i] as i128) << LO_BITS).wrapping_add(self.lo[i] as i128))
        };
        for (i, s) in pixel.radiance_sum.iter_mut().enumerate() {
            *s += sum(i);
        }
        pixel.weight_sum += sum(3);
        *self = LimbSums::default();
    }
}

/// [`LimbSums::add_weighted`] in AVX2, four channels at once, for `rgb1` = (r, g, b, 1)
/// of the sample in `f64` (see [`rgb1`]). The limbs differ from the scalar path's
/// (sign and magnitude instead of floor and remainder), their value `hi·2⁴⁸ + lo` does
/// not.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
#[inline]
pub fn add_weighted_avx2(sums: &mut LimbSums, rgb1: std::arch::x86_64::__m256d, weight: f32) {
    use std::arch::x86_64::*;
    // The terms, exact in f64 (products of two f32), scaled exactly by 2⁵⁶.
    let t = _mm256_mul_pd(rgb1, _mm256_set1_pd(weight as f64 * (1u64 << 56) as f64));
    let t_bits = _mm256_castpd_si256(t);
    let negative = _mm256_cmpgt_epi64(_mm256_setzero_si256(), t_bits);
    let a = _mm256_castpd_si256(_mm256_andnot_pd(_mm256_set1_pd(-0.0), t));
    let two_52 = _mm256_set1_pd((1u64 << 52) as f64);
    let small = _mm256_castpd_si256(_mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_castsi256_pd(a), two_52));
    // Below 2⁵²: rounded to an integer, ties to even, by adding 2⁵² (see
    // `exact_sum::to_fixed`), with no shift. Above: the significand, shifted by the
    // exponent less 52.
    let rounded = _mm256_sub_epi64(
        _mm256_castpd_si256(_mm256_add_pd(_mm256_castsi256_pd(a), two_52)),
        _mm256_castpd_si256(two_52),
    );
    let significand = _mm256_or_si256(
        _mm256_and_si256(a, _mm256_set1_epi64x((1 << 52) - 1)),
        _mm256_set1_epi64x(1 << 52),
    );
    let exponent = _mm256_sub_epi64(_mm256_srli_epi64::<52>(a), _mm256_set1_epi64x(1075));
    let m = _mm256_blendv_epi8(significand, rounded, small);
    let shift = _mm256_andnot_si256(small, exponent);
    // The magnitude m·2^shift (< 2⁹⁶) as lo + hi·2⁴⁸.
    let lo = _mm256_and_si256(
        _mm256_sllv_epi64(m, shift),
        _mm256_set1_epi64x((1 << LO_BITS) - 1),
    );
    let hi = _mm256_srlv_epi64(
        m,
        _mm256_sub_epi64(_mm256_set1_epi64x(LO_BITS as i64), shift),
    );
    // Negated where the term is negative: (x ^ −1) − (−1) = −x.
    let lo = _mm256_sub_epi64(_mm256_xor_si256(lo, negative), negative);
    let hi = _mm256_sub_epi64(_mm256_xor_si256(hi, negative), negative);
    // SAFETY: `LimbSums` is 32-byte aligned, `lo` and `hi` its two 32-byte halves.
    unsafe {
        let p_lo = sums.lo.as_mut_ptr() as *mut __m256i;
        let p_hi = sums.hi.as_mut_ptr() as *mut __m256i;
        _mm256_store_si256(p_lo, _mm256_add_epi64(_mm256_load_si256(p_lo), lo));
        _mm256_store_si256(p_hi, _mm256_add_epi64(_mm256_load_si256(p_hi), hi));
    }
}

/// A sample's (r, g, b, 1) in `f64`, for [`add_weighted_avx2`].
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
#[inline]
pub fn rgb1(radiance: Vec3) -> std::arch::x86_64::__m256d {
    use std::arch::x86_64::*;
    _mm256_cvtps_pd(_mm_set_ps(1.0, radiance.z, radiance.y, radiance.x))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random radiances (every magnitude up to the film's limit, both signs, zeros) and
    /// weights: the folded limbs give the bits of `Pixel::add_weighted`, by the scalar
    /// path and by the AVX2 one where the CPU has it.
    #[test]
    fn folded_limbs_equal_the_exact_sums() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state = crate::sampler::mix64(state);
            state
        };
        let value = |bits: u64| {
            // Biased f32 exponents 0 … 166 (below 2⁴⁰), and a few exact zeros.
            let exp = (bits >> 40) % 167;
            if bits.is_multiple_of(17) {
                return if bits.is_multiple_of(2) { 0.0 } else { -0.0 };
            }
            f32::from_bits(((bits as u32) & 0x807f_ffff) | ((exp as u32) << 23))
        };
        let avx2 = cfg!(target_arch = "x86_64") && std::arch::is_x86_feature_detected!("avx2");
        for _ in 0..200 {
            let mut exact = Pixel::default();
            let mut scalar = LimbSums::default();
            let mut lanes = LimbSums::default();
            for _ in 0..500 {
                let l = Vec3::new(value(next()), value(next()), value(next()));
                let w = (value(next()).abs() / 2f32.powi(127))
                    .min(1.0)
                    .max(next() as u32 as f32 / 4.3e9);
                assert!(exact.add_weighted(l, w));
                scalar.add_weighted(l, w);
                #[cfg(target_arch = "x86_64")]
                if avx2 {
                    // SAFETY: the CPU has AVX2 (checked above).
                    unsafe { add_weighted_avx2(&mut lanes, rgb1(l), w) };
                }
            }
            let mut a = Pixel::default();
            scalar.fold_into(&mut a);
            assert_eq!(
                (a.radiance_sum, a.weight_sum),
                (exact.radiance_sum, exact.weight_sum)
            );
            if avx2 {
                let mut b = Pixel::default();
                lanes.fold_into(&mut b);
                assert_eq!(
                    (b.radiance_sum, b.weight_sum),
                    (exact.radiance_sum, exact.weight_sum)
                );
            }
        }
    }
}
