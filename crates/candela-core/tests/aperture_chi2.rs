//! Chi-square tests of aperture sampling: disc, regular n-gons (n = 3, 5, 6, 8) and an
//! image mask, two ways:
//!
//! - with `candela_core::chi2`'s planar harness, samples against the aperture's own `pdf`
//!   (which must also integrate to one);
//! - against the geometry itself: on a grid over [-1,1]², the probability of a cell is
//!   (area of cell ∩ aperture) / (aperture area), computed exactly by clipping the cell
//!   against the convex aperture polygon, independent of the sampler's `pdf`; the counts
//!   go through `chi2::discrete`.
//!
//! 10⁶ samples per test and fixed seeds; the file's family-wise significance is 0.01,
//! split over its 11 chi-square tests by the Šidák correction, so a correct sampler fails
//! this file with probability ≈ 1% (deterministically, given the seeds).

use std::f64::consts::TAU;

use candela_core::camera::Aperture;
use candela_core::chi2::{discrete, sidak_alpha, ChiSquareTest};
use candela_core::desc::ApertureDesc;
use candela_core::sampler::Pcg32;
use glam::{DVec2, Vec2};

const N: usize = 1_000_000;
const GRID: usize = 48;
/// Chi-square tests in this file, for the Šidák correction.
const TESTS: usize = 11;

fn alpha() -> f64 {
    sidak_alpha(0.01, TESTS)
}

fn harness(seed: u64) -> ChiSquareTest {
    ChiSquareTest {
        alpha: alpha(),
        seed,
        ..Default::default()
    }
}

/// Sutherland–Hodgman clip of a convex polygon to an axis-aligned box, then its area.
fn clipped_area(poly: &[DVec2], lo: DVec2, hi: DVec2) -> f64 {
    let mut pts = poly.to_vec();
    // Each half-plane as (axis, bound, keep-below).
    for (axis, bound, below) in [
        (0, lo.x, false),
        (0, hi.x, true),
        (1, lo.y, false),
        (1, hi.y, true),
    ] {
        let inside = |p: DVec2| {
            let v = if axis == 0 { p.x } else { p.y };
            if below {
                v <= bound
            } else {
                v >= bound
            }
        };
        let mut out = Vec::with_capacity(pts.len() + 4);
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            let (ia, ib) = (inside(a), inside(b));
            if ia {
                out.push(a);
            }
            if ia != ib {
                let (va, vb) = if axis == 0 { (a.x, b.x) } else { (a.y, b.y) };
                out.push(a + (b - a) * ((bound - va) / (vb - va)));
            }
        }
        pts = out;
        if pts.is_empty() {
            return 0.0;
        }
    }
    shoelace(&pts)
}

fn shoelace(pts: &[DVec2]) -> f64 {
    let n = pts.len();
    0.5 * (0..n)
        .map(|i| pts[i].perp_dot(pts[(i + 1) % n]))
        .sum::<f64>()
}

fn regular_polygon(n: usize, rotation: f64) -> Vec<DVec2> {
    (0..n)
        .map(|k| {
            let phi = std::f64::consts::FRAC_PI_2 + rotation + TAU * k as f64 / n as f64;
            DVec2::new(phi.cos(), phi.sin())
        })
        .collect()
}

fn samples(aperture: &Aperture, seed: u64) -> impl Iterator<Item = Vec2> + '_ {
    let mut rng = Pcg32::new(seed, 1);
    (0..N).map(move |_| {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        aperture.sample(u)
    })
}

/// Tests an aperture against the convex polygon `shape` it should fill uniformly: with
/// the harness (against its own pdf) and against the exact cell areas of the shape.
fn check_convex(name: &str, aperture: &Aperture, shape: &[DVec2], seed: u64) {
    let report = harness(seed).planar(
        name,
        Vec2::splat(-1.0),
        Vec2::ONE,
        |u| Some(aperture.sample(u)),
        |p| aperture.pdf(p),
    );
    println!(
        "{name}: harness χ² = {:.1}, dof = {}, p = {:.3}, ∫pdf = {:.5}",
        report.statistic, report.dof, report.p_value, report.pdf_integral
    );
    report.assert_passed();

    let area = shoelace(shape);
    let cell = 2.0 / GRID as f64;
    let mut pmf = vec![0.0; GRID * GRID];
    for j in 0..GRID {
        for i in 0..GRID {
            let lo = DVec2::new(-1.0 + i as f64 * cell, -1.0 + j as f64 * cell);
            pmf[j * GRID + i] = clipped_area(shape, lo, lo + DVec2::splat(cell)) / area;
        }
    }
    let mut counts = vec![0u64; GRID * GRID];
    for p in samples(aperture, seed + 1000) {
        assert!(p.is_finite() && p.abs().max_element() <= 1.0, "{name}: {p}");
        let ij = ((p + Vec2::ONE) / cell as f32)
            .as_uvec2()
            .min(glam::UVec2::splat(GRID as u32 - 1));
        counts[ij.y as usize * GRID + ij.x as usize] += 1;
    }
    let report = discrete(&format!("{name} vs exact areas"), &counts, &pmf, alpha());
    println!(
        "{name}: exact-area χ² = {:.1}, dof = {}, p = {:.3}",
        report.statistic, report.dof, report.p_value
    );
    report.assert_passed();
}

