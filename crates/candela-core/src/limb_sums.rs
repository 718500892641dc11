//! Pending exact sums of a run of pixels (radiance r, g, b and filter weight), for the
//! splat's many small contributions: each contribution is the integer [`ExactSum::of`]
//! would add, v = round(t) for t = x·2⁵⁶, split as `hi·2⁴⁸ + lo` with hi = round(t/2⁴⁸)
//! and |lo| ≤ 2⁴⁷, and the limbs are summed in plain wrapping `i64`s (no carries between
//! them), four channels in two AVX2 registers. [`LimbSums::fold_into`] then adds
//! `hi·2⁴⁸ + lo` to each pixel's [`ExactSum`]s. Integer sums are exact and do not depend
//! on their order, so the pixel gets the same bits as if every contribution had gone
//! through [`Pixel::add_weighted`].
//!
//! The split costs three operations, no rounding instruction and no conversion:
//! t + C with C = 1.5·2¹⁰⁰ rounds t to h, a multiple of 2⁴⁸, and leaves h/2⁴⁸ in the low
//! bits of the float (offset by C's bits); (M + C) − (t + C) = M − h is exact (2⁴⁸ times
//! an integer below 2⁴⁹), and t + (M − h), with M = 1.5·2⁵², rounds t − h (|t − h| ≤ 2⁴⁷)
//! to an integer and leaves that in the low bits likewise (t being a product of two
//! floats, both additions of t are one fused multiply-add each in AVX2). The limbs sum
//! those floats' bits as they are; each pixel counts its contributions, and the fold
//! takes off the count times C's and M's bits.
//!
//! Capacity: |hi| < 2⁴⁸ and |lo| ≤ 2⁴⁷, so [`LimbSums::CAPACITY`] = 2¹⁵ contributions
//! per pixel fit an `i64` (2⁶³) and the count a `u16` before a fold.

use glam::Vec3;

use crate::exact_sum::ExactSum;
use crate::film::Pixel;

/// Bits of the low limb: hi counts units of 2⁴⁸.
const LO_BITS: u32 = 48;
/// 1.5·2¹⁰⁰: t + C rounds t to a multiple of 2⁴⁸ (ties to even), whose quotient are the
/// float's bits less C's, for |t| < 2⁹⁹.
const HI_SHIFT: f64 = f64::from_bits(0x4638_0000_0000_0000);
/// 1.5·2⁵²: x + M rounds x to an integer (ties to even), which are the float's bits less
/// M's, for |x| < 2⁵¹.
const LO_SHIFT: f64 = f64::from_bits(0x4338_0000_0000_0000);
/// M + C, exact (its bits span 2⁵¹ … 2¹⁰⁰).
const LO_LESS_HI: f64 = LO_SHIFT + HI_SHIFT;
/// 2⁵⁶, the fixed point's units per 1.0 (see [`crate::exact_sum`]).
const SCALE: f64 = (1u64 << 56) as f64;

/// One pixel's limbs, r, g, b and weight in lane order, each the sum of its
/// contributions' shifted floats' bits (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
struct Limbs {
    lo: [i64; 4],
    hi: [i64; 4],
}

/// The pending sums of `len` pixels, indexed as the caller's pixels are.
#[derive(Clone, Debug, Default)]
pub struct LimbSums {
    limbs: Vec<Limbs>,
    /// Contributions per pixel since the last fold.
    counts: Vec<u16>,
}

impl LimbSums {
    /// Contributions a pixel takes before its sums must be folded.
    pub const CAPACITY: u64 = 1 << 15;

    /// Empty sums for `len` pixels.
    pub fn new(len: usize) -> LimbSums {
        LimbSums {
            limbs: vec![Limbs::default(); len],
            counts: vec![0; len],
        }
    }

    pub fn len(&self) -> usize {
        self.limbs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.limbs.is_empty()
    }

    /// Adds `weight` × `radiance` and `weight` to pixel `i`'s sums, as
    /// [`Pixel::add_weighted`] would. The caller guarantees every term is accepted there
    /// (finite, below [`crate::exact_sum::MAX_CONTRIBUTION`]): a splatted share of an
    /// accepted sample, whose weight is at most 1.
    #[inline]
    pub fn add_weighted(&mut self, i: usize, radiance: Vec3, weight: f32) {
        let w = weight as f64;
        let limbs = &mut self.limbs[i];
        let rgb1 = [radiance.x, radiance.y, radiance.z, 1.0];
        for (c, x) in rgb1.into_iter().enumerate() {
            debug_assert!(
                ExactSum::of(x as f64 * w).is_some(),
                "a share beyond the film's range"
            );
            // The AVX2 lanes' operations: t is exact, so each addition of it rounds once,
            // as their fused multiply-adds do.
            let t = x as f64 * SCALE * w;
            let hi = t + HI_SHIFT;
            let lo = t + (LO_LESS_HI - hi);
            limbs.lo[c] = limbs.lo[c].wrapping_add(lo.to_bits() as i64);
            limbs.hi[c] = limbs.hi[c].wrapping_add(hi.to_bits() as i64);
        }
        self.counts[i] += 1;
    }

