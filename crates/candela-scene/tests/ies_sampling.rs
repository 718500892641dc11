//! Chi-square test of the goniometric table's emission sampling against its own density,
//! on a real file and on a synthetic narrow spot.
//!
//! A compact local chi-square (Pearson, bins with expected count < 5 pooled) rather than
//! a shared harness, so this file depends on nothing but the table. Significance 0.01,
//! Šidák-corrected over the tables tested: α = 1 − 0.99^(1/k).

use std::f64::consts::PI;

use candela_core::photometry::GoniometricTable;
use candela_core::sampler::Pcg32;
use candela_scene::ies::{load_ies, parse_ies};
use glam::{Vec2, Vec3};

const SAMPLES: usize = 1_000_000;
/// Bins: 36 in φ (10°) × 720 in θ (0.25°). Equal-θ rather than equal-cos θ rows so that
/// a narrow beam spans many rows, and finer than the tables' 0.5° cells so that a wrong
/// distribution *inside* a cell shows (checked: sampling cos θ with t² instead of t inside
/// each cell gives χ² ≈ 1.8e5 on ~1.7e3 and ~1.1e4 dof). Bin edges fall on the tables'
/// cell edges, so the expected counts below are exact.
const PHI_BINS: usize = 36;
const THETA_BINS: usize = 720;

fn bin_of(d: Vec3) -> usize {
    let theta = (d.z as f64).clamp(-1.0, 1.0).acos();
    let mut phi = (d.y as f64).atan2(d.x as f64);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let i = ((theta / PI * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
    let j = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    i * PHI_BINS + j
}

/// Expected counts: N ∫ pdf dω per bin, by a 4 × 4 midpoint rule in (cos θ, φ) inside
/// each bin (exact here: the density is constant on each table cell and the bins do not
/// straddle cell edges).
fn expected_counts(t: &GoniometricTable) -> Vec<f64> {
    const SUB: usize = 4;
    let mut e = vec![0.0; PHI_BINS * THETA_BINS];
    for i in 0..THETA_BINS {
        let (c0, c1) = (
            (PI * i as f64 / THETA_BINS as f64).cos(),
            (PI * (i + 1) as f64 / THETA_BINS as f64).cos(),
        );
        for j in 0..PHI_BINS {
            let mut sum = 0.0;
            for a in 0..SUB {
                let z = c0 + (c1 - c0) * (a as f64 + 0.5) / SUB as f64;
                let r = (1.0 - z * z).max(0.0).sqrt();
                for b in 0..SUB {
                    let p = 2.0 * PI * (j as f64 + (b as f64 + 0.5) / SUB as f64) / PHI_BINS as f64;
                    sum += t.pdf(Vec3::new(
                        (r * p.cos()) as f32,
                        (r * p.sin()) as f32,
                        z as f32,
                    )) as f64;
                }
            }
            let omega = (c0 - c1) * 2.0 * PI / PHI_BINS as f64;
            e[i * PHI_BINS + j] = SAMPLES as f64 * sum / (SUB * SUB) as f64 * omega;
        }
    }
    e
}

/// ln Γ(x), Lanczos approximation (Numerical Recipes, 3rd ed., §6.1).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 6] = [
        76.18009172947146,
        -86.50532032941677,
        24.01409824083091,
        -1.231739572450155,
        0.1208650973866179e-2,
        -0.5395239384953e-5,
    ];
    let tmp = x + 5.5 - (x + 0.5) * (x + 5.5).ln();
    let ser = C
        .iter()
        .enumerate()
        .fold(1.000000000190015, |s, (k, c)| s + c / (x + 1.0 + k as f64));
    -tmp + (2.5066282746310005 * ser / x).ln()
}

/// Upper regularized incomplete gamma Q(a, x): the chi-square p-value is Q(dof/2, χ²/2).
/// Series for x < a + 1, continued fraction otherwise (Numerical Recipes §6.2).
fn gamma_q(a: f64, x: f64) -> f64 {
    let gln = ln_gamma(a);
    if x < a + 1.0 {
        let (mut ap, mut del) = (a, 1.0 / a);
        let mut sum = del;
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - gln).exp()
    } else {
        let mut b = x + 1.0 - a;
        let (mut c, mut d) = (1.0 / 1e-300, 1.0 / b);
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            d = if d.abs() < 1e-300 { 1e-300 } else { d };
            c = b + an / c;
            c = if c.abs() < 1e-300 { 1e-300 } else { c };
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (-x + a * x.ln() - gln).exp() * h
    }
}

