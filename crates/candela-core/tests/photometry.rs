//! The goniometric table: its frame, interpolation without overshoot, flux, beam angle and
//! the density of its emission sampling.

use std::f64::consts::PI;

use candela_core::photometry::{GoniometricTable, HorizontalSymmetry};
use candela_core::sampler::Pcg32;
use glam::{Vec2, Vec3};

fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(
        (t.sin() * p.cos()) as f32,
        (t.sin() * p.sin()) as f32,
        t.cos() as f32,
    )
}

#[test]
fn table_frame_nadir_is_z_c0_is_x_c90_is_y() {
    // At θ = 90° the planes C0, C90, C180, C270 have 100, 50, 20, 10 cd; nadir 7, zenith 3.
    let v = [0.0, 90.0, 180.0];
    let h = [0.0, 90.0, 180.0, 270.0, 360.0];
    let cd: Vec<f64> = [100.0, 50.0, 20.0, 10.0, 100.0]
        .iter()
        .flat_map(|&m| [7.0, m, 3.0])
        .collect();
    let t = GoniometricTable::new(&v, &h, &cd).unwrap();
    assert_eq!(t.intensity(Vec3::Z), 7.0);
    assert_eq!(t.intensity(-Vec3::Z), 3.0);
    assert_eq!(t.intensity(Vec3::X), 100.0);
    assert_eq!(t.intensity(Vec3::Y), 50.0);
    assert_eq!(t.intensity(-Vec3::X), 20.0);
    assert_eq!(t.intensity(-Vec3::Y), 10.0);
    assert_eq!(t.max_intensity(), 100.0);
}

#[test]
fn symmetry_is_classified_from_the_angle_range() {
    use HorizontalSymmetry::*;
    let c = |h: &[f64]| HorizontalSymmetry::classify(h);
    assert_eq!(c(&[0.0]), Ok(Rotational));
    assert_eq!(c(&[0.0, 45.0, 90.0]), Ok(Quadrant));
    assert_eq!(c(&[0.0, 180.0]), Ok(BilateralC0));
    assert_eq!(c(&[90.0, 180.0, 270.0]), Ok(BilateralC90));
    assert_eq!(c(&[0.0, 120.0, 240.0, 360.0]), Ok(None));
    assert!(c(&[0.0, 45.0]).is_err() && c(&[10.0, 100.0]).is_err() && c(&[]).is_err());
}

/// Random non-uniform angles and random values: the interpolated intensity at any
/// direction lies between the smallest and largest of the measured values around it.
/// Angles on a 0.5° grid are reproduced exactly, so the bound is the four corners of the
/// measured cell; angles off every grid (0.1° steps here) are resampled to 0.25° × 0.5°,
/// and a table cell straddling a measured angle may then reach into the neighbouring
/// measured cell, so the bound widens to the 4 × 4 measured values around the direction.
#[test]
fn interpolation_never_overshoots() {
    for (resolution, reach) in [(2.0, 0usize), (10.0, 1)] {
        let mut rng = Pcg32::new(11, resolution as u64);
        let mut angles = |n: usize, max: f64| {
            let mut a: Vec<f64> = (0..n)
                .map(|_| (rng.uniform_f32() as f64 * max * resolution).round() / resolution)
                .collect();
            a.extend([0.0, max]);
            a.sort_by(f64::total_cmp);
            a.dedup();
            a
        };
        let v = angles(12, 180.0);
        let h = angles(9, 360.0);
        let mut rng = Pcg32::new(12, 0);
        let mut cd: Vec<f64> = (0..v.len() * h.len())
            .map(|_| 1000.0 * rng.uniform_f32() as f64)
            .collect();
        let first_plane = cd[..v.len()].to_vec();
        cd[(h.len() - 1) * v.len()..].copy_from_slice(&first_plane); // 360° = 0°
        let t = GoniometricTable::new(&v, &h, &cd).unwrap();
        let bracket = |a: &[f64], x: f64| {
            let k = a.partition_point(|&y| y <= x).clamp(1, a.len() - 1);
            (k - 1).saturating_sub(reach)..=(k + reach).min(a.len() - 1)
        };
        for _ in 0..20_000 {
            let (theta, phi) = (
                180.0 * rng.uniform_f32() as f64,
                360.0 * rng.uniform_f32() as f64,
            );
            let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
            for hk in bracket(&h, phi) {
                for vk in bracket(&v, theta) {
                    lo = lo.min(cd[hk * v.len() + vk]);
                    hi = hi.max(cd[hk * v.len() + vk]);
                }
            }
            let i = t.intensity(dir(theta, phi)) as f64;
            assert!(
                i >= lo * (1.0 - 1e-5) - 1e-3 && i <= hi * (1.0 + 1e-5) + 1e-3,
                "θ {theta} φ {phi}: {i} not in [{lo}, {hi}]"
            );
        }
    }
    // And along a single plane between two measured vertical angles.
    let t = GoniometricTable::new(&[0.0, 10.0, 90.0], &[0.0], &[50.0, 200.0, 0.0]).unwrap();
    for k in 0..=100 {
        let i = t.intensity(dir(k as f64 * 0.1, 0.0));
        assert!((50.0..=200.0).contains(&i), "{i}");
    }
}