    /// Adds each pixel's pending sums to `pixels[i]`'s (the same length) and clears them.
    pub fn fold_into(&mut self, pixels: &mut [Pixel]) {
        assert_eq!(pixels.len(), self.len());
        let bias = |shift: f64, n: u16| (shift.to_bits() as i64).wrapping_mul(n as i64);
        for ((limbs, n), pixel) in self.limbs.iter_mut().zip(&mut self.counts).zip(pixels) {
            if *n == 0 {
                continue;
            }
            let (hi_bias, lo_bias) = (bias(HI_SHIFT, *n), bias(LO_SHIFT, *n));
            let sum = |c: usize| {
                let hi = limbs.hi[c].wrapping_sub(hi_bias) as i128;
                let lo = limbs.lo[c].wrapping_sub(lo_bias) as i128;
                ExactSum::from_bits((hi << LO_BITS).wrapping_add(lo))
            };
            for (c, s) in pixel.radiance_sum.iter_mut().enumerate() {
                *s += sum(c);
            }
            pixel.weight_sum += sum(3);
            *limbs = Limbs::default();
            *n = 0;
        }
    }

    /// Adds a row of one sample's shares in AVX2: `rgb1` × `weights[k]` into pixel
    /// `start + k` for k < `len` ≤ 4, as [`Self::add_weighted`] adds them, for `rgb1` =
    /// (r, g, b, 1)·2⁵⁶ of the sample (see [`rgb1`]) and the weights in `f64`. Some ten
    /// instructions a share.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma")]
    #[inline]
    pub fn add_row_avx2(
        &mut self,
        start: usize,
        len: usize,
        rgb1: std::arch::x86_64::__m256d,
        weights: std::arch::x86_64::__m256d,
    ) {
        use std::arch::x86_64::*;
        if len == 4 {
            assert!(start + 4 <= self.len(), "a row beyond the sums");
            // SAFETY: pixels start … start + 3 exist (checked).
            unsafe { self.add_row4(start, rgb1, weights) };
            return;
        }
        let mut w = [0.0f64; 4];
        // SAFETY: `w` holds four f64.
        unsafe { _mm256_storeu_pd(w.as_mut_ptr(), weights) };
        let limbs = &mut self.limbs[start..start + len];
        let counts = &mut self.counts[start..start + len];
        for ((limbs, n), w) in limbs.iter_mut().zip(counts).zip(&w) {
            // SAFETY: this function's features.
            unsafe { add_share(limbs, rgb1, _mm256_set1_pd(*w)) };
            *n += 1;
        }
    }
}

impl LimbSums {
    /// A 4 × 4 block of one sample's shares in AVX2, rows `stride` pixels apart from
    /// pixel `start`: `rgb1` × (`wx[k]` · `wy[j]` rounded to `f32`) into pixel
    /// `start + j·stride + k`, as [`Self::add_weighted`] adds them.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    /// Inlined, so that its intrinsics inline into a caller compiled for them (the v3
    /// render loop).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub unsafe fn add_4x4_avx2(
        &mut self,
        (start, stride): (usize, usize),
        rgb1: std::arch::x86_64::__m256d,
        wx: std::arch::x86_64::__m128,
        wy: std::arch::x86_64::__m128,
    ) {
        use std::arch::x86_64::*;
        assert!(
            start + 3 * stride + 4 <= self.len(),
            "a block beyond the sums"
        );
        let row = |wy: __m128| _mm256_cvtps_pd(_mm_mul_ps(wx, wy));
        // SAFETY: the four rows of four pixels exist (checked).
        unsafe {
            self.add_row4(start, rgb1, row(_mm_permute_ps::<0x00>(wy)));
            self.add_row4(start + stride, rgb1, row(_mm_permute_ps::<0x55>(wy)));
            self.add_row4(start + 2 * stride, rgb1, row(_mm_permute_ps::<0xaa>(wy)));
            self.add_row4(start + 3 * stride, rgb1, row(_mm_permute_ps::<0xff>(wy)));
        }
    }

    /// [`Self::add_row_avx2`] for a row of four pixels, unchecked.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA, and pixels `start` … `start + 3` must exist.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn add_row4(
        &mut self,
        start: usize,
        rgb1: std::arch::x86_64::__m256d,
        weights: std::arch::x86_64::__m256d,
    ) {
        use std::arch::x86_64::*;
        // SAFETY: the caller guarantees pixels start … start + 3.
        unsafe {
            let limbs = self.limbs.as_mut_ptr().add(start);
            add_share(&mut *limbs, rgb1, _mm256_permute4x64_pd::<0x00>(weights));
            add_share(
                &mut *limbs.add(1),
                rgb1,
                _mm256_permute4x64_pd::<0x55>(weights),
            );
            add_share(
                &mut *limbs.add(2),
                rgb1,
                _mm256_permute4x64_pd::<0xaa>(weights),
            );
            add_share(
                &mut *limbs.add(3),
                rgb1,
                _mm256_permute4x64_pd::<0xff>(weights),
            );
            // One add for the four counts (each below 2¹⁶, so no carry between them),
            // eight bytes read and written unaligned.
            let counts = self.counts.as_mut_ptr().add(start) as *mut u64;
            counts.write_unaligned(counts.read_unaligned() + 0x0001_0001_0001_0001);
        }
    }
}

