//! Tests of the harness itself: its numerics against closed forms, and that it accepts
//! correct samplers and rejects wrong ones.

use std::f32::consts::PI;

use glam::Vec2;

use super::*;
use crate::sampling::{
    cosine_hemisphere_pdf, sample_concentric_disk, sample_cosine_hemisphere, sample_uniform_sphere,
    UNIFORM_SPHERE_PDF,
};

fn small() -> ChiSquareTest {
    // 2·10⁵ samples keep the unit tests quick; the wrong samplers below are wrong by far
    // more than this resolves.
    ChiSquareTest {
        sample_count: 200_000,
        res: 16,
        ..Default::default()
    }
}

#[test]
fn ln_gamma_matches_factorials_and_sqrt_pi() {
    let close = |a: f64, b: f64| (a - b).abs() < 1e-12 * b.abs().max(1.0);
    assert!(close(ln_gamma(1.0), 0.0));
    assert!(close(ln_gamma(5.0), 24f64.ln()));
    assert!(close(ln_gamma(0.5), std::f64::consts::PI.sqrt().ln()));
    assert!(close(
        ln_gamma(101.0),
        (1..=100).map(|i| (i as f64).ln()).sum()
    ));
}

#[test]
fn chi2_survival_matches_closed_forms_and_tables() {
    // Two degrees of freedom: Q = e^{-x/2} exactly.
    for x in [0.1, 1.0, 5.0, 30.0, 200.0] {
        let q = chi2_survival(x, 2.0);
        assert!(
            (q / (-x / 2.0f64).exp() - 1.0).abs() < 1e-10,
            "x = {x}: {q}"
        );
    }
    // Upper 5% and 1% points from standard tables (Abramowitz & Stegun 26.8).
    for (x, k, p) in [
        (3.841_459, 1.0, 0.05),
        (18.307_038, 10.0, 0.05),
        (124.342_113, 100.0, 0.05),
        (135.806_723, 100.0, 0.01),
        (1_106.969_0, 1000.0, 0.01),
    ] {
        let q = chi2_survival(x, k);
        assert!(
            (q - p).abs() < 1e-4 * p.max(0.01) * 10.0,
            "k = {k}: {q} vs {p}"
        );
    }
    assert_eq!(chi2_survival(0.0, 3.0), 1.0);
    assert!(chi2_survival(1e4, 3.0) < 1e-300);
}

#[test]
fn sidak_alpha_composes_to_the_family_significance() {
    let a = sidak_alpha(0.01, 20);
    assert!(((1.0 - a).powi(20) - 0.99).abs() < 1e-12);
    assert!((sidak_alpha(0.01, 1) - 0.01).abs() < 1e-15);
}

#[test]
fn accepts_a_correct_direction_sampler() {
    let r = small().spherical(
        "cosine",
        |u| Some(sample_cosine_hemisphere(u)),
        |d| cosine_hemisphere_pdf(d.z),
    );
    r.assert_passed();
    assert!((r.pdf_integral - 1.0).abs() < 1e-3, "{r}");
}

#[test]
fn rejects_cosine_samples_against_a_uniform_hemisphere_pdf() {
    // Same support and both normalized: only the histogram's shape can tell them apart.
    let r = small().spherical(
        "cosine vs uniform",
        |u| Some(sample_cosine_hemisphere(u)),
        |d| {
            if d.z > 0.0 {
                1.0 / (2.0 * PI)
            } else {
                0.0
            }
        },
    );
    assert!(!r.passed(), "{r}");
    assert!(r.p_value < 1e-100, "{r}");
    assert!(r.failures.iter().any(|f| f.contains("histogram")), "{r}");
    assert!(!r.worst_cells.is_empty());
    assert!(format!("{r}").contains("FAILED"));
}

#[test]
fn rejects_a_pdf_off_by_a_constant() {
    // The shape is right, so χ² alone would pass the normalized counts: the integral check
    // must catch it.
    let r = small().spherical(
        "sphere, pdf × 1.01",
        |u| Some(sample_uniform_sphere(u)),
        |_| UNIFORM_SPHERE_PDF * 1.01,
    );
    assert!(r.failures.iter().any(|f| f.contains("integrates")), "{r}");
}

#[test]
fn accounts_for_failed_samples() {
    // A sampler that gives up on half its inputs, with a pdf that integrates to one half.
    let ok = small().spherical(
        "half sphere",
        |u| (u.x < 0.5).then(|| sample_uniform_sphere(u)),
        |d| if d.z > 0.0 { UNIFORM_SPHERE_PDF } else { 0.0 },
    );
    ok.assert_passed();
    assert!((ok.success_fraction - 0.5).abs() < 0.01);
}

#[test]
fn rejects_samples_where_the_pdf_is_zero() {
    // Uniform-sphere samples, but the pdf claims they never go below z = -0.9.
    let r = small().spherical(
        "leaky",
        |u| Some(sample_uniform_sphere(u)),
        |d| {
            if d.z > -0.9 {
                UNIFORM_SPHERE_PDF
            } else {
                0.0
            }
        },
    );
    assert!(r.failures.iter().any(|f| f.contains("pdf is 0")), "{r}");
}

#[test]
fn rejects_non_unit_directions() {
    let r = small().spherical(
        "long",
        |u| Some(2.0 * sample_uniform_sphere(u)),
        |_| UNIFORM_SPHERE_PDF,
    );
    assert!(r.failures.iter().any(|f| f.contains("unit")), "{r}");
}

#[test]
fn planar_accepts_the_concentric_disk_and_rejects_a_naive_polar_map() {
    let disk_pdf = |p: Vec2| {
        if p.length_squared() <= 1.0 {
            1.0 / PI
        } else {
            0.0
        }
    };
    let t = small();
    let ok = t.planar(
        "concentric disk",
        -Vec2::ONE,
        Vec2::ONE,
        |u| Some(sample_concentric_disk(u)),
        disk_pdf,
    );
    ok.assert_passed();
    // r = u₁ instead of √u₁ crowds the centre: the classic mistake.
    let bad = t.planar(
        "naive polar disk",
        -Vec2::ONE,
        Vec2::ONE,
        |u| {
            let (s, c) = (2.0 * PI * u.y).sin_cos();
            Some(u.x * Vec2::new(c, s))
        },
        disk_pdf,
    );
    assert!(!bad.passed(), "{bad}");
    assert!(bad.histogram_dump().lines().count() == 2 * (t.res + 1));
}

#[test]
fn discrete_accepts_true_frequencies_and_rejects_a_wrong_pmf() {
    let pmf = [0.1, 0.0, 0.3, 0.6];
    let mut rng = Pcg32::new(3, 4);
    let mut counts = [0u64; 4];
    for _ in 0..100_000 {
        let u = rng.uniform_f32() as f64;
        let i = if u < 0.1 {
            0
        } else if u < 0.4 {
            2
        } else {
            3
        };
        counts[i] += 1;
    }
    discrete("true", &counts, &pmf, 0.01).assert_passed();
    let wrong = [0.11, 0.0, 0.29, 0.6];
    assert!(!discrete("wrong", &counts, &wrong, 0.01).passed());
    counts[1] = 1;
    let r = discrete("impossible outcome", &counts, &pmf, 0.01);
    assert!(
        r.failures.iter().any(|f| f.contains("probability 0")),
        "{r}"
    );
}
