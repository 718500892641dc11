//! `expf` for eight `f32` lanes in AVX2 + FMA that returns **the bits of glibc's `expf`**
//! on the CPUs that run it, so the splat's Gaussian weights ([`crate::splat`]) keep the
//! film bit-identical to the scalar path's libm calls while costing one call's
//! instructions for eight.
//!
//! glibc (2.27 onwards) computes `expf` as ARM's optimized-routines do
//! (`math/expf.c`, `math/exp2f_data.c`; MIT / Apache-2.0): in `f64`,
//! x·32/ln 2 = k + r with integer k and |r| ≤ ½, then
//! 2^(k/32) · (1 + C₂r + C₁r² + C₀r³), with 2^(i/32) from a 32-entry table whose
//! exponent field takes k/32's integer part by an integer add, and one rounding to `f32`.
//! On x86-64 glibc dispatches to a copy compiled with FMA (`__expf_fma`) where the CPU
//! has FMA and AVX2, as every CPU that runs the v3 render loop does; that copy contracts
//! the reduction and the polynomial into the FMAs below, in this order (read from its
//! machine code). The lanes repeat those operations one for one, so each lane's result
//! is the same `f64` before the final rounding, hence the same `f32`. `tests` compares
//! them over every finite `f32` below 88 in magnitude (the range without glibc's
//! special cases; callers keep their arguments there, see [`in_range`]).

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// 32/ln 2 (`InvLn2N`).
const INV_LN2_N: f64 = f64::from_bits(0x40471547652b82fe);
/// 1.5·2⁵², which rounds to an integer when added (`SHIFT`).
const SHIFT: f64 = f64::from_bits(0x4338000000000000);
/// The cubic's coefficients for 2^(r/32), r³ first (`poly_scaled`).
const C0: f64 = f64::from_bits(0x3ebc6af84b912394);
const C1: f64 = f64::from_bits(0x3f2ebfce50fac4f3);
const C2: f64 = f64::from_bits(0x3f962e42ff0c52d6);

/// 2^(i/32) for i = 0 … 31 with i·2⁴⁷ taken off its bits, so that adding k·2⁴⁷ (k's
/// integer part lands in the exponent field) gives 2^(k/32) (`__exp2f_data.tab`).
const TABLE: [u64; 32] = [
    0x3ff0000000000000,
    0x3fefd9b0d3158574,
    0x3fefb5586cf9890f,
    0x3fef9301d0125b51,
    0x3fef72b83c7d517b,
    0x3fef54873168b9aa,
    0x3fef387a6e756238,
    0x3fef1e9df51fdee1,
    0x3fef06fe0a31b715,
    0x3feef1a7373aa9cb,
    0x3feedea64c123422,
    0x3feece086061892d,
    0x3feebfdad5362a27,
    0x3feeb42b569d4f82,
    0x3feeab07dd485429,
    0x3feea47eb03a5585,
    0x3feea09e667f3bcd,
    0x3fee9f75e8ec5f74,
    0x3feea11473eb0187,
    0x3feea589994cce13,
    0x3feeace5422aa0db,
    0x3feeb737b0cdc5e5,
    0x3feec49182a3f090,
    0x3feed503b23e255d,
    0x3feee89f995ad3ad,
    0x3feeff76f2fb5e47,
    0x3fef199bdd85529c,
    0x3fef3720dcef9069,
    0x3fef5818dcfba487,
    0x3fef7c97337b9b5f,
    0x3fefa4afa2a490da,
    0x3fefd0765b6e4540,
];

/// Whether `x` lies where glibc's `expf` takes its main path: the top 12 bits of its
/// magnitude below those of 88.0 (`top12`), i.e. |x| < 88. The lanes compute only that
/// path.
pub fn in_range(x: f32) -> bool {
    (x.to_bits() >> 20) & 0x7ff < 0x42b
}

