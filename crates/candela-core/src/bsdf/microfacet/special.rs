//! Special functions of the Beckmann distribution, in `f32` and without calls to `libm`
//! beyond one `exp` or `ln` each: the scaled complementary error function erfcx (Smith's
//! Λ and the sampler's erf share its e^(−x²) with the formulas around them), the inverse
//! error function, and the coarse `acos` and `powf` of the sampler's first guess.
//!
//! Each was a `libm` call or two before (`erfcf` computes e^(−x²) twice more inside,
//! `erff` once): callgrind on `bench/scenes/sun-sky-glass.xml` counted ≈ 670
//! instructions a visible-normal sample and ≈ 200 a Λ with `libm`'s functions.

/// e^(x²) erfc(x), the scaled complementary error function, for x ≥ 0 (+∞ gives 0).
///
/// erfcx(x) = t g(t) with t = 1/(1 + x/2) ∈ (0, 1], g a degree-10 polynomial: a
/// least-squares fit (relative weights, Chebyshev nodes in t, f64) whose error is
/// 1.2·10⁻⁸ relative on all of [0, ∞); with its coefficients rounded to `f32` and
/// evaluated in `f32` it is 2.9·10⁻⁷ (tests). The variable t maps the half-line to
/// [0, 1] and takes erfcx's 1/(x√π) tail to a finite g(0) = 1/(2√π), as Numerical Recipes' `erfcc` does (there the fit is of ln erfcx,
/// which costs an exponential).
#[inline]
pub fn erfcx(x: f32) -> f32 {
    const G: [f32; 11] = [
        2.820_948e-1,
        2.820_937_6e-1,
        2.468_845_5e-1,
        1.753_161_8e-1,
        9.346_116e-2,
        -5.920_681_7e-2,
        1.321_669_7e-1,
        -4.549_599_6e-1,
        4.936_83e-1,
        -2.347_279_6e-1,
        4.319_429_4e-2,
    ];
    let t = 1.0 / (1.0 + 0.5 * x);
    let mut g = G[10];
    for c in G[..10].iter().rev() {
        g = g * t + c;
    }
    t * g
}

/// The inverse error function on (−1, 1): M. Giles 2012, "Approximating the erfinv
/// function" (GPU Computing Gems, Jade Edition, ch. 10), the single-precision version:
/// two polynomials in w = −ln(1 − x²). Its relative error is a few f32 rounding errors;
/// the tests hold it to the inverse of `libm`'s erf.
pub fn erfinv(x: f32) -> f32 {
    let w = -((1.0 - x) * (1.0 + x)).ln();
    let p = if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.810_226_4e-8;
        p = 3.432_739_4e-7 + p * w;
        p = -3.523_387_7e-6 + p * w;
        p = -4.391_506_5e-6 + p * w;
        p = 2.185_808_7e-4 + p * w;
        p = -1.253_725e-3 + p * w;
        p = -4.177_681_6e-3 + p * w;
        p = 0.246_640_73 + p * w;
        1.501_409_4 + p * w
    } else {
        let w = w.sqrt() - 3.0;
        let mut p = -2.002_142_6e-4;
        p = 1.009_505_6e-4 + p * w;
        p = 1.349_343_2e-3 + p * w;
        p = -3.673_428_4e-3 + p * w;
        p = 5.739_507_7e-3 + p * w;
        p = -7.622_461_3e-3 + p * w;
        p = 9.438_870_5e-3 + p * w;
        p = 1.001_674 + p * w;
        2.832_976_8 + p * w
    };
    p * x
}

/// acos(x) for x ∈ [0, 1] to 6.7·10⁻⁵ rad: Abramowitz & Stegun 4.4.45,
/// √(1 − x)(a₀ + a₁x + a₂x² + a₃x³). For a first guess only.
#[inline]
pub fn coarse_acos(x: f32) -> f32 {
    let p = 1.570_728_8 + x * (-0.212_114_4 + x * (0.074_261 - 0.018_729_3 * x));
    (1.0 - x).max(0.0).sqrt() * p
}

