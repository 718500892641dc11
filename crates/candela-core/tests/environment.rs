//! Environment light sampling: chi-square of samples against the solid-angle pdf for a
//! synthetic sun-and-sky panorama and a cube map, the pdf's integral, sample/pdf
//! consistency, the direction mapping and the cube map face table.
//!
//! The chi-square statistic is computed here with a compact local helper (the shared
//! `candela_core::chi2` harness had not landed when this was written). Bins live in each
//! map's own parameterisation, aligned with the sampler's half-texel cells, and their
//! expected counts integrate `pdf_li` (solid angle) times the mapping's Jacobian written
//! out independently here, so a wrong Jacobian or mapping inside the light shows up.

use std::f32::consts::PI;

use candela_core::light::envmap::{cubemap, equirect, Cubemap, Equirect, Image};
use candela_core::light::{EnvironmentLight, EnvironmentMap, ShadingCtx};
use glam::{Mat3, Vec2, Vec3};

/// Significance of each chi-square test (as Mitsuba's tests use).
const ALPHA: f64 = 0.01;

fn ctx() -> ShadingCtx {
    ShadingCtx {
        p: Vec3::ZERO,
        n: Vec3::ZERO,
    }
}

/// A small deterministic generator (SplitMix64) for sample streams.
struct Rng(u64);
impl Rng {
    fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 24) as f32
    }
    fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next_f32(), self.next_f32())
    }
}

fn ln_gamma(x: f64) -> f64 {
    // Lanczos approximation (Numerical Recipes §6.1), |error| < 2e-10.
    let c = [
        76.18009172947146,
        -86.50532032941677,
        24.01409824083091,
        -1.231739572450155,
        0.1208650973866179e-2,
        -0.5395239384953e-5,
    ];
    let t = x + 5.5 - (x + 0.5) * (x + 5.5).ln();
    let s = c
        .iter()
        .enumerate()
        .fold(1.000000000190015, |s, (j, c)| s + c / (x + 1.0 + j as f64));
    -t + (2.5066282746310005 * s / x).ln()
}

/// Upper regularised incomplete gamma Q(a, x) (Numerical Recipes §6.2).
fn gamma_q(a: f64, x: f64) -> f64 {
    if x < a + 1.0 {
        let (mut sum, mut del, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-14 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - ln_gamma(a)).exp()
    } else {
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
            if (del - 1.0).abs() < 1e-14 {
                break;
            }
        }
        (-x + a * x.ln() - ln_gamma(a)).exp() * h
    }
}

/// Pearson's chi-square of observed counts against expected ones; bins expecting fewer
/// than 5 are pooled. Returns (statistic, degrees of freedom, p-value).
fn chi_square(observed: &[f64], expected: &[f64]) -> (f64, usize, f64) {
    let (mut stat, mut dof) = (0.0, 0usize);
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            stat += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pool_e > 0.0 {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e.max(1e-9);
        dof += 1;
    }
    let dof = dof - 1;
    (stat, dof, gamma_q(dof as f64 / 2.0, stat / 2.0))
}

/// A 1° sun of 10⁴ times the sky's radiance, over a sky that brightens towards the
/// zenith, as a `w × h` panorama (each texel the sun's coverage of 4×4 sub-points).
fn sun_and_sky(w: usize, h: usize, sun_dir: Vec3) -> Image {
    let cos_sun = (0.5f32.to_radians()).cos();
    let mut pixels = Vec::with_capacity(w * h);
    for j in 0..h {
        for i in 0..w {
            let mut cover = 0.0;
            for k in 0..16 {
                let uv = Vec2::new(
                    (i as f32 + (k % 4) as f32 / 4.0 + 0.125) / w as f32,
                    (j as f32 + (k / 4) as f32 / 4.0 + 0.125) / h as f32,
                );
                if equirect::uv_to_direction(uv).dot(sun_dir) > cos_sun {
                    cover += 1.0 / 16.0;
                }
            }
            let d = equirect::uv_to_direction(Vec2::new(
                (i as f32 + 0.5) / w as f32,
                (j as f32 + 0.5) / h as f32,
            ));
            let sky = Vec3::new(0.3, 0.5, 1.0) * (0.5 + 0.5 * d.y.max(0.0));
            pixels.push(sky + Vec3::splat(1e4) * cover);
        }
    }
    Image {
        width: w,
        height: h,
        pixels,
    }
}

