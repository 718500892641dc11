//! Rendered depth of field: the bokeh of a tiny out-of-focus emitter has the aperture's
//! corners and the thin lens's circle-of-confusion size, and a scene lying in the plane of
//! focus renders as the pinhole renders it (Welch test per pixel).
use std::f32::consts::TAU;
use std::sync::atomic::AtomicBool;

use candela_core::build::build;
use candela_core::chi2::welch_p;
use candela_core::desc::*;
use candela_core::integrator::render;
use glam::{Mat4, Quat, Vec2, Vec3};

const FOV: f32 = 40.0;

fn black_material() -> MaterialDesc {
    MaterialDesc::diffuse("black", Vec3::ZERO)
}

fn shape(geometry: GeometryDesc, material: &str, le: Option<f32>, transform: Mat4) -> ShapeDesc {
    ShapeDesc::new(geometry, material)
        .transformed(transform)
        .with_emission(le.map(Vec3::splat))
}

fn camera(lens: Option<LensDesc>) -> CameraDesc {
    CameraDesc {
        position: Vec3::ZERO,
        look_at: Vec3::new(0.0, 0.0, -1.0),
        up: Vec3::Y,
        fov_y_deg: FOV,
        lens,
        ..Default::default()
    }
}

/// Mean luminance-like value (channel mean) of each pixel.
fn render_grey(desc: &SceneDesc, samples: std::ops::Range<u32>) -> Vec<f32> {
    let scene = build(desc).unwrap();
    let r = render(&scene, samples, &AtomicBool::new(false), &|_| {});
    r.film
        .resolve()
        .iter()
        .map(|c| c.element_sum() / 3.0)
        .collect()
}

/// The thin-lens circle of confusion of a point at depth `z`, as a fraction of the image
/// height (derived from the lens equation and checked in `tests/thin_lens.rs`).
fn coc_fraction(radius: f32, focus: f32, z: f32) -> f32 {
    radius * (z - focus).abs() / (z * focus * (0.5 * FOV.to_radians()).tan())
}

struct Bokeh {
    /// Pixels above half the interior level.
    area: f32,
    /// Magnitudes of the angular harmonics k = 0..=16 of the boundary's radius r(θ).
    harmonics: Vec<f32>,
    /// Phase angle (radians) of the k-th harmonic's maxima: r peaks at φ_k + 2πj/k.
    peak_angle: Vec<f32>,
}

