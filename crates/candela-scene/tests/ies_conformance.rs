//! IES conformance on every file in ../shared/data/ies: each parses, its table integrates
//! to the lumens the file states (up to the luminaire's efficiency, listed below), agrees
//! with an independent quadrature of the raw data, reproduces the measured values and is
//! symmetric where the file says it is.

use std::f64::consts::PI;
use std::path::PathBuf;

use candela_core::photometry::HorizontalSymmetry;
use candela_core::sampler::Pcg32;
use candela_scene::ies::{load_ies, summary, IesFile};

fn data_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/ies"
    ));
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("skipped: ../shared/data not found (the optional IES conformance collection)");
        None
    }
}

fn ies_files(dir: &PathBuf) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("readable data dir")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("ies")))
        .collect();
    files.sort();
    files
}

/// Luminaire efficiency η = integrated lumens / (lamps × rated lamp lumens). Relative
/// photometry states the bare lamps' output while the candela table is the luminaire's,
/// so η < 1 is legitimate (reflector, lens and housing losses). Only two files state their
/// own reference: `defined.ies` is scaled to the luminaire's own lumens (η ≈ 1) and
/// `defined_diffuse.ies` says "light output ratio: 0.5912" in its header. The others have
/// no stated efficiency; their η is what this loader measures, cross-checked by the
/// independent quadrature in `integrated_lumens_match_an_independent_quadrature` (so it
/// is not just this code's answer echoed back) and each is physically plausible (< 1).
const EFFICIENCY: &[(&str, f64)] = &[
    ("area_light.ies", 0.691), // multiplier 1.27 applied; street light with reflector
    ("bollard.ies", 0.284),    // bollard with cone reflector and acrylic lens
    ("comet.ies", 0.731),      // 2 lamps × 11000 lm
    ("cylinder_narrow.ies", 0.595), // narrow cylinder downlight
    ("defined.ies", 1.0),      // stated lumens are the luminaire's: must agree
    ("defined_diffuse.ies", 0.5912), // the file's own "light output ratio: 0.5912"
    ("medium_scatter.ies", 0.438),
    ("soft_arrow.ies", 0.885),
    ("star_focused.ies", 0.487), // the [LAMP] line rates the lamp at 68 lm
    ("tight_focused.ies", 0.510),
    ("vee.ies", 0.361),
    ("x_arrow.ies", 0.300),
];

/// Relative tolerance on η: 3%. The table fades to 0 over one grid step (≤ 1°) past the
/// file's vertical range and rounding in the files' printed values is ~0.1%; the 0.35%
/// gap on `defined_diffuse.ies` is the largest seen. A factor-of-2 (missing multiplier,
/// lamps counted twice) or feet/metres (×10.76 in area) error is far outside it.
const EFFICIENCY_TOLERANCE: f64 = 0.03;

#[test]
fn every_file_parses_and_integrates_to_its_stated_lumens() {
    let Some(dir) = data_dir() else { return };
    let files = ies_files(&dir);
    assert!(
        files.len() >= 13,
        "expected the 13 staged files, found {}",
        files.len()
    );
    for f in files {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let ies = load_ies(&f).unwrap_or_else(|e| panic!("{e}"));
        let s = summary(&ies).unwrap_or_else(|e| panic!("{e}"));
        assert!(s.integrated_lumens > 0.0 && s.peak_candela > 0.0, "{name}");
        assert!(
            s.beam_angle_deg > 0.0 && s.beam_angle_deg <= 360.0,
            "{name}"
        );
        let Some(stated) = s.stated_lumens else {
            assert!(
                ies.lumens_per_lamp < 0.0,
                "{name}: only absolute photometry lacks lumens"
            );
            continue;
        };
        let eta = s.integrated_lumens / stated;
        let expected = EFFICIENCY
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("{name}: not in EFFICIENCY (η = {eta:.4})"))
            .1;
        assert!(
            (eta / expected - 1.0).abs() < EFFICIENCY_TOLERANCE,
            "{name}: integrated {:.1} lm / stated {stated} lm = {eta:.4}, expected {expected}",
            s.integrated_lumens
        );
        assert!(
            eta < 1.0 + EFFICIENCY_TOLERANCE,
            "{name}: luminaire brighter than its lamps"
        );
    }
}

/// ∫ I dω of the file's own data, written independently of the table: the θ integral of
/// each plane's piecewise-linear curve × sin θ by the midpoint rule (0.01° steps), the φ
/// integral by trapezoid weights over the measured planes times the symmetry's copies.
fn raw_flux(ies: &IesFile) -> f64 {
    let (v, h) = (&ies.vertical_angles, &ies.horizontal_angles);
    let nv = v.len();
    let plane_integral = |col: &[f64]| -> f64 {
        let mut sum = 0.0;
        for k in 0..nv - 1 {
            let steps = ((v[k + 1] - v[k]) * 100.0).ceil() as usize;
            let d = (v[k + 1] - v[k]) / steps as f64;
            for s in 0..steps {
                let t = (s as f64 + 0.5) / steps as f64;
                let theta = (v[k] + t * (v[k + 1] - v[k])).to_radians();
                sum += ((1.0 - t) * col[k] + t * col[k + 1]) * theta.sin() * d.to_radians();
            }
        }
        sum
    };
    let planes: Vec<f64> = ies.candela.chunks(nv).map(plane_integral).collect();
    if h.len() == 1 {
        return 2.0 * PI * planes[0];
    }
    let mut over_range = 0.0;
    for k in 0..h.len() - 1 {
        over_range += 0.5 * (planes[k] + planes[k + 1]) * (h[k + 1] - h[k]).to_radians();
    }
    match ies.symmetry() {
        HorizontalSymmetry::Quadrant => 4.0 * over_range,
        HorizontalSymmetry::BilateralC0 | HorizontalSymmetry::BilateralC90 => 2.0 * over_range,
        HorizontalSymmetry::None => {
            let gap = (360.0 - h[h.len() - 1]).to_radians();
            over_range + 0.5 * (planes[0] + planes[h.len() - 1]) * gap
        }
        HorizontalSymmetry::Rotational => unreachable!(),
    }
}