fn light(map: EnvironmentMap) -> EnvironmentLight {
    EnvironmentLight::new(map, 1.0, Mat3::IDENTITY, 1.0)
}

/// Chi-square test of an equirect light in (u, v) bins of `cells × cells` half-texels.
fn chi_square_equirect(light: &EnvironmentLight, w: usize, h: usize, cells: usize, n: usize) {
    let (bw, bh) = (2 * w / cells, 2 * h / cells);
    let mut expected = vec![0.0f64; bw * bh];
    // One point per half-texel cell: the sampler's density in (u, v) is constant there.
    for qy in 0..2 * h {
        let v = (qy as f32 + 0.5) / (2 * h) as f32;
        let jac = 2.0 * PI * PI * (PI * v).sin() / (4 * w * h) as f32;
        for qx in 0..2 * w {
            let u = (qx as f32 + 0.5) / (2 * w) as f32;
            let p = light.pdf_li(&ctx(), equirect::uv_to_direction(Vec2::new(u, v)));
            expected[(qy / cells) * bw + qx / cells] += (p * jac) as f64;
        }
    }
    let total: f64 = expected.iter().sum();
    assert!((total - 1.0).abs() < 1e-3, "pdf integrates to {total}");
    let mut observed = vec![0.0f64; bw * bh];
    let mut rng = Rng(7);
    for _ in 0..n {
        let s = light.sample_li(&ctx(), rng.next_2d()).expect("sample");
        let d = s.wi;
        // The native mapping, written out independently of the light's code.
        let u = 0.5 * (1.0 + d.x.atan2(-d.z) / PI);
        let v = d.y.clamp(-1.0, 1.0).acos() / PI;
        let bx = ((u * bw as f32) as usize).min(bw - 1);
        let by = ((v * bh as f32) as usize).min(bh - 1);
        observed[by * bw + bx] += 1.0;
    }
    let expected: Vec<f64> = expected.iter().map(|e| e * n as f64).collect();
    let (stat, dof, p) = chi_square(&observed, &expected);
    println!("equirect chi-square {stat:.1} on {dof} dof, p = {p:.4}");
    assert!(p > ALPHA, "chi-square {stat} on {dof} dof, p = {p}");
}

#[test]
fn sun_and_sky_sampling_matches_pdf_chi_square() {
    let sun = Vec3::new(0.4, 0.5, -0.6).normalize();
    let (w, h) = (720, 360); // 0.5° texels: the sun spans about two
    let l = light(EnvironmentMap::Equirect(Equirect::new(sun_and_sky(
        w, h, sun,
    ))));
    chi_square_equirect(&l, w, h, 16, 1_000_000);
}

#[test]
fn sun_carries_most_samples() {
    // The sun has ~10⁴ × 2.4e-4 sr ≈ 2.4 of luminance-weighted integral against the
    // sky's ≈ 2.7; a sampler proportional to radiance sends a matching share to it.
    let sun = Vec3::new(0.0, 0.8, -0.6).normalize();
    let l = light(EnvironmentMap::Equirect(Equirect::new(sun_and_sky(
        720, 360, sun,
    ))));
    let mut rng = Rng(3);
    let n = 20_000;
    let near = (0..n)
        .filter(|_| {
            l.sample_li(&ctx(), rng.next_2d()).unwrap().wi.dot(sun) > 2f32.to_radians().cos()
        })
        .count();
    assert!(
        near as f32 / n as f32 > 0.3,
        "{near} of {n} samples near the sun"
    );
}

fn coloured_cube(n: usize) -> Box<[Image; 6]> {
    // Distinct content per face, varying across it, with one dark face.
    Box::new(std::array::from_fn(|f| {
        let pixels = (0..n * n)
            .map(|k| {
                let (x, y) = ((k % n) as f32 / n as f32, (k / n) as f32 / n as f32);
                let base = [0.2, 1.0, 4.0, 0.0, 0.5, 2.0][f];
                base * Vec3::new(0.2 + x, 0.3 + y, 0.5 + 0.1 * x * y)
            })
            .collect();
        Image {
            width: n,
            height: n,
            pixels,
        }
    }))
}