/// y^p for y ∈ (0, 1] and p ∈ [0, 1], to 2·10⁻⁴ relative: 2^(p log₂ y) with log₂ of the
/// mantissa and 2^f of the fraction by degree-4 least-squares polynomials (errors
/// 1.9·10⁻⁴ and 8.8·10⁻⁶). For a first guess only. y = 0 gives 2^(−126 p) or less,
/// a tiny positive number, not 0.
#[inline]
pub fn coarse_powf(y: f32, p: f32) -> f32 {
    let bits = y.to_bits();
    let exponent = ((bits >> 23) & 0xff) as i32 - 127;
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000) - 1.0;
    let log2_m = m * (1.438_547_9 + m * (-0.678_089_5 + m * (0.323_646_3 - 0.084_294_66 * m)));
    // z ≤ 0; from −126 on 2^z is normal.
    let z = (p * (exponent as f32 + log2_m)).clamp(-126.0, 0.0);
    // Truncation rounds towards zero: n = ⌈z⌉ and the fraction f = z − n ∈ (−1, 0].
    let n = z as i32;
    let f = z - n as f32;
    let two_f = 1.0 + f * (0.693_075_8 + f * (0.239_547_9 + f * (0.053_403_67 + 0.006_935_99 * f)));
    f32::from_bits(((n + 127) as u32) << 23) * two_f
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::FRAC_2_SQRT_PI;

    /// e^(x²) erfc(x) in f64: `libm::erfc` times the exponential where that is finite
    /// and accurate (erfc's relative error is an ulp or two down to its underflow), the
    /// asymptotic series beyond x = 20 (its first omitted term is < 10⁻¹⁷ there).
    fn erfcx_reference(x: f64) -> f64 {
        if x < 20.0 {
            return libm::erfc(x) * (x * x).exp();
        }
        let (mut sum, mut term) = (1.0, 1.0);
        for n in 1..8 {
            term *= -(2 * n - 1) as f64 / (2.0 * x * x);
            sum += term;
        }
        sum / (x * std::f64::consts::PI.sqrt())
    }

    /// erfcx against `libm` over [0, 10] in steps of 10⁻⁴ and on to 10⁶ geometrically,
    /// relative tolerance 5·10⁻⁷: the fit's own error is 1.2·10⁻⁸ and f32's rounding of
    /// t and of the ten Horner steps adds up to ~3·10⁻⁷; a wrong coefficient costs 10⁻⁴
    /// or more. And erfcx(+∞) = 0, erfcx(0) = 1.
    #[test]
    fn erfcx_matches_libm() {
        let mut worst = 0.0f64;
        let grid = (0..=100_000).map(|i| i as f32 * 1e-4);
        let tail = (0..=500).map(|i| 10f32 * 10f32.powf(i as f32 / 100.0));
        for x in grid.chain(tail) {
            let want = erfcx_reference(x as f64);
            let err = (erfcx(x) as f64 - want).abs() / want;
            worst = worst.max(err);
            assert!(err < 5e-7, "erfcx({x}) = {}, exact {want}", erfcx(x));
        }
        eprintln!("erfcx: worst relative error {worst:e}");
        assert_eq!(erfcx(f32::INFINITY), 0.0);
        assert!((erfcx(0.0) - 1.0).abs() < 1e-7);
    }

    /// The coarse acos within 7·10⁻⁵ rad of `f64::acos` on [0, 1]; the coarse powf within
    /// 2.5·10⁻⁴ relative of `f64::powf` for y from 2⁻²⁴ to 1 and p from 0.4 to 1 (the
    /// first guess's range), their documented bounds with f32 rounding on top.
    #[test]
    fn coarse_acos_and_powf_are_within_their_bounds() {
        for i in 0..=10_000 {
            let x = i as f32 / 10_000.0;
            let err = (coarse_acos(x) as f64 - (x as f64).acos()).abs();
            assert!(err < 7e-5, "acos({x}): error {err:e}");
        }
        for i in 0..=2400 {
            let y = 2f32.powf(-i as f32 / 100.0);
            for j in 0..=60 {
                let p = 0.4 + j as f32 / 100.0;
                let want = (y as f64).powf(p as f64);
                let err = (coarse_powf(y, p) as f64 - want).abs() / want;
                assert!(err < 2.5e-4, "{y}^{p}: error {err:e}");
            }
        }
        assert!(coarse_powf(0.0, 1.0) > 0.0);
    }

    /// erfinv(y) for f32 y, in f64: bisection on `libm::erf` (f64, accurate to an ulp).
    fn erfinv_reference(y: f32) -> f64 {
        let (mut lo, mut hi) = (-6.0f64, 6.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if libm::erf(mid) < y as f64 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// erfinv against the exact inverse of erf, for y on a grid of (−1, 1) that is
    /// dense near ±1 (y = ±(1 − 10⁻ᵏ) down to f32's last step below 1). Tolerance 10⁻⁶
    /// relative: Giles' polynomials are fitted to ≈ 3·10⁻⁷ and f32 rounds each step by
    /// 6·10⁻⁸; a wrong coefficient costs 10⁻⁴ or more. And erfinv(erf(x)) = x on
    /// |x| ≤ 3, within 10⁻⁶ relative plus erf's conditioning: erf(x) is rounded to f32
    /// (≤ 6·10⁻⁸ absolute), which moves x by 6·10⁻⁸/erf′(x) (4·10⁻⁴ at x = 3), doubled
    /// for the erfinv side.
    #[test]
    fn erfinv_inverts_erf() {
        let mut ys: Vec<f32> = (-999..=999).map(|i| i as f32 / 1000.0).collect();
        for k in 1..8 {
            let y = 1.0 - 10f32.powi(-k);
            ys.extend([y, -y]);
        }
        ys.extend([
            1.0 - f32::EPSILON / 2.0,
            -(1.0 - f32::EPSILON / 2.0),
            1e-8,
            -1e-8,
        ]);
        let mut worst = 0.0f64;
        for y in ys {
            let (got, want) = (erfinv(y) as f64, erfinv_reference(y));
            let err = (got - want).abs() / want.abs().max(1e-30);
            worst = worst.max(err);
            assert!(
                err < 1e-6,
                "erfinv({y}) = {got}, exact {want}: rel. error {err:e}"
            );
        }
        eprintln!("erfinv: worst relative error {worst:e}");
        for i in -300..=300 {
            let x = i as f32 / 100.0;
            let slope = FRAC_2_SQRT_PI as f64 * (-(x as f64).powi(2)).exp();
            let tol = 1e-6 * x.abs() as f64 + 2.0 * 6e-8 / slope;
            let back = erfinv(libm::erff(x)) as f64;
            assert!(
                (back - x as f64).abs() <= tol,
                "erfinv(erf({x})) = {back}, tolerance {tol:e}"
            );
        }
    }
}
