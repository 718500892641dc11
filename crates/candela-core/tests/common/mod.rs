//! Distribution tails for the statistical tests of the camera: chi-square and Student t,
//! from the regularized incomplete gamma and beta functions (Numerical Recipes, 3rd ed.,
//! §6.2 and §6.4). A compact stand-in until `candela_core::chi2` lands on main.

#![allow(dead_code)]

fn ln_gamma(x: f64) -> f64 {
    // Lanczos approximation, g = 7, n = 9 (error < 1e-13 for x > 0).
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let t = x + 7.5;
    let s = C[0] + (1..9).map(|i| C[i] / (x + i as f64)).sum::<f64>();
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + s.ln()
}

/// Regularized upper incomplete gamma Q(a, x).
fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // Series for P(a, x).
        let (mut sum, mut term, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * front
    } else {
        // Continued fraction for Q(a, x) (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            d = if d.abs() < tiny { tiny } else { d };
            c = b + an / c;
            c = if c.abs() < tiny { tiny } else { c };
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        front * h
    }
}

/// P(X ≥ x) for X ~ χ²(dof).
pub fn chi2_sf(x: f64, dof: f64) -> f64 {
    gamma_q(0.5 * dof, 0.5 * x)
}

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
    // χ²(10) at its 0.05 critical value 18.307; χ²(1) at 3.841 (0.05).
    assert!((chi2_sf(18.307, 10.0) - 0.05).abs() < 1e-4);
    assert!((chi2_sf(3.841, 1.0) - 0.05).abs() < 1e-4);
    // t(10) two-sided 0.05 critical value 2.228; t(1000) ≈ normal, 1.962.
    assert!((student_t_two_sided(2.228, 10.0) - 0.05).abs() < 1e-4);
    assert!((student_t_two_sided(1.962, 1000.0) - 0.05).abs() < 1e-3);
}