/// Draws SAMPLES directions and returns the chi-square p-value of their histogram.
fn chi2_p_value(t: &GoniometricTable, seed: u64) -> f64 {
    let mut observed = vec![0.0f64; PHI_BINS * THETA_BINS];
    let mut rng = Pcg32::new(seed, 1);
    for _ in 0..SAMPLES {
        let (d, pdf) = t.sample(Vec2::new(rng.uniform_f32(), rng.uniform_f32()));
        assert!(pdf > 0.0 && (d.length() - 1.0).abs() < 1e-4);
        observed[bin_of(d)] += 1.0;
    }
    let expected = expected_counts(t);
    // Pool bins expected below 5 into one, as Pearson's approximation needs.
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for (o, e) in observed.iter().zip(&expected) {
        if *e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            chi2 += (o - e).powi(2) / e;
            dof += 1;
        }
    }
    if pool_e >= 5.0 {
        chi2 += (pool_o - pool_e).powi(2) / pool_e;
        dof += 1;
    } else {
        assert!(
            pool_o <= 5.0 + 3.0 * pool_e.sqrt() + 5.0,
            "{pool_o} samples where {pool_e} expected"
        );
    }
    let p = gamma_q((dof - 1) as f64 / 2.0, chi2 / 2.0);
    eprintln!("chi2 = {chi2:.1}, dof = {}, p = {p:.4}", dof - 1);
    p
}

/// Šidák-corrected significance for the two tables tested below.
fn alpha() -> f64 {
    1.0 - 0.99f64.powf(1.0 / 2.0)
}

#[test]
fn chi_square_helper_matches_known_quantiles() {
    // χ² 0.99 quantiles: dof 1 → 6.635, dof 10 → 23.209, dof 100 → 135.807.
    for (dof, q) in [(1.0, 6.635), (10.0, 23.209), (100.0, 135.807)] {
        assert!(
            (gamma_q(dof / 2.0, q / 2.0) - 0.01).abs() < 2e-4,
            "dof {dof}"
        );
    }
}

#[test]
#[ignore = "1e6 samples; run in release with --include-ignored"]
fn emission_sampling_of_a_real_profile_follows_its_pdf() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/ies");
    let path = std::path::Path::new(dir).join("area_light.ies");
    if !path.exists() {
        eprintln!("skipped: ../shared/data not found (the optional IES conformance collection)");
        return;
    }
    // area_light.ies: asymmetric street light, bilateral 0–180° planes, 0–180° vertical.
    let t = load_ies(&path).unwrap().table().unwrap();
    let p = chi2_p_value(&t, 1);
    assert!(p > alpha(), "p = {p} below α = {}", alpha());
}

#[test]
#[ignore = "1e6 samples; run in release with --include-ignored"]
fn emission_sampling_of_a_narrow_spot_follows_its_pdf() {
    // 12° half-width spot with a 0–90° quadrant-symmetric φ variation, 0.5° vertical steps.
    let v: Vec<String> = (0..=180).map(|k| format!("{}", k as f64 * 0.5)).collect();
    let h = ["0", "30", "60", "90"];
    let mut data = format!(
        "1 -1 1 {} {} 1 2 0 0 0\n1 1 0\n{}\n{}\n",
        v.len(),
        h.len(),
        v.join(" "),
        h.join(" ")
    );
    for (k, _) in h.iter().enumerate() {
        for a in 0..v.len() {
            let theta = a as f64 * 0.5;
            let c = (1000.0 + 300.0 * k as f64) * (1.0 - (theta / 12.0).powi(2)).max(0.0);
            data.push_str(&format!("{c:.3}\n"));
        }
    }
    let text = format!("IESNA:LM-63-2002\n[TEST] spot\nTILT=NONE\n{data}");
    let t = parse_ies(text.as_bytes(), "spot.ies")
        .unwrap()
        .table()
        .unwrap();
    let p = chi2_p_value(&t, 2);
    assert!(p > alpha(), "p = {p} below α = {}", alpha());
}
