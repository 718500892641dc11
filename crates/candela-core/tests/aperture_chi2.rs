//! Chi-square tests of aperture sampling: disc, regular n-gons (n = 3, 5, 6, 8) and an
//! image mask. Samples are binned on a grid over the aperture's square; the expected count
//! of a cell is N · (area of cell ∩ aperture) / (aperture area), computed exactly by
//! clipping the cell against the (convex) aperture polygon — independent of the sampler's
//! own `pdf`. Cells expecting fewer than 5 samples are pooled, as usual for Pearson's
//! test. Each test rejects at α = 0.01/6 (Šidák-style correction over the six tests of
//! this file, as Mitsuba's chi-square harness does), so a correct sampler fails this file
//! with probability ≈ 1%; with fixed seeds the outcome is deterministic.

mod common;

use std::f64::consts::TAU;

use candela_core::camera::Aperture;
use candela_core::desc::ApertureDesc;
use candela_core::sampler::Pcg32;
use glam::{DVec2, Vec2};

const N: usize = 1_000_000;
const GRID: usize = 48;
const ALPHA: f64 = 0.01 / 6.0;

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

/// Pearson's statistic with pooling of small cells; returns (χ², dof, p).
fn pearson(observed: &[f64], expected: &[f64]) -> (f64, f64, f64) {
    let (mut chi2, mut cells) = (0.0, 0usize);
    let (mut pooled_o, mut pooled_e) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < 5.0 {
            pooled_o += o;
            pooled_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pooled_e > 0.0 {
        chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        cells += 1;
    }
    let dof = cells as f64 - 1.0;
    (chi2, dof, common::chi2_sf(chi2, dof))
}

fn samples(aperture: &Aperture, seed: u64) -> impl Iterator<Item = Vec2> + '_ {
    let mut rng = Pcg32::new(seed, 1);
    (0..N).map(move |_| {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        aperture.sample(u)
    })
}

/// Bins samples on the GRID×GRID grid over [-1,1]² and tests them against `shape`.
fn check_convex(name: &str, aperture: &Aperture, shape: &[DVec2], seed: u64) {
    let area = shoelace(shape);
    let cell = 2.0 / GRID as f64;
    let mut expected = vec![0.0; GRID * GRID];
    for j in 0..GRID {
        for i in 0..GRID {
            let lo = DVec2::new(-1.0 + i as f64 * cell, -1.0 + j as f64 * cell);
            expected[j * GRID + i] =
                N as f64 * clipped_area(shape, lo, lo + DVec2::splat(cell)) / area;
        }
    }
    let mut observed = vec![0.0; GRID * GRID];
    for p in samples(aperture, seed) {
        assert!(p.is_finite() && p.abs().max_element() <= 1.0, "{name}: {p}");
        let ij = ((p + Vec2::ONE) / cell as f32)
            .as_uvec2()
            .min(glam::UVec2::splat(GRID as u32 - 1));
        observed[ij.y as usize * GRID + ij.x as usize] += 1.0;
        // The sampler's own density agrees with the shape's area.
        let pdf = aperture.pdf(p);
        assert!(
            pdf == 0.0 || (pdf as f64 * area - 1.0).abs() < 1e-4,
            "{name}: pdf {pdf}"
        );
    }
    let (chi2, dof, p) = pearson(&observed, &expected);
    println!("{name}: chi2 = {chi2:.1}, dof = {dof}, p = {p:.4}");
    assert!(
        p > ALPHA,
        "{name}: chi2 = {chi2:.1} with {dof} dof, p = {p:.2e} < {ALPHA:.2e}"
    );
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
    let total: f64 = lum.iter().map(|&v| v as f64).sum();
    // The longer side (12 px) spans the diameter: the mask covers [-1,1]×[-2/3,2/3].
    let half = DVec2::new(1.0, h as f64 / w as f64);
    let mut observed = vec![0.0; w * h];
    for p in samples(&aperture, 31) {
        let p = p.as_dvec2();
        assert!(p.x.abs() <= half.x && p.y.abs() <= half.y, "{p}");
        let col = (((p.x / half.x + 1.0) * 0.5 * w as f64) as usize).min(w - 1);
        let row = (((1.0 - p.y / half.y) * 0.5 * h as f64) as usize).min(h - 1);
        let k = row * w + col;
        assert!(lum[k] > 0.0, "sample {p} in black pixel ({col}, {row})");
        observed[k] += 1.0;
        // Density per lens area: luminance share over the pixel's area.
        let pixel_area = 4.0 * half.x * half.y / (w * h) as f64;
        let want = lum[k] as f64 / total / pixel_area;
        assert!((aperture.pdf(p.as_vec2()) as f64 / want - 1.0).abs() < 1e-4);
    }
    let expected: Vec<f64> = lum.iter().map(|&v| N as f64 * v as f64 / total).collect();
    let lit: Vec<usize> = (0..w * h).filter(|&k| lum[k] > 0.0).collect();
    let o: Vec<f64> = lit.iter().map(|&k| observed[k]).collect();
    let e: Vec<f64> = lit.iter().map(|&k| expected[k]).collect();
    let (chi2, dof, p) = pearson(&o, &e);
    println!("image: chi2 = {chi2:.1}, dof = {dof}, p = {p:.4}");
    assert!(
        p > ALPHA,
        "image: chi2 = {chi2:.1} with {dof} dof, p = {p:.2e}"
    );
}

#[test]
fn the_test_rejects_a_biased_sampler() {
    // A disc sampled with r = u (not √u) crowds the centre: the test must catch it.
    let circle = regular_polygon(4096, 0.0);
    let cell = 2.0 / GRID as f64;
    let mut expected = vec![0.0; GRID * GRID];
    for j in 0..GRID {
        for i in 0..GRID {
            let lo = DVec2::new(-1.0 + i as f64 * cell, -1.0 + j as f64 * cell);
            expected[j * GRID + i] =
                N as f64 * clipped_area(&circle, lo, lo + DVec2::splat(cell)) / shoelace(&circle);
        }
    }
    let mut rng = Pcg32::new(5, 1);
    let mut observed = vec![0.0; GRID * GRID];
    for _ in 0..N {
        let (r, phi) = (rng.uniform_f32() as f64, TAU * rng.uniform_f32() as f64);
        let p = DVec2::new(r * phi.cos(), r * phi.sin());
        let ij = ((p + DVec2::ONE) / cell)
            .as_uvec2()
            .min(glam::UVec2::splat(GRID as u32 - 1));
        observed[ij.y as usize * GRID + ij.x as usize] += 1.0;
    }
    let (_, _, p) = pearson(&observed, &expected);
    assert!(p < ALPHA, "a biased sampler passed: p = {p}");
}
