//! Welch's t-test for the camera's statistical tests: Student's t tail from the
//! regularized incomplete beta function (Numerical Recipes, 3rd ed., §6.4), with
//! `candela_core::chi2::ln_gamma`.

#![allow(dead_code)]

use candela_core::chi2::ln_gamma;

/// Continued fraction of the incomplete beta function (modified Lentz).
fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    let tiny = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    d = if d.abs() < tiny { tiny } else { d };
    d = 1.0 / d;
    let mut h = d;
    for m in 1..10_000 {
        let m = m as f64;
        let m2 = 2.0 * m;
        for aa in [
            m * (b - m) * x / ((qam + m2) * (a + m2)),
            -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2)),
        ] {
            d = 1.0 + aa * d;
            d = if d.abs() < tiny { tiny } else { d };
            c = 1.0 + aa / c;
            c = if c.abs() < tiny { tiny } else { c };
            d = 1.0 / d;
            h *= d * c;
        }
        if (d * c - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// Regularized incomplete beta I_x(a, b).
fn beta_i(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front =
        (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_cf(a, b, x) / a
    } else {
        1.0 - front * beta_cf(b, a, 1.0 - x) / b
    }
}

/// Two-sided p-value of Student's t with `dof` degrees of freedom.
pub fn student_t_two_sided(t: f64, dof: f64) -> f64 {
    beta_i(0.5 * dof, 0.5, dof / (dof + t * t))
}

/// Welch's t-test of equal means from two samples' means, variances (unbiased) and
/// sizes; returns the two-sided p-value (Welch–Satterthwaite degrees of freedom).
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

#[test]
fn tails_match_tabulated_values() {
    // t(10) two-sided 0.05 critical value 2.228; t(1000) ≈ normal, 1.962.
    assert!((student_t_two_sided(2.228, 10.0) - 0.05).abs() < 1e-4);
    assert!((student_t_two_sided(1.962, 1000.0) - 0.05).abs() < 1e-3);
}