/// Four lanes of `expf` (see the module docs) for arguments [`in_range`].
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma")]
#[inline]
fn expf4(x: __m128) -> __m128 {
    let xd = _mm256_cvtps_pd(x);
    let inv_ln2_n = _mm256_set1_pd(INV_LN2_N);
    let shift = _mm256_set1_pd(SHIFT);
    // kd = round(z) (ties to even) through the shift; its low bits are the integer ki.
    let kd_shifted = _mm256_fmadd_pd(inv_ln2_n, xd, shift);
    let ki = _mm256_castpd_si256(kd_shifted);
    let kd = _mm256_sub_pd(kd_shifted, shift);
    // r = z − kd with z unrounded, as the FMA copy contracts it.
    let r = _mm256_fmsub_pd(inv_ln2_n, xd, kd);
    // s = 2^(ki/32): the table entry plus ki·2⁴⁷.
    let index = _mm256_and_si256(ki, _mm256_set1_epi64x(31));
    // SAFETY: the indices are below 32, the table's length.
    let t = unsafe { _mm256_i64gather_epi64::<8>(TABLE.as_ptr() as *const i64, index) };
    let s = _mm256_castsi256_pd(_mm256_add_epi64(t, _mm256_slli_epi64::<47>(ki)));
    let z = _mm256_fmadd_pd(_mm256_set1_pd(C0), r, _mm256_set1_pd(C1));
    let r2 = _mm256_mul_pd(r, r);
    let y = _mm256_fmadd_pd(_mm256_set1_pd(C2), r, _mm256_set1_pd(1.0));
    let y = _mm256_fmadd_pd(z, r2, y);
    _mm256_cvtpd_ps(_mm256_mul_pd(y, s))
}

/// Eight lanes of `expf` (see the module docs) for arguments [`in_range`].
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma")]
#[inline]
pub fn expf8(x: __m256) -> __m256 {
    let lo = expf4(_mm256_castps256_ps128(x));
    let hi = expf4(_mm256_extractf128_ps::<1>(x));
    _mm256_set_m128(hi, lo)
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    /// Where the equality holds: the lanes repeat glibc's FMA copy, which glibc runs on a
    /// CPU with FMA and AVX2.
    fn comparable() -> bool {
        cfg!(target_env = "gnu")
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
    }

    /// The lanes against `f32::exp` (libm) for the `f32`s whose bits are `first`,
    /// `first + step`, … below `end`, both signs, those [`in_range`]; returns how many
    /// were compared.
    fn compare(first: u32, end: u32, step: usize) -> u64 {
        let mut compared = 0;
        let mut batch = [0.0f32; 8];
        let mut n = 0;
        let check = |batch: &[f32; 8]| {
            let mut out = [0.0f32; 8];
            // SAFETY: `comparable` checked for AVX2 and FMA.
            unsafe {
                _mm256_storeu_ps(out.as_mut_ptr(), expf8(_mm256_loadu_ps(batch.as_ptr())));
            }
            for (x, y) in batch.iter().zip(out) {
                assert_eq!(
                    y.to_bits(),
                    x.exp().to_bits(),
                    "expf({x:e}) = {y:e}, libm {:e}",
                    x.exp()
                );
            }
        };
        for bits in (first..end).step_by(step) {
            for x in [f32::from_bits(bits), -f32::from_bits(bits)] {
                if in_range(x) {
                    batch[n] = x;
                    n += 1;
                    if n == 8 {
                        check(&batch);
                        compared += 8;
                        n = 0;
                    }
                }
            }
        }
        compared
    }

    /// Every 61st `f32` of the main path, zeros, subnormals and the edges near ±88
    /// included: the lanes give libm's bits. (The exhaustive comparison is the ignored
    /// test below.)
    #[test]
    fn lanes_give_libms_bits() {
        if !comparable() {
            return;
        }
        let compared = compare(0, 0x42b0_0000, 61) + compare(0x42af_f000, 0x42b0_0000, 1);
        assert!(compared > 30_000_000, "{compared}");
        assert!(in_range(87.99) && in_range(-87.99) && !in_range(88.0) && !in_range(f32::NAN));
    }

    /// Every `f32` of the main path (2.2·10⁹, about 15 s in release): the lanes give libm's
    /// bits.
    #[test]
    #[ignore = "exhaustive: about 15 s in release"]
    fn lanes_give_libms_bits_everywhere() {
        if !comparable() {
            return;
        }
        assert!(compare(0, 0x42b0_0000, 1) > 2_000_000_000);
    }
}
