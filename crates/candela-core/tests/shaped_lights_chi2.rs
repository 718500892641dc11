//! Chi-square tests of the emission sampling of spotlights (cone) and goniometric lights
//! (profile table) against the densities they claim, with the shared harness
//! (`candela_core::chi2`): 10⁶ samples, fixed seeds, family-wise significance 0.01 split
//! over the tests of this file by the Šidák correction. `#[ignore]`d because they are
//! slow in debug builds (about 45 s in release on one core); CI runs them with
//! `--release -- --include-ignored`. Each prints its χ², dof and p-value.

use std::sync::Arc;

use candela_core::chi2::{sidak_alpha, ChiSquareTest};
use candela_core::desc::SpotFalloff;
use candela_core::light::{GoniometricLight, LightProfile, SpotLight};
use candela_core::photometry::GoniometricTable;
use glam::Vec3;

/// Spots: 3 cones (the sampler does not depend on the falloff curve, which only changes
/// the value); goniometric: 2 profiles; spot with profile: 1.
const TESTS: usize = 6;

fn test() -> ChiSquareTest {
    ChiSquareTest {
        alpha: sidak_alpha(0.01, TESTS),
        ..Default::default()
    }
}

#[test]
#[ignore = "slow: 6 chi-square tests of 10^6 samples"]
fn spot_emission_sampling_matches_its_pdf() {
    for (falloff, (inner, outer)) in [
        (SpotFalloff::Smoothstep, (15.0f32, 40.0f32)),
        (SpotFalloff::Mitsuba, (0.0, 90.0)),
        (SpotFalloff::Gltf, (30.0, 30.0)),
    ] {
        {
            let spot = SpotLight::new(
                Vec3::ZERO,
                Vec3::new(0.3, -0.2, 0.9),
                inner.to_radians(),
                outer.to_radians(),
                falloff,
                Vec3::ONE,
                None,
            );
            let report = test().spherical(
                &format!("{falloff:?} spot {inner}–{outer}°"),
                |u| spot.sample_emission(u).map(|(w, _)| w),
                |w| spot.emission_pdf(w),
            );
            println!("{}", report.to_string().lines().next().unwrap_or(""));
            report.assert_passed();
            // The density the sampler returns is the one `emission_pdf` states.
            for u in [[0.1, 0.2], [0.5, 0.9], [0.95, 0.4]] {
                if let Some((w, pdf)) = spot.sample_emission(u.into()) {
                    assert!((pdf - spot.emission_pdf(w)).abs() <= 1e-4 * pdf);
                    assert!(spot.intensity_towards(w) != Vec3::ZERO || inner == outer);
                }
            }
        }
    }
}

fn narrow_table() -> Arc<GoniometricTable> {
    let v: Vec<f64> = (0..=36).map(|i| i as f64 * 2.5).collect();
    let cd: Vec<f64> = v
        .iter()
        .map(|&t| 500.0 * (-(t / 12.0).powi(2)).exp())
        .collect();
    Arc::new(GoniometricTable::new(&v, &[0.0], &cd).unwrap())
}

fn batwing_table() -> Arc<GoniometricTable> {
    let v: Vec<f64> = (0..=18).map(|i| i as f64 * 10.0).collect();
    let h: Vec<f64> = (0..=4).map(|i| i as f64 * 22.5).collect();
    let mut cd = Vec::new();
    for &phi in &h {
        for &t in &v {
            let wing = (-((t - 50.0) / 15.0).powi(2)).exp() * (1.0 + phi / 90.0);
            cd.push(if t <= 90.0 { 200.0 * wing + 20.0 } else { 0.0 });
        }
    }
    Arc::new(GoniometricTable::new(&v, &h, &cd).unwrap())
}

#[test]
#[ignore = "slow: 6 chi-square tests of 10^6 samples"]
fn goniometric_emission_sampling_matches_its_pdf() {
    for (name, table) in [("narrow", narrow_table()), ("batwing", batwing_table())] {
        let light = GoniometricLight {
            position: Vec3::ZERO,
            intensity: Vec3::ONE,
            profile: LightProfile::new(table, Vec3::new(0.2, -1.0, 0.1), Vec3::X).unwrap(),
        };
        let report = test().spherical(
            &format!("goniometric {name}"),
            |u| light.sample_emission(u).map(|(w, _)| w),
            |w| light.emission_pdf(w),
        );
        println!("{}", report.to_string().lines().next().unwrap_or(""));
        report.assert_passed();
    }
}

#[test]
#[ignore = "slow: 6 chi-square tests of 10^6 samples"]
fn profiled_spot_emission_sampling_matches_its_pdf() {
    let dir = Vec3::new(-0.4, -1.0, 0.3);
    let spot = SpotLight::new(
        Vec3::ZERO,
        dir,
        10f32.to_radians(),
        70f32.to_radians(),
        SpotFalloff::Smoothstep,
        Vec3::ONE,
        LightProfile::new(batwing_table(), dir, Vec3::Z),
    );
    let report = test().spherical(
        "spot with batwing profile",
        |u| spot.sample_emission(u).map(|(w, _)| w),
        |w| spot.emission_pdf(w),
    );
    println!("{}", report.to_string().lines().next().unwrap_or(""));
    report.assert_passed();
}