#[test]
fn cubemap_sampling_matches_pdf_chi_square() {
    let n = 32;
    let l = light(EnvironmentMap::Cubemap(Cubemap::new(coloured_cube(n))));
    let cells = 8; // bins of 8×8 half-texels: 8×8 bins per face
    let b = 2 * n / cells;
    let mut expected = vec![0.0f64; 6 * b * b];
    for f in 0..6 {
        for qy in 0..2 * n {
            for qx in 0..2 * n {
                let st = Vec2::new(
                    (qx as f32 + 0.5) / (2 * n) as f32,
                    (qy as f32 + 0.5) / (2 * n) as f32,
                );
                let (a, bb) = (2.0 * st.x - 1.0, 2.0 * st.y - 1.0);
                let jac = 4.0 * (1.0 + a * a + bb * bb).powf(-1.5) / (4 * n * n) as f32;
                let p = l.pdf_li(&ctx(), cubemap::face_to_direction(f, st));
                expected[f * b * b + (qy / cells) * b + qx / cells] += (p * jac) as f64;
            }
        }
    }
    let total: f64 = expected.iter().sum();
    assert!((total - 1.0).abs() < 1e-3, "pdf integrates to {total}");
    let samples = 500_000;
    let mut observed = vec![0.0f64; 6 * b * b];
    let mut rng = Rng(11);
    for _ in 0..samples {
        let s = l.sample_li(&ctx(), rng.next_2d()).unwrap();
        let (f, st) = cubemap::direction_to_face(s.wi);
        let bx = ((st.x * b as f32) as usize).min(b - 1);
        let by = ((st.y * b as f32) as usize).min(b - 1);
        observed[f * b * b + by * b + bx] += 1.0;
    }
    // The dark face (−y) is never sampled and expects nothing.
    assert_eq!(observed[3 * b * b..4 * b * b].iter().sum::<f64>(), 0.0);
    let expected: Vec<f64> = expected.iter().map(|e| e * samples as f64).collect();
    let (stat, dof, p) = chi_square(&observed, &expected);
    println!("cubemap chi-square {stat:.1} on {dof} dof, p = {p:.4}");
    assert!(p > ALPHA, "chi-square {stat} on {dof} dof, p = {p}");
}

#[test]
fn pdf_integrates_to_one_on_a_fine_unaligned_grid() {
    // Midpoint rule on a grid unrelated to the maps' cells; the sun map is
    // left out (its pdf is too peaked for a 1000×500 grid). Tolerance 2e-3: the
    // quadrature error of step functions on a grid of this size.
    let maps = [
        light(EnvironmentMap::Constant(Vec3::ONE)),
        light(EnvironmentMap::Cubemap(Cubemap::new(coloured_cube(16)))),
        light(EnvironmentMap::Equirect(Equirect::new(Image {
            width: 8,
            height: 4,
            pixels: (0..32).map(|k| Vec3::splat((k * 7 % 5) as f32)).collect(),
        }))),
    ];
    for l in &maps {
        // Midpoint rule in (θ, φ) with dω = sin θ dθ dφ: the integrand pdf · sin θ stays
        // bounded at the poles, where the equirect pdf grows as 1/sin θ.
        let (nt, np) = (500, 1000);
        let mut sum = 0.0f64;
        for i in 0..nt {
            let theta = PI * (i as f32 + 0.5) / nt as f32;
            let (st, ct) = theta.sin_cos();
            for j in 0..np {
                let phi = 2.0 * PI * (j as f32 + 0.5) / np as f32;
                let d = Vec3::new(st * phi.cos(), ct, st * phi.sin());
                sum += (l.pdf_li(&ctx(), d) * st) as f64;
            }
        }
        let pi = std::f64::consts::PI;
        let integral = sum * pi * 2.0 * pi / (nt * np) as f64;
        assert!((integral - 1.0).abs() < 2e-3, "∫ pdf dω = {integral}");
    }
}