/// One share, `rgb1` × `weight` (the weight in every lane), into `limbs`: the scalar
/// path's operations lane by lane.
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn add_share(
    limbs: &mut Limbs,
    rgb1: std::arch::x86_64::__m256d,
    weight: std::arch::x86_64::__m256d,
) {
    use std::arch::x86_64::*;
    // The terms t = rgb1 × weight in units of 2⁻⁵⁶ are exact (a product of two f32
    // scaled by a power of two), so each fused multiply-add rounds t + c once, as the
    // scalar path's additions do.
    let hi = _mm256_fmadd_pd(rgb1, weight, _mm256_set1_pd(HI_SHIFT));
    let lo = _mm256_fmadd_pd(rgb1, weight, _mm256_sub_pd(_mm256_set1_pd(LO_LESS_HI), hi));
    // SAFETY: `Limbs` is 32-byte aligned, `lo` and `hi` its two 32-byte halves.
    unsafe {
        let p_lo = limbs.lo.as_mut_ptr() as *mut __m256i;
        let p_hi = limbs.hi.as_mut_ptr() as *mut __m256i;
        let lo = _mm256_add_epi64(_mm256_load_si256(p_lo), _mm256_castpd_si256(lo));
        let hi = _mm256_add_epi64(_mm256_load_si256(p_hi), _mm256_castpd_si256(hi));
        _mm256_store_si256(p_lo, lo);
        _mm256_store_si256(p_hi, hi);
    }
}

/// A sample's (r, g, b, 1)·2⁵⁶ in `f64` (exact: a power-of-two scaling of `f32`s below
/// 2⁴⁰), for [`LimbSums::add_row_avx2`].
///
/// # Safety
/// The CPU must have AVX2. Inlined, so that its intrinsics inline into a caller compiled
/// for them.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub unsafe fn rgb1(radiance: Vec3) -> std::arch::x86_64::__m256d {
    use std::arch::x86_64::*;
    _mm256_mul_pd(
        _mm256_cvtps_pd(_mm_set_ps(1.0, radiance.z, radiance.y, radiance.x)),
        _mm256_set1_pd(SCALE),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random radiances (every magnitude up to the film's limit, both signs, zeros) and
    /// weights: the folded limbs give the bits of `Pixel::add_weighted`, by the scalar
    /// path and by the AVX2 rows where the CPU has it (full and partial rows; limbs
    /// equal too), folded more than once.
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
        const N: usize = 6;
        let mut exact = [Pixel::default(); N];
        let mut folded_scalar = [Pixel::default(); N];
        let mut folded_lanes = [Pixel::default(); N];
        for _ in 0..100 {
            let mut scalar = LimbSums::new(N);
            let mut lanes = LimbSums::new(N);
            for _ in 0..300 {
                let l = Vec3::new(value(next()), value(next()), value(next()));
                let start = (next() % 3) as usize;
                let len = [4, 4, 3, 2, 1][(next() % 5) as usize];
                let mut w = [0.0f32; 4];
                for w in &mut w {
                    *w = (value(next()).abs() / 2f32.powi(127))
                        .min(1.0)
                        .max(next() as u32 as f32 / 4.3e9);
                }
                for (k, &w) in w.iter().enumerate().take(len) {
                    assert!(exact[start + k].add_weighted(l, w));
                    scalar.add_weighted(start + k, l, w);
                }
                #[cfg(target_arch = "x86_64")]
                if avx2 {
                    use std::arch::x86_64::*;
                    // SAFETY: the CPU has AVX2 and FMA (checked above).
                    unsafe {
                        let w = _mm256_cvtps_pd(_mm_loadu_ps(w.as_ptr()));
                        lanes.add_row_avx2(start, len, rgb1(l), w);
                    }
                }
            }
            if avx2 {
                for (a, b) in lanes.limbs.iter().zip(&scalar.limbs) {
                    assert_eq!((a.lo, a.hi), (b.lo, b.hi));
                }
                assert_eq!(lanes.counts, scalar.counts);
                lanes.fold_into(&mut folded_lanes);
            }
            scalar.fold_into(&mut folded_scalar);
            for (i, e) in exact.iter().enumerate() {
                let sums = |p: &Pixel| (p.radiance_sum, p.weight_sum);
                assert_eq!(sums(&folded_scalar[i]), sums(e));
                if avx2 {
                    assert_eq!(sums(&folded_lanes[i]), sums(e));
                }
            }
        }
    }
}