#[test]
fn integrated_lumens_match_an_independent_quadrature() {
    let Some(dir) = data_dir() else { return };
    for f in ies_files(&dir) {
        let ies = load_ies(&f).unwrap_or_else(|e| panic!("{e}"));
        let table = ies.table().unwrap();
        let (ours, theirs) = (table.total_flux(), raw_flux(&ies));
        // 1%: the fade past the vertical range adds at most I(edge)·sin θ·Δθ/2 per plane,
        // well under 1% for these files; the midpoint rule's error is ~1e-8.
        assert!(
            (ours / theirs - 1.0).abs() < 0.01,
            "{}: table {ours:.2} lm vs quadrature {theirs:.2} lm",
            f.display()
        );
    }
}

#[test]
fn table_reproduces_measured_values_and_mirrors_symmetric_profiles() {
    let Some(dir) = data_dir() else { return };
    let mut rng = Pcg32::new(7, 3);
    for f in ies_files(&dir) {
        let ies = load_ies(&f).unwrap_or_else(|e| panic!("{e}"));
        let table = ies.table().unwrap();
        let nv = ies.vertical_angles.len();
        let peak = table.max_intensity();
        // At the measured angles the table gives the measured candela.
        for (hi, &phi) in ies.horizontal_angles.iter().enumerate() {
            for (vi, &theta) in ies.vertical_angles.iter().enumerate() {
                let want = ies.candela[hi * nv + vi] as f32;
                let got = table.intensity(direction(theta, phi));
                // Off-grid angles (ies_light_1.ies) are resampled to 0.25°: allow 2% of
                // the peak there, 1e-4 of the peak (f32 round-off) elsewhere.
                let tol = if table.resolution().0 == 720 {
                    0.02
                } else {
                    1e-4
                } * peak;
                assert!(
                    (got - want).abs() <= tol,
                    "{}: θ {theta} φ {phi}: {got} vs {want}",
                    f.display()
                );
            }
        }
        // Mirrored directions give the same intensity.
        let sym = ies.symmetry();
        for _ in 0..2000 {
            let theta = 180.0 * rng.uniform_f32() as f64;
            let phi = 360.0 * rng.uniform_f32() as f64;
            let i = table.intensity(direction(theta, phi));
            let mirrors: Vec<f64> = match sym {
                HorizontalSymmetry::Rotational => vec![360.0 * rng.uniform_f32() as f64],
                HorizontalSymmetry::Quadrant => vec![180.0 - phi, 180.0 + phi, 360.0 - phi],
                HorizontalSymmetry::BilateralC0 => vec![360.0 - phi],
                HorizontalSymmetry::BilateralC90 => vec![180.0 - phi],
                HorizontalSymmetry::None => vec![],
            };
            for m in mirrors {
                let j = table.intensity(direction(theta, m));
                assert!(
                    (i - j).abs() <= 1e-4 * peak,
                    "{}: φ {phi} vs {m}: {i} vs {j}",
                    f.display()
                );
            }
        }
    }
}

fn direction(theta_deg: f64, phi_deg: f64) -> glam::Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    glam::Vec3::new(
        (t.sin() * p.cos()) as f32,
        (t.sin() * p.sin()) as f32,
        t.cos() as f32,
    )
}

#[test]
fn polar_plot_draws_both_planes_within_the_peak_ring() {
    let Some(dir) = data_dir() else { return };
    for f in ies_files(&dir) {
        let ies = load_ies(&f).unwrap_or_else(|e| panic!("{e}"));
        let img = candela_scene::ies::polar_plot(&ies, 256).unwrap();
        assert_eq!(img.dimensions(), (256, 256));
        let (c, r) = (128.0f64, 0.45 * 256.0);
        let mut coloured = [0usize; 2];
        for (x, y, p) in img.enumerate_pixels() {
            let k = match p.0 {
                [210, 30, 30] => 0,
                [30, 60, 210] => 1,
                _ => continue,
            };
            coloured[k] += 1;
            // Curves are scaled to the peak: nothing outside the 100% ring (+2 px pen).
            let d = ((x as f64 + 0.5 - c).powi(2) + (y as f64 + 0.5 - c).powi(2)).sqrt();
            assert!(d <= r + 2.5, "{}: pixel at distance {d}", f.display());
        }
        assert!(
            coloured[0] > 50 || coloured[1] > 50,
            "{}: {coloured:?}",
            f.display()
        );
    }
}
