//! Welch's t-test, for comparing two estimators' means when their variances differ
//! (Welch 1947): the statistical tests that check one renderer setting against another.

use super::special::ln_gamma;

/// Two-sided p-value of Student's t with `dof` degrees of freedom:
/// P(|T| ≥ t) = I_{ν/(ν+t²)}(ν/2, 1/2).
pub fn student_t_two_sided(t: f64, dof: f64) -> f64 {
    beta_inc(0.5 * dof, 0.5, dof / (dof + t * t))
}

/// Welch's t-test of equal means from two samples' means, unbiased variances and sizes;
/// the two-sided p-value with Welch–Satterthwaite degrees of freedom.
pub fn welch_p(mean_a: f64, var_a: f64, n_a: f64, mean_b: f64, var_b: f64, n_b: f64) -> f64 {
    let (sa, sb) = (var_a / n_a, var_b / n_b);
    let se2 = sa + sb;
    if se2 == 0.0 {
        return if mean_a == mean_b { 1.0 } else { 0.0 };
    }
    let t = (mean_a - mean_b) / se2.sqrt();
    let dof = se2 * se2 / (sa * sa / (n_a - 1.0) + sb * sb / (n_b - 1.0));
    student_t_two_sided(t, dof)
}

/// [`welch_p`] of two samples given as values.
pub fn welch_p_samples(a: &[f64], b: &[f64]) -> f64 {
    let ((ma, va), (mb, vb)) = (mean_var(a), mean_var(b));
    welch_p(ma, va, a.len() as f64, mb, vb, b.len() as f64)
}

/// Mean and unbiased variance.
fn mean_var(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (
        m,
        x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0),
    )
}

/// Regularized incomplete beta function I_x(a, b) (Numerical Recipes, 3rd ed., §6.4),
/// by its continued fraction with the modified Lentz method.
fn beta_inc(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    // The fraction converges fast for x < (a+1)/(a+b+2); use the symmetry otherwise.
    if x > (a + 1.0) / (a + b + 2.0) {
        return 1.0 - beta_inc(b, a, 1.0 - x);
    }
    let front =
        (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    let tiny = 1e-300;
    let guard = |v: f64| if v.abs() < tiny { tiny } else { v };
    let (mut c, mut d) = (1.0, 1.0 / guard(1.0 - (a + b) * x / (a + 1.0)));
    let mut h = d;
    for m in 1..1000 {
        let m = m as f64;
        for num in [
            m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0)),
        ] {
            d = 1.0 / guard(1.0 + num * d);
            c = guard(1.0 + num / c);
            h *= d * c;
        }
        if (d * c - 1.0).abs() < 1e-15 {
            break;
        }
    }
    front * h / a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tails_match_student_t_tables() {
        // t(0.975; ν = 10) = 2.228139, so a two-sided p of 0.05; t(0.995; 5) = 4.032143;
        // t(1000) is nearly normal: 1.962 → 0.05.
        assert!((student_t_two_sided(2.228_139, 10.0) - 0.05).abs() < 1e-5);
        assert!((student_t_two_sided(4.032_143, 5.0) - 0.01).abs() < 1e-5);
        assert!((student_t_two_sided(1.962, 1000.0) - 0.05).abs() < 1e-3);
        assert!((student_t_two_sided(0.0, 7.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn welch_separates_shifted_samples_and_accepts_equal_ones() {
        let a: Vec<f64> = (0..100).map(|i| (i % 10) as f64).collect();
        let shifted: Vec<f64> = a.iter().map(|v| v + 3.0).collect();
        assert!((welch_p_samples(&a, &a) - 1.0).abs() < 1e-12);
        assert!(welch_p_samples(&a, &shifted) < 1e-6);
    }
}
