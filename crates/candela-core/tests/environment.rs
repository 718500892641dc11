//! Environment light sampling: chi-square of samples against the solid-angle pdf for a
//! synthetic sun-and-sky panorama and a cube map, the pdf's integral, sample/pdf
//! consistency, the direction mapping and the cube map face table.
//!
//! Chi-square tests use `candela_core::chi2` on the sphere (cells in φ and cos θ about
//! the z axis, unrelated to the maps' own grids) or, for the bilinear density itself, on
//! the unit square, 10⁶ samples each, at a suite-wide significance of 0.01 split over the
//! five tests by Šidák's correction. Three of them have histogram cells much finer than
//! the texels, so that the density's shape within a texel is tested, not only its mass.

use std::f32::consts::PI;

use candela_core::chi2::{sidak_alpha, ChiSquareTest};
use candela_core::light::envmap::bilinear::{Bilinear2D, GridAxis};
use candela_core::light::envmap::{cubemap, equirect, Cubemap, Equirect, Image};
use candela_core::light::{EnvironmentLight, EnvironmentMap, LightSource, ShadingCtx};
use glam::{Mat3, Vec2, Vec3};

/// Chi-square tests in this file, for the Šidák correction.
const CHI2_TESTS: usize = 5;

fn chi2_test() -> ChiSquareTest {
    ChiSquareTest {
        alpha: sidak_alpha(0.01, CHI2_TESTS),
        ..Default::default()
    }
}

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

#[test]
fn sun_and_sky_sampling_matches_pdf_chi_square() {
    let sun = Vec3::new(0.4, 0.5, -0.6).normalize();
    let (w, h) = (720, 360); // 0.5° texels: the sun spans about two
    let l = light(EnvironmentMap::Equirect(Equirect::new(sun_and_sky(
        w, h, sun,
    ))));
    let report = chi2_test().spherical(
        "sun and sky",
        |u| l.sample_li(&ctx(), u).map(|s| s.wi),
        |d| l.pdf_li(&ctx(), d),
    );
    println!("{report}");
    report.assert_passed();
}

#[test]
fn bilinear_density_matches_its_samples_chi_square() {
    // 6 × 6 vertices (5 even columns; 4 texel rows and the two edges), zeros included, so
    // that cells with one, two and four positive corners all occur; 32 × 32 histogram
    // cells, six or more per grid cell along each axis.
    let values: Vec<f32> = (0..36)
        .map(|i| [0.0, 1.0, 4.0, 0.5, 0.0, 2.5, 9.0][i * 5 % 7])
        .collect();
    let d = Bilinear2D::new(values, GridAxis::Even(5), GridAxis::Centred(4));
    let report = chi2_test().planar(
        "bilinear 6×6",
        Vec2::ZERO,
        Vec2::ONE,
        |u| d.sample(u).map(|(p, _)| p),
        |p| d.pdf(p),
    );
    println!("{report}");
    report.assert_passed();
}

#[test]
fn coarse_panorama_sampling_matches_pdf_chi_square() {
    // An 8 × 4 panorama: each texel spans 8 × 8 of the 64 × 32 histogram cells (in φ and
    // cos θ), so that the bilinear shape within texels, the wrap in u and the half-rows
    // at the poles are tested; a bright texel makes the mean subtraction bite.
    let pixels = (0..32)
        .map(|k| {
            let v = [0.2, 1.0, 0.0, 3.0, 0.5][k % 5];
            Vec3::new(v, 0.5 * v + 0.1 * (k / 8) as f32, 1.0)
        })
        .enumerate()
        .map(|(k, l)| if k == 13 { l * 40.0 } else { l })
        .collect();
    let l = light(EnvironmentMap::Equirect(Equirect::new(Image {
        width: 8,
        height: 4,
        pixels,
    })));
    let report = chi2_test().spherical(
        "panorama 8×4",
        |u| l.sample_li(&ctx(), u).map(|s| s.wi),
        |d| l.pdf_li(&ctx(), d),
    );
    println!("{report}");
    report.assert_passed();
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
    let l = light(EnvironmentMap::Cubemap(Cubemap::new(coloured_cube(32))));
    let report = chi2_test().spherical(
        "cube map",
        |u| l.sample_li(&ctx(), u).map(|s| s.wi),
        |d| l.pdf_li(&ctx(), d),
    );
    println!("{report}");
    report.assert_passed();
    // The dark face (−y) is never sampled.
    let mut rng = Rng(11);
    for _ in 0..100_000 {
        let s = l.sample_li(&ctx(), rng.next_2d()).unwrap();
        assert_ne!(cubemap::direction_to_face(s.wi).0, 3, "{}", s.wi);
    }
}

#[test]
fn coarse_cube_map_sampling_matches_pdf_chi_square() {
    // Faces of 3 × 3 texels, a bright one among them: each texel spans about ten of the
    // 64 × 32 histogram cells across, so the bilinear shape within texels and the
    // half-texels at the faces' edges are tested.
    let mut faces = coloured_cube(3);
    faces[4].pixels[5] *= 30.0;
    let l = light(EnvironmentMap::Cubemap(Cubemap::new(faces)));
    let report = chi2_test().spherical(
        "cube map 3×3",
        |u| l.sample_li(&ctx(), u).map(|s| s.wi),
        |d| l.pdf_li(&ctx(), d),
    );
    println!("{report}");
    report.assert_passed();
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
    // Each map with its brightest radiance (strength 2 included).
    let maps = [
        (
            EnvironmentMap::Equirect(Equirect::new(sun_and_sky(360, 180, sun))),
            2e4,
        ),
        (
            EnvironmentMap::Cubemap(Cubemap::new(coloured_cube(16))),
            2.0 * 4.0 * 1.3,
        ),
    ];
    for (map, brightest) in maps {
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
            // The radiance is looked up where the sample was drawn, not at the (u, v) the
            // direction maps back to: the rotation there and back and atan2/acos move it
            // by a few ulps of u (~6e-8, 2e-5 of one of 360 texels). Across the sun's rim
            // (its 2·10⁴ falling to the sky's ~1 within a texel) that changes the
            // radiance by up to ~2e-5 of the sun's, so the bound is 1e-4 of the brightest.
            let e = (s.radiance - l.eval(s.wi)).abs().max_element();
            assert!(e <= 1e-4 * brightest, "{e} {} {}", s.radiance, s.wi);
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