#[test]
fn disc_aperture_is_uniform() {
    // The disc as a 4096-gon: its area and cell areas differ from the circle's by < 1e-6.
    let circle = regular_polygon(4096, 0.0);
    check_convex("disc", &Aperture::new(&ApertureDesc::Disc), &circle, 11);
}

#[test]
fn polygon_apertures_are_uniform() {
    for (n, rotation_deg, seed) in [
        (3u32, 0.0f32, 21u64),
        (5, 15.0, 22),
        (6, 0.0, 23),
        (8, 7.5, 24),
    ] {
        let desc = ApertureDesc::Polygon {
            blades: n,
            rotation_deg,
        };
        let shape = regular_polygon(n as usize, (rotation_deg as f64).to_radians());
        check_convex(&format!("{n}-gon"), &Aperture::new(&desc), &shape, seed);
    }
}

#[test]
fn image_aperture_follows_luminance() {
    // A 12×8 mask (wider than tall) with black pixels and a range of luminances.
    let (w, h) = (12usize, 8usize);
    let lum: Vec<f32> = (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            [0.0, 0.5, 1.0, 2.0, 4.0][(x * 7 + y * 3) % 5]
        })
        .collect();
    let desc = ApertureDesc::Image {
        width: w as u32,
        height: h as u32,
        luminance: lum.clone(),
    };
    let aperture = Aperture::new(&desc);
    // The longer side (12 px) spans the diameter: the mask covers [-1,1]×[-2/3,2/3].
    let half = DVec2::new(1.0, h as f64 / w as f64);
    // 24 cells a side: two cells per image column, three per row, so no cell straddles
    // a pixel edge.
    let report = ChiSquareTest {
        res: 24,
        ..harness(31)
    }
    .planar(
        "image",
        -half.as_vec2(),
        half.as_vec2(),
        |u| Some(aperture.sample(u)),
        |p| aperture.pdf(p),
    );
    println!(
        "image: harness χ² = {:.1}, dof = {}, p = {:.3}, ∫pdf = {:.5}",
        report.statistic, report.dof, report.p_value, report.pdf_integral
    );
    report.assert_passed();

    // Against the luminances themselves: one outcome per image pixel.
    let total: f64 = lum.iter().map(|&v| v as f64).sum();
    let pmf: Vec<f64> = lum.iter().map(|&v| v as f64 / total).collect();
    let mut counts = vec![0u64; w * h];
    for p in samples(&aperture, 32) {
        let p = p.as_dvec2();
        assert!(p.x.abs() <= half.x && p.y.abs() <= half.y, "{p}");
        // Image rows run downwards from the top of the aperture.
        let col = (((p.x / half.x + 1.0) * 0.5 * w as f64) as usize).min(w - 1);
        let row = (((1.0 - p.y / half.y) * 0.5 * h as f64) as usize).min(h - 1);
        counts[row * w + col] += 1;
    }
    let report = discrete("image vs luminance", &counts, &pmf, alpha());
    println!(
        "image: luminance χ² = {:.1}, dof = {}, p = {:.3}",
        report.statistic, report.dof, report.p_value
    );
    report.assert_passed();
}

#[test]
fn the_test_rejects_a_biased_sampler() {
    // A disc sampled with r = u (not √u) crowds the centre: the exact-area test must
    // catch it. (Not counted in TESTS: it is meant to fail.)
    let circle = regular_polygon(4096, 0.0);
    let area = shoelace(&circle);
    let cell = 2.0 / GRID as f64;
    let mut pmf = vec![0.0; GRID * GRID];
    for j in 0..GRID {
        for i in 0..GRID {
            let lo = DVec2::new(-1.0 + i as f64 * cell, -1.0 + j as f64 * cell);
            pmf[j * GRID + i] = clipped_area(&circle, lo, lo + DVec2::splat(cell)) / area;
        }
    }
    let mut rng = Pcg32::new(5, 1);
    let mut counts = vec![0u64; GRID * GRID];
    for _ in 0..N {
        let (r, phi) = (rng.uniform_f32() as f64, TAU * rng.uniform_f32() as f64);
        let p = DVec2::new(r * phi.cos(), r * phi.sin());
        let ij = ((p + DVec2::ONE) / cell)
            .as_uvec2()
            .min(glam::UVec2::splat(GRID as u32 - 1));
        counts[ij.y as usize * GRID + ij.x as usize] += 1;
    }
    assert!(!discrete("biased disc", &counts, &pmf, alpha()).passed());
}
