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
/// of the sample in `f64` scaled by 2⁵⁶ (see [`rgb1`]) and the weight in every lane of
/// `weight`. The limbs are the scalar path's (floor and remainder), some 15 instructions.
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma")]
#[inline]
pub fn add_weighted_avx2(
    sums: &mut LimbSums,
    rgb1: std::arch::x86_64::__m256d,
    weight: std::arch::x86_64::__m256d,
) {
    use std::arch::x86_64::*;
    // The terms in units of 2⁻⁵⁶, exact (a product of two f32 scaled by a power of two).
    let t = _mm256_mul_pd(rgb1, weight);
    // Rounded to integers, ties to even, as `ExactSum::of` rounds; |v| < 2⁹⁶ (an integer
    // valued f64: exact).
    let v = _mm256_round_pd::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(t);
    // v = hi·2⁴⁸ + lo with hi = ⌊v/2⁴⁸⌋ (|hi| ≤ 2⁴⁸) and lo ∈ [0, 2⁴⁸): a power-of-two
    // scaling, a floor, and a difference that is representable, so all exact.
    let hi = _mm256_round_pd::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(_mm256_mul_pd(
        v,
        _mm256_set1_pd(1.0 / (1u64 << LO_BITS) as f64),
    ));
    let lo = _mm256_fnmadd_pd(hi, _mm256_set1_pd((1u64 << LO_BITS) as f64), v);
    // Integers below 2⁵¹ in magnitude to i64: 1.5·2⁵² + x lies in [2⁵², 2⁵³), where
    // the float's bits grow by one per unit, so its bits less those of 1.5·2⁵² are x.
    let magic = _mm256_set1_pd(1.5 * (1u64 << 52) as f64);
    let to_i64 = |x: __m256d| {
        _mm256_sub_epi64(
            _mm256_castpd_si256(_mm256_add_pd(x, magic)),
            _mm256_castpd_si256(magic),
        )
    };
    let (lo, hi) = (to_i64(lo), to_i64(hi));
    // SAFETY: `LimbSums` is 32-byte aligned, `lo` and `hi` its two 32-byte halves.
    unsafe {
        let p_lo = sums.lo.as_mut_ptr() as *mut __m256i;
        let p_hi = sums.hi.as_mut_ptr() as *mut __m256i;
        _mm256_store_si256(p_lo, _mm256_add_epi64(_mm256_load_si256(p_lo), lo));
        _mm256_store_si256(p_hi, _mm256_add_epi64(_mm256_load_si256(p_hi), hi));
    }
}

/// A sample's (r, g, b, 1)·2⁵⁶ in `f64` (exact: a power-of-two scaling of `f32`s below
/// 2⁴⁰), for [`add_weighted_avx2`].
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
#[inline]
pub fn rgb1(radiance: Vec3) -> std::arch::x86_64::__m256d {
    use std::arch::x86_64::*;
    _mm256_mul_pd(
        _mm256_cvtps_pd(_mm_set_ps(1.0, radiance.z, radiance.y, radiance.x)),
        _mm256_set1_pd((1u64 << 56) as f64),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random radiances (every magnitude up to the film's limit, both signs, zeros) and
    /// weights: the folded limbs give the bits of `Pixel::add_weighted`, by the scalar
    /// path and by the AVX2 one where the CPU has it (limbs equal too).
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
        let avx2 = cfg!(target_arch = "x86_64")
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
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
                    // SAFETY: the CPU has AVX2 and FMA (checked above).
                    unsafe {
                        let w = std::arch::x86_64::_mm256_set1_pd(w as f64);
                        add_weighted_avx2(&mut lanes, rgb1(l), w)
                    };
                }
            }
            if avx2 {
                assert_eq!((lanes.lo, lanes.hi), (scalar.lo, scalar.hi));
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