#[test]
fn sample_reports_the_pdf_and_radiance_of_its_direction() {
    let sun = Vec3::new(-0.3, 0.2, 0.9).normalize();
    let rot = Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(0.2);
    let maps = [
        EnvironmentMap::Equirect(Equirect::new(sun_and_sky(360, 180, sun))),
        EnvironmentMap::Cubemap(Cubemap::new(coloured_cube(16))),
    ];
    for map in maps {
        let l = EnvironmentLight::new(map, 2.0, rot, 1.0);
        let mut rng = Rng(5);
        let n = 20_000;
        // A sample within float rounding of a cell border may land in the neighbouring
        // cell on the way back; allow 0.1% of such mismatches.
        let mut mismatches = 0;
        for _ in 0..n {
            let s = l.sample_li(&ctx(), rng.next_2d()).unwrap();
            assert!((s.wi.length() - 1.0).abs() < 1e-5);
            assert_eq!(s.distance, f32::INFINITY);
            let p = l.pdf_li(&ctx(), s.wi);
            if (p - s.pdf).abs() > 1e-3 * s.pdf {
                mismatches += 1;
            }
            assert!(
                (s.radiance - l.eval(s.wi)).abs().max_element() <= 1e-5 * s.radiance.max_element()
            );
        }
        assert!(mismatches <= n / 1000, "{mismatches} pdf mismatches");
    }
}

#[test]
fn marked_texel_lights_the_predicted_direction() {
    let (w, h) = (64, 32);
    let (mi, mj) = (40, 10);
    let mut pixels = vec![Vec3::ZERO; w * h];
    pixels[mj * w + mi] = Vec3::new(1.0, 2.0, 3.0);
    let img = Image {
        width: w,
        height: h,
        pixels,
    };
    // Predicted by the documented formula: u = (1 + atan2(x, −z)/π)/2, v = acos(y)/π.
    let (u, v) = ((mi as f32 + 0.5) / w as f32, (mj as f32 + 0.5) / h as f32);
    let (phi, theta) = (PI * (2.0 * u - 1.0), PI * v);
    let d = Vec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    );
    for rot_deg in [0.0f32, 90.0] {
        let rot = Mat3::from_rotation_y(rot_deg.to_radians());
        let l = EnvironmentLight::new(
            EnvironmentMap::Equirect(Equirect::new(img.clone())),
            1.0,
            rot,
            1.0,
        );
        let world = rot * d;
        assert!(
            (l.eval(world) - Vec3::new(1.0, 2.0, 3.0))
                .abs()
                .max_element()
                < 1e-4
        );
        // The unrotated direction is dark once the map is turned.
        if rot_deg != 0.0 {
            assert_eq!(l.eval(d), Vec3::ZERO);
        }
        // Every sample comes from within the texel's bilinear footprint (< 2 texels).
        let mut rng = Rng(1);
        for _ in 0..1000 {
            let s = l.sample_li(&ctx(), rng.next_2d()).unwrap();
            let angle = s.wi.dot(world).clamp(-1.0, 1.0).acos();
            assert!(angle < 2.0 * PI / w as f32 * 2.0, "sample {angle} rad away");
        }
    }
}

#[test]
fn cube_faces_show_their_colours_along_the_axes() {
    let colours = [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
    ];
    let n = 4;
    let mut faces: [Image; 6] = std::array::from_fn(|f| Image {
        width: n,
        height: n,
        pixels: vec![colours[f]; n * n],
    });
    // Mark the top-left texel of +x: by the table (sc = −z, tc = −y) it looks towards
    // +y and +z.
    faces[0].pixels[0] = Vec3::splat(9.0);
    let l = light(EnvironmentMap::Cubemap(Cubemap::new(Box::new(faces))));
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for (axis, c) in axes.iter().zip(colours) {
        assert_eq!(l.eval(*axis), c, "face towards {axis}");
        // Off-centre but on the same face.
        let off = (*axis + 0.3 * axis.any_orthonormal_vector()).normalize();
        assert_eq!(l.eval(off), c);
    }
    let corner = Vec3::new(1.0, 0.75, 0.75).normalize(); // texel centre (0.5, 0.5)/4
    assert_eq!(l.eval(corner), Vec3::splat(9.0));
    assert_eq!(l.eval(Vec3::new(1.0, -0.75, 0.75).normalize()), colours[0]);
}