#[test]
fn flux_matches_closed_forms() {
    // Isotropic 10 cd: Φ = 4π · 10 lm.
    let t = GoniometricTable::new(&[0.0, 180.0], &[0.0], &[10.0, 10.0]).unwrap();
    assert!(
        (t.total_flux() / (40.0 * PI) - 1.0).abs() < 1e-6,
        "{}",
        t.total_flux()
    );
    // Lambertian downlight I = I0 cos θ (θ ≤ 90°, 1° samples): Φ = π I0. The 1° linear
    // interpolation of cos θ is within 4e-5 relative of it.
    let v: Vec<f64> = (0..=90).map(|d| d as f64).collect();
    let cd: Vec<f64> = v.iter().map(|d| 1000.0 * d.to_radians().cos()).collect();
    let t = GoniometricTable::new(&v, &[0.0], &cd).unwrap();
    assert!(
        (t.total_flux() / (1000.0 * PI) - 1.0).abs() < 1e-4,
        "{}",
        t.total_flux()
    );
    // The same halved, as bilateral 0–180° data in three planes: half the flux.
    let h = [0.0, 90.0, 180.0];
    let half: Vec<f64> = (0..3).flat_map(|_| cd.iter().map(|c| 0.5 * c)).collect();
    let f_half = GoniometricTable::new(&v, &h, &half).unwrap().total_flux();
    assert!((f_half / (500.0 * PI) - 1.0).abs() < 1e-4, "{f_half}");
}

#[test]
fn beam_angle_is_the_full_width_at_half_maximum() {
    // I = 1000 (1 − θ/30°) up to 30°: half at 15°, so 30° across the beam in every plane.
    let v: Vec<f64> = (0..=90).map(|d| d as f64).collect();
    let cd: Vec<f64> = v
        .iter()
        .map(|d| 1000.0 * (1.0 - d / 30.0).max(0.0))
        .collect();
    let t = GoniometricTable::new(&v, &[0.0], &cd).unwrap();
    assert!((t.beam_angle() - 30.0).abs() < 0.1, "{}", t.beam_angle());
    // Isotropic: never falls to half.
    let t = GoniometricTable::new(&[0.0, 180.0], &[0.0], &[1.0, 1.0]).unwrap();
    assert_eq!(t.beam_angle(), 360.0);
}

/// Midpoint rule over (cos θ, φ) with 1000 × 2000 cells: the density integrates to one.
/// The density is piecewise constant over the table's cells, so the only error is from
/// integration cells that straddle a table cell edge: below 1e-3 here.
#[test]
fn pdf_integrates_to_one_and_is_positive_where_light_is() {
    let v: Vec<f64> = (0..=90).map(|d| d as f64).collect();
    let h = [0.0, 45.0, 90.0];
    let cd: Vec<f64> = (0..3)
        .flat_map(|k| {
            v.iter()
                .map(move |d| (500.0 + 200.0 * k as f64) * (1.0 - d / 40.0).max(0.0))
        })
        .collect();
    let t = GoniometricTable::new(&v, &h, &cd).unwrap();
    let (nc, np) = (1000, 2000);
    let mut sum = 0.0f64;
    for a in 0..nc {
        let z = -1.0 + 2.0 * (a as f64 + 0.5) / nc as f64;
        let r = (1.0 - z * z).sqrt();
        for b in 0..np {
            let p = 2.0 * PI * (b as f64 + 0.5) / np as f64;
            let d = Vec3::new((r * p.cos()) as f32, (r * p.sin()) as f32, z as f32);
            let pdf = t.pdf(d);
            if t.intensity(d) > 0.0 {
                assert!(pdf > 0.0, "dark pdf where light shines: {d}");
            }
            sum += pdf as f64;
        }
    }
    let integral = sum * 4.0 * PI / (nc * np) as f64;
    assert!((integral - 1.0).abs() < 1e-3, "∫ pdf = {integral}");
    // Sampled directions carry the density pdf() gives them, and light shines there.
    let mut rng = Pcg32::new(5, 5);
    for _ in 0..10_000 {
        let (d, pdf) = t.sample(Vec2::new(rng.uniform_f32(), rng.uniform_f32()));
        assert!((d.length() - 1.0).abs() < 1e-5 && pdf > 0.0);
        assert!((t.pdf(d) / pdf - 1.0).abs() < 1e-5 || t.intensity(d) == 0.0);
    }
}