/// Renders a tiny emitter at depth `z` on the view axis through an aperture focused at
/// `focus`, and measures its bokeh.
fn measure_bokeh(aperture: ApertureDesc, radius: f32, focus: f32, z: f32, res: u32) -> Bokeh {
    let mut desc = SceneDesc {
        render: RenderSettings {
            width: res,
            height: res,
            spp: 1024,
            max_depth: 0,
            seed: 3,
            ..Default::default()
        },
        camera: camera(Some(LensDesc {
            focus: FocusDesc::Distance(focus),
            size: ApertureSizeDesc::Radius(radius),
            aperture,
        })),
        ..Default::default()
    };
    desc.materials.push(black_material());
    // The emitter's own image is ~3 px in radius: small beside the bokeh, large enough
    // that 1024 samples per pixel see it often.
    let rho = 3.0 * 2.0 * z * (0.5 * FOV.to_radians()).tan() / res as f32;
    desc.shapes.push(shape(
        GeometryDesc::Sphere {
            center: Vec3::new(0.0, 0.0, -z),
            radius: rho,
        },
        "black",
        Some(1.0),
        Mat4::IDENTITY,
    ));
    let img = render_grey(&desc, 0..desc.render.spp);
    let n = res as i32;
    let at = |x: i32, y: i32| img[(y.clamp(0, n - 1) * n + x.clamp(0, n - 1)) as usize];
    // A 3×3 box filter: it cuts the per-pixel noise threefold and, being symmetric, keeps
    // the half-level contour of straight edges in place.
    let smooth: Vec<f32> = (0..n * n)
        .map(|k| {
            let (x, y) = (k % n, k / n);
            (-1..=1)
                .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
                .map(|(dx, dy)| at(x + dx, y + dy))
                .sum::<f32>()
                / 9.0
        })
        .collect();
    // The interior level: the mean within a quarter of the bokeh's radius of the centre.
    let c = n as f32 / 2.0;
    let inner = 0.25 * 0.5 * coc_fraction(radius, focus, z) * res as f32;
    let pix = |k: i32| Vec2::new((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
    let core: Vec<f32> = (0..n * n)
        .filter(|&k| pix(k).distance(Vec2::splat(c)) < inner)
        .map(|k| smooth[k as usize])
        .collect();
    let level = core.iter().sum::<f32>() / core.len() as f32;
    let inside: Vec<Vec2> = (0..n * n)
        .filter(|&k| smooth[k as usize] > 0.5 * level)
        .map(pix)
        .collect();
    let centroid = inside.iter().copied().sum::<Vec2>() / inside.len() as f32;
    // Radial profile: the farthest inside pixel per 5° of angle (image y points down, so
    // flip it to measure angles counter-clockwise from +x as the aperture does).
    const BINS: usize = 72;
    let mut r = [0.0f32; BINS];
    for p in &inside {
        let d = *p - centroid;
        let theta = (-d.y).atan2(d.x).rem_euclid(TAU);
        let b = ((theta / TAU * BINS as f32) as usize).min(BINS - 1);
        r[b] = r[b].max(d.length());
    }
    let (mut harmonics, mut peak_angle) = (Vec::new(), Vec::new());
    for k in 0..=16 {
        let (mut re, mut im) = (0.0f32, 0.0f32);
        for (b, &rb) in r.iter().enumerate() {
            let theta = (b as f32 + 0.5) / BINS as f32 * TAU;
            re += rb * (k as f32 * theta).cos();
            im += rb * (k as f32 * theta).sin();
        }
        harmonics.push((re * re + im * im).sqrt() / BINS as f32);
        peak_angle.push(if k == 0 { 0.0 } else { im.atan2(re) / k as f32 });
    }
    Bokeh {
        area: inside.len() as f32,
        harmonics,
        peak_angle,
    }
}

/// The strongest harmonic k ≥ 2 of the radial profile: an n-gon's radius repeats n times
/// around the circle.
fn corner_count(b: &Bokeh) -> usize {
    (2..b.harmonics.len())
        .max_by(|&i, &j| b.harmonics[i].total_cmp(&b.harmonics[j]))
        .unwrap()
}

/// Whether some corner of the measured n-gon lies within 10° of angle `theta`.
fn has_corner_near(b: &Bokeh, n: usize, theta: f32) -> bool {
    (0..n).any(|j| {
        let a = b.peak_angle[n] + TAU * j as f32 / n as f32;
        let d = (a - theta).rem_euclid(TAU);
        d.min(TAU - d) < 10f32.to_radians()
    })
}

fn polygon_area(n: usize, circumradius: f32) -> f32 {
    0.5 * n as f32 * circumradius * circumradius * (TAU / n as f32).sin()
}

/// Area tolerance: the mask's edge wanders by about a pixel's noise along a perimeter of
/// ~190 px (√190 ≈ 14 px² ≈ 0.5% of the area), the half-level contour rounds each corner
/// by ~0.05·r² for the emitter's 3 px image radius, and pixel-centre sampling of the edge
/// adds ~0.5%: 4% is several times all of them together.
const AREA_TOL: f32 = 0.04;

#[test]
fn hexagonal_bokeh_has_six_corners_and_the_predicted_area() {
    let (res, focus, z) = (104u32, 2.0f32, 8.0f32);
    let radius = 0.56; // a bokeh ~60 px across
    let aperture = ApertureDesc::Polygon {
        blades: 6,
        rotation_deg: 0.0,
    };
    let b = measure_bokeh(aperture, radius, focus, z, res);
    let d = coc_fraction(radius, focus, z) * res as f32;
    let want = polygon_area(6, 0.5 * d);
    println!(
        "hexagon: area {} px², predicted {want:.1} px²; harmonics {:?}",
        b.area, b.harmonics
    );
    assert!(
        (b.area / want - 1.0).abs() < AREA_TOL,
        "area {} vs {want}",
        b.area
    );
    assert_eq!(corner_count(&b), 6, "harmonics {:?}", b.harmonics);
    // Behind the plane of focus the bokeh is the aperture upright: a corner points up.
    assert!(has_corner_near(&b, 6, TAU / 4.0));
}

#[test]
fn pentagonal_bokeh_is_upright_behind_focus_and_inverted_in_front() {
    let (res, focus) = (104u32, 2.0f32);
    let aperture = ApertureDesc::Polygon {
        blades: 5,
        rotation_deg: 0.0,
    };
    // Behind focus (z = 8) and in front of it (z = 1.2), both ~60 px across.
    for (z, radius, corner) in [(8.0f32, 0.56f32, 90.0f32), (1.2, 0.52, 270.0)] {
        let b = measure_bokeh(aperture.clone(), radius, focus, z, res);
        let d = coc_fraction(radius, focus, z) * res as f32;
        let want = polygon_area(5, 0.5 * d);
        println!(
            "pentagon z = {z}: area {} px², predicted {want:.1} px²",
            b.area
        );
        assert!(
            (b.area / want - 1.0).abs() < AREA_TOL,
            "z = {z}: area {} vs {want}",
            b.area
        );
        assert_eq!(corner_count(&b), 5, "z = {z}: harmonics {:?}", b.harmonics);
        assert!(has_corner_near(&b, 5, corner.to_radians()), "z = {z}");
    }
}

#[test]
fn disc_bokeh_has_no_corners() {
    let (res, focus, z, radius) = (104u32, 2.0f32, 8.0f32, 0.56f32);
    let b = measure_bokeh(ApertureDesc::Disc, radius, focus, z, res);
    let d = coc_fraction(radius, focus, z) * res as f32;
    let want = std::f32::consts::PI * 0.25 * d * d;
    assert!(
        (b.area / want - 1.0).abs() < AREA_TOL,
        "area {} vs {want}",
        b.area
    );
    // A hexagon's 6th harmonic is (R − r_in)/2·… ≈ 2.5% of its mean radius; a disc's
    // profile has only pixel noise, well under 1%.
    let strongest = b.harmonics[2..].iter().copied().fold(0.0, f32::max);
    println!(
        "disc: area {} px², predicted {want:.1}; strongest harmonic {strongest:.3} of mean {:.2}",
        b.area, b.harmonics[0]
    );
    assert!(
        strongest < 0.01 * b.harmonics[0],
        "harmonics {:?}",
        b.harmonics
    );
}

/// A scene that lies in the plane z = −3: a lit diffuse backdrop and two tilted emissive
/// squares (their edges cut pixels, so pixels vary within themselves).
fn flat_scene(lens: Option<LensDesc>, seed: u64) -> SceneDesc {
    let mut desc = SceneDesc {
        render: RenderSettings {
            width: 24,
            height: 24,
            spp: 1,
            max_depth: 1,
            seed,
            ..Default::default()
        },
        camera: camera(lens),
        ..Default::default()
    };
    desc.materials.push(black_material());
    desc.materials
        .push(MaterialDesc::diffuse("grey", Vec3::splat(0.7)));
    let backdrop =
        Mat4::from_translation(Vec3::new(0.0, 0.0, -3.0)) * Mat4::from_scale(Vec3::splat(2.0));
    desc.shapes
        .push(shape(GeometryDesc::Rectangle, "grey", None, backdrop));
    for (x, y, angle, le) in [(-0.4f32, 0.3f32, 0.5f32, 4.0f32), (0.45, -0.35, -0.3, 1.5)] {
        let t = Mat4::from_scale_rotation_translation(
            Vec3::splat(0.3),
            Quat::from_rotation_z(angle),
            Vec3::new(x, y, -2.999),
        );
        desc.shapes
            .push(shape(GeometryDesc::Rectangle, "black", Some(le), t));
    }
    desc.lights.push(LightDesc::point(
        Vec3::new(0.5, 0.8, -1.0),
        Vec3::splat(2.0),
    ));
    desc
}

/// Per-pixel mean and unbiased variance over `k` one-sample renders.
fn pixel_stats(desc: &SceneDesc, k: u32) -> Vec<(f64, f64)> {
    let runs: Vec<Vec<f32>> = (0..k).map(|i| render_grey(desc, i..i + 1)).collect();
    (0..runs[0].len())
        .map(|p| {
            let mean = runs.iter().map(|r| r[p] as f64).sum::<f64>() / k as f64;
            let var = runs
                .iter()
                .map(|r| (r[p] as f64 - mean).powi(2))
                .sum::<f64>()
                / (k as f64 - 1.0);
            (mean, var)
        })
        .collect()
}

/// Pixels whose Welch test rejects equal means, at family-wise α = 0.01 over all pixels
/// (Bonferroni: per-pixel α = 0.01/576). α is small because 576 tests run at once; the
/// samples are independent (the two renders' streams differ) and 256 per pixel make the
/// means close enough to normal for the t-test even at the edges' two-valued pixels.
fn rejected_pixels(a: &[(f64, f64)], b: &[(f64, f64)], k: f64) -> usize {
    let alpha = 0.01 / a.len() as f64;
    a.iter()
        .zip(b)
        .filter(|((ma, va), (mb, vb))| welch_p(*ma, *va, k, *mb, *vb, k) < alpha)
        .count()
}

#[test]
fn in_focus_scene_matches_the_pinhole_render() {
    const K: u32 = 256;
    let lens = |focus| LensDesc {
        focus: FocusDesc::Distance(focus),
        size: ApertureSizeDesc::Radius(0.3),
        aperture: ApertureDesc::Polygon {
            blades: 6,
            rotation_deg: 0.0,
        },
    };
    let pinhole = pixel_stats(&flat_scene(None, 1), K);
    let focused = pixel_stats(&flat_scene(Some(lens(3.0)), 2), K);
    let rejected = rejected_pixels(&pinhole, &focused, K as f64);
    println!("in focus: {rejected} of 576 pixels reject");
    assert_eq!(
        rejected, 0,
        "{rejected} pixels differ from the pinhole render"
    );
    // The same test sees a lens focused at 1.5 (a blur ~6 px across): it can fail.
    let blurred = pixel_stats(&flat_scene(Some(lens(1.5)), 2), K);
    let rejected = rejected_pixels(&pinhole, &blurred, K as f64);
    println!("focused at 1.5: {rejected} of 576 pixels reject");
    assert!(
        rejected >= 10,
        "only {rejected} pixels differ from an out-of-focus render"
    );
}
