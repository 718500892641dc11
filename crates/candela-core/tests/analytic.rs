//! Scenes with closed-form radiance, built in code and rendered by the path tracer.
//!
//! Statistical tolerances: every pixel of these scenes has the same expected value `L`,
//! and pixels are independent (each has its own sample streams). The standard deviation
//! σ of a pixel is estimated from the spread of all pixels; the image mean must lie within
//! 4 standard errors σ/√pixels of `L` (two-sided p = 6·10⁻⁵ per check) and, where the
//! estimator's variance is finite, the mean of every 4×4 block of pixels within 6σ/4 of
//! `L` (p = 2·10⁻⁹ per block for a normal mean; 64 blocks an image). Blocks, not single
//! pixels: Russian roulette makes a pixel's distribution skewed (its rare survivors add a
//! whole further path), so a single pixel's mean is not close to normal at 64 spp (skew
//! 1.3–1.5 in the ρ = 0.5 sphere, where single pixels land 7σ out), while a block's mean
//! of 16 pixels has a quarter of that skew. A block still shows any error confined to a
//! part of the image, at 1.5σ of a single pixel. Where a scene has
//! no variance at all (the furnace with BSDF sampling), a floor of 10⁻⁴·L covers f32
//! round-off.
//!
//! Every scene is rendered with each sampler: the Sobol' samplers' pixels are as
//! independent of each other as the independent sampler's (each pixel has its own
//! scrambles and patterns), so the same bounds apply to them.

use std::sync::atomic::AtomicBool;

use candela_core::build::build;
use candela_core::desc::*;
use candela_core::integrator::render;
use glam::{Mat4, Vec3};

const MIS_MODES: [MisMode; 4] = [
    MisMode::Balance,
    MisMode::Power,
    MisMode::NeeOnly,
    MisMode::BsdfOnly,
];

const SAMPLERS: [SamplerKind; 3] = [
    SamplerKind::Independent,
    SamplerKind::Sobol,
    SamplerKind::SobolCmj,
];

fn material(name: &str, albedo: f32) -> MaterialDesc {
    MaterialDesc::diffuse(name, Vec3::splat(albedo))
}

fn shape(geometry: GeometryDesc, material: &str, le: Option<f32>, flip: bool) -> ShapeDesc {
    ShapeDesc::new(geometry, material)
        .with_emission(le.map(Vec3::splat))
        .with_flipped_normals(flip)
}

fn settings(
    sampler: SamplerKind,
    mis: MisMode,
    max_depth: u32,
    spp: u32,
    seed: u64,
) -> RenderSettings {
    RenderSettings {
        sampler,
        width: 32,
        height: 32,
        spp,
        max_depth,
        seed,
        mis,
        light_sampler: LightSamplerKind::Power,
        ..Default::default()
    }
}

/// The red channel of every pixel.
fn render_pixels(desc: &SceneDesc) -> Vec<f64> {
    let scene = build(desc).expect("scene builds");
    let spp = desc.render.spp;
    let result = render(&scene, 0..spp, &AtomicBool::new(false), &|_| {});
    assert_eq!(result.film.rejected_samples(), 0, "non-finite samples");
    result.film.resolve().iter().map(|v| v.x as f64).collect()
}

/// Side of the square blocks of pixels whose means are checked one by one.
const BLOCK: usize = 4;

/// Checks the image mean and, if `blocks`, the mean of every `BLOCK`² block of pixels
/// against `expected` (see the module docs). `pixels` is a square image, row by row.
fn check_uniform(name: &str, pixels: &[f64], expected: f64, blocks: bool) {
    let n = pixels.len() as f64;
    let mean = pixels.iter().sum::<f64>() / n;
    let var = pixels.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let sigma = var.sqrt();
    let floor = 1e-4 * expected;
    let se = sigma / n.sqrt();
    assert!(
        (mean - expected).abs() <= (4.0 * se).max(floor),
        "{name}: image mean {mean:.5}, expected {expected:.5}, 4·SE = {:.5}",
        4.0 * se
    );
    let side = pixels.len().isqrt();
    assert_eq!(side * side, pixels.len(), "{name}: a square image");
    let sigma_block = sigma / BLOCK as f64;
    let per_side = side / BLOCK;
    for b in (0..per_side * per_side).filter(|_| blocks) {
        let (by, bx) = (b / per_side, b % per_side);
        let block_mean = (0..BLOCK * BLOCK)
            .map(|k| pixels[(by * BLOCK + k / BLOCK) * side + bx * BLOCK + k % BLOCK])
            .sum::<f64>()
            / (BLOCK * BLOCK) as f64;
        assert!(
            (block_mean - expected).abs() <= (6.0 * sigma_block).max(floor),
            "{name}: block ({bx}, {by}) mean {block_mean:.5}, expected {expected:.5}, \
             6σ/{BLOCK} = {:.5}",
            6.0 * sigma_block
        );
    }
    eprintln!("{name}: mean {mean:.5} vs {expected:.5} (SE {se:.2e}, σ {sigma:.3})");
}

fn inside_camera(position: Vec3, look_at: Vec3) -> CameraDesc {
    CameraDesc {
        position,
        look_at,
        up: Vec3::Y,
        fov_y_deg: 70.0,
        span: Span::code(),
        ..Default::default()
    }
}

/// The inside of a unit sphere of albedo `rho` emitting `le` everywhere, seen from inside.
fn closed_sphere(rho: f32, le: f32, render: RenderSettings) -> SceneDesc {
    let mut desc = SceneDesc {
        camera: inside_camera(Vec3::new(0.2, -0.1, 0.3), Vec3::new(0.0, 0.4, -1.0)),
        render,
        ..Default::default()
    };
    desc.materials.push(material("wall", rho));
    desc.shapes.push(shape(
        GeometryDesc::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        },
        "wall",
        Some(le),
        true,
    ));
    desc
}

#[test]
fn closed_emitting_sphere_has_radiance_le_over_one_minus_albedo() {
    // Every surface point emits Le and reflects ρ of the uniform radiance L around it:
    // L = Le + ρL, so L = Le/(1−ρ) (paths unlimited; Russian roulette ends them).
    // 32×32 pixels at 64 spp.
    let le = 0.7;
    for (rho, sampler) in [0.5f32, 0.8]
        .into_iter()
        .flat_map(|r| SAMPLERS.map(|s| (r, s)))
    {
        for mis in MIS_MODES {
            let desc = closed_sphere(rho, le, settings(sampler, mis, 1000, 64, 17));
            let expected = le as f64 / (1.0 - rho as f64);
            check_uniform(
                &format!("sphere ρ = {rho}, {mis:?}, {sampler:?}"),
                &render_pixels(&desc),
                expected,
                true,
            );
        }
    }
}

#[test]
fn a_closed_sphere_of_a_mixed_material_reflects_the_mixed_albedo() {
    // The closed emitting sphere again, its wall a mix: of weight w between diffuse ρ_a
    // and ρ_b, or between diffuse ρ_a and a perfect mirror (Mitsuba's `none` conductor,
    // η = 0, k = 1, albedo 1 at every angle). Under the uniform radiance L inside, the
    // wall reflects L·((1 − w)·ρ_a + w·ρ_b) towards every direction, so L = Le/(1 − ρ)
    // with that ρ, exactly as for a plain wall. This checks that choosing one side per
    // hit leaves the estimator unbiased under every MIS mode, a delta side included
    // (where next event estimation is skipped for the hit).
    let diffuse = |albedo: f32| BsdfDesc::Diffuse {
        albedo: TextureDesc::Constant(Vec3::splat(albedo)),
    };
    let mirror = BsdfDesc::Conductor {
        eta: Vec3::ZERO,
        k: Vec3::ONE,
        specular: Vec3::ONE,
        alpha_u: 0.0,
        alpha_v: 0.0,
        distribution: MicrofacetDesc::Ggx,
    };
    let le = 0.7;
    for (name, b, rho_b, w) in [
        ("diffuse 0.2 + 0.9", diffuse(0.9), 0.9, 0.4f32),
        ("diffuse 0.2 + mirror", mirror, 1.0, 0.3),
    ] {
        let rho = (1.0 - w as f64) * 0.2 + w as f64 * rho_b;
        for (sampler, mis) in SAMPLERS.into_iter().flat_map(|s| MIS_MODES.map(|m| (s, m))) {
            let mut desc = closed_sphere(0.0, le, settings(sampler, mis, 1000, 64, 29));
            desc.materials[0].bsdf = BsdfDesc::Mix {
                weight: TextureDesc::Constant(Vec3::splat(w)),
                a: Box::new(diffuse(0.2)),
                b: Box::new(b.clone()),
            };
            check_uniform(
                &format!("mixed sphere {name} at w {w}, {mis:?}, {sampler:?}"),
                &render_pixels(&desc),
                le as f64 / (1.0 - rho),
                true,
            );
        }
    }
}

#[test]
fn russian_roulette_starts_after_rr_depth_bounces() {
    // The closed ρ = 0.5 sphere again, cut at max_depth 4: L = Le·(1 + ρ + … + ρ⁴) whether
    // or not roulette runs. With BSDF sampling only a path casts one ray a segment, and
    // roulette follows each scattering from the rr_depth-th on, the last one (at max_depth)
    // included: with rr_depth > max_depth every path casts exactly 5 rays; with rr_depth 2
    // each casts at least 2 (camera and first bounce) and 2.44 on average.
    let (le, rho, max_depth) = (0.7f64, 0.5f32, 4u32);
    for (rr_depth, sampler) in [2u32, 4, 5]
        .into_iter()
        .flat_map(|d| SAMPLERS.map(|s| (d, s)))
    {
        let with_rr = RenderSettings {
            rr_depth,
            ..settings(sampler, MisMode::BsdfOnly, max_depth, 64, 41)
        };
        let desc = closed_sphere(rho, le as f32, with_rr);
        let scene = build(&desc).expect("scene builds");
        let result = render(&scene, 0..64, &AtomicBool::new(false), &|_| {});
        let (paths, rays) = (result.stats.paths, result.stats.rays);
        if rr_depth > max_depth {
            assert_eq!(rays, 5 * paths, "rr_depth {rr_depth}, {sampler:?}");
        } else {
            assert!(
                rays >= rr_depth as u64 * paths && rays < 5 * paths,
                "rr_depth {rr_depth}, {sampler:?}: {rays} rays for {paths} paths"
            );
        }
        let pixels: Vec<f64> = result.film.resolve().iter().map(|v| v.x as f64).collect();
        let expected = le
            * (0..=max_depth)
                .map(|k| (rho as f64).powi(k as i32))
                .sum::<f64>();
        check_uniform(
            &format!("sphere ρ = {rho}, max_depth {max_depth}, rr_depth {rr_depth}, {sampler:?}"),
            &pixels,
            expected,
            true,
        );
    }
}

#[test]
fn furnace_box_with_max_depth_n_has_radiance_n_plus_one_le() {
    // An inward cube of albedo 1 emitting Le everywhere: each of the N scattering events
    // a path may take adds exactly Le to what the eye sees, so L = (N+1)·Le.
    let le = 0.25;
    for (max_depth, sampler) in [0u32, 1, 3, 6]
        .into_iter()
        .flat_map(|d| SAMPLERS.map(|s| (d, s)))
    {
        for mis in MIS_MODES {
            let mut desc = SceneDesc {
                // The camera sees the middle of one face (see the per-pixel note below).
                camera: CameraDesc {
                    fov_y_deg: 40.0,
                    ..inside_camera(Vec3::new(0.1, -0.05, 0.2), Vec3::new(0.1, -0.05, -1.0))
                },
                render: settings(sampler, mis, max_depth, 32, 23),
                ..Default::default()
            };
            desc.materials.push(material("white", 1.0));
            desc.shapes
                .push(shape(GeometryDesc::Cube, "white", Some(le), true));
            let expected = (max_depth + 1) as f64 * le as f64;
            check_uniform(
                &format!("furnace, max_depth {max_depth}, {mis:?}, {sampler:?}"),
                &render_pixels(&desc),
                expected,
                // Paths reach points near the cube's concave edges, where next event
                // estimation has (log-)divergent variance: rare samples of ~10³ break any
                // block σ bound while the image mean stays within its 4·SE.
                false,
            );
        }
    }
}

#[test]
fn sphere_enclosure_around_a_black_emitter_conserves_energy() {
    // A black sphere of radius r emitting Le sits at the centre of an inward sphere of
    // radius R and albedo ρ. By symmetry the wall radiance L_w is uniform. The wall's
    // irradiance is the emitter's power spread over the wall, π·Le·r²/R², plus the wall's
    // own radiosity π·L_w times the fraction of it that misses the emitter, 1 − r²/R²
    // (reciprocity: F_wall→emitter = A_emitter/A_wall). With π·L_w = ρ·E:
    //   L_w = ρ·Le·k / (1 − ρ·(1 − k)),  k = r²/R².
    // At ρ = 1 every watt emitted returns to the emitter and L_w = Le exactly.
    let (le, r) = (2.0f32, 0.3f32);
    let k = (r * r) as f64;
    for (rho, sampler) in [1.0f32, 0.7]
        .into_iter()
        .flat_map(|r| SAMPLERS.map(|s| (r, s)))
    {
        for mis in [MisMode::Balance, MisMode::BsdfOnly] {
            let mut desc = SceneDesc {
                // Looking away from the emitter, so that every pixel sees the wall.
                camera: inside_camera(Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.0, 0.0, 1.0)),
                render: settings(sampler, mis, 1000, 64, 29),
                ..Default::default()
            };
            desc.materials.push(material("wall", rho));
            desc.materials.push(material("black", 0.0));
            desc.shapes.push(shape(
                GeometryDesc::Sphere {
                    center: Vec3::ZERO,
                    radius: 1.0,
                },
                "wall",
                None,
                true,
            ));
            desc.shapes.push(shape(
                GeometryDesc::Sphere {
                    center: Vec3::ZERO,
                    radius: r,
                },
                "black",
                Some(le),
                false,
            ));
            let rho64 = rho as f64;
            let expected = rho64 * le as f64 * k / (1.0 - rho64 * (1.0 - k));
            check_uniform(
                &format!("sphere enclosure ρ = {rho}, {mis:?}, {sampler:?}"),
                &render_pixels(&desc),
                expected,
                true,
            );
        }
    }
}

/// A camera at `target` + `offset` looking at `target` through a footprint ~10⁻³ wide:
/// the radiance of the scenes below varies over it by ~10⁻⁶ relative.
fn narrow_camera(target: Vec3, offset: Vec3) -> CameraDesc {
    CameraDesc {
        position: target + offset,
        look_at: target,
        up: Vec3::Z,
        fov_y_deg: 0.02,
        span: Span::code(),
        ..Default::default()
    }
}

/// The plane y = 0, 20 × 20 around the origin, facing +y.
fn floor_plane(material: &str) -> ShapeDesc {
    shape(GeometryDesc::Rectangle, material, None, false).transformed(
        Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2) * Mat4::from_scale(Vec3::splat(10.0)),
    )
}

/// Radiance of a diffuse plane y = 0 (albedo ρ) at `target` on it, lit by a point light
/// of intensity `intensity` at height `h` over the origin, seen by a narrow camera.
fn plane_radiance(
    rho: f32,
    intensity: f32,
    h: f32,
    target: Vec3,
    mis: MisMode,
    sampler: SamplerKind,
) -> f64 {
    let mut desc = SceneDesc {
        camera: narrow_camera(target, Vec3::new(0.3, 2.0, 0.2)),
        render: RenderSettings {
            width: 4,
            height: 4,
            ..settings(sampler, mis, 1, 4, 5)
        },
        ..Default::default()
    };
    desc.materials.push(material("plane", rho));
    desc.shapes.push(floor_plane("plane"));
    desc.lights.push(LightDesc::point(
        Vec3::new(0.0, h, 0.0),
        Vec3::splat(intensity),
    ));
    let px = render_pixels(&desc);
    px.iter().sum::<f64>() / px.len() as f64
}

#[test]
fn point_light_over_a_diffuse_plane() {
    // Direct light only (max_depth 1): L = ρ/π · I·cos θ/d². Every sample is exact, so
    // the tolerance 10⁻³ (relative) covers only the f32 arithmetic and the footprint.
    let (rho, intensity, h) = (0.6f32, 5.0f32, 1.5f32);
    for (mis, sampler) in MIS_MODES.into_iter().flat_map(|m| SAMPLERS.map(|s| (m, s))) {
        let foot = plane_radiance(rho, intensity, h, Vec3::ZERO, mis, sampler);
        let expected = rho as f64 / std::f64::consts::PI * intensity as f64 / (h * h) as f64;
        assert!(
            (foot / expected - 1.0).abs() < 1e-3,
            "{mis:?}, {sampler:?}: foot {foot} vs {expected}"
        );
        let x = Vec3::new(1.2, 0.0, -0.7);
        let off = plane_radiance(rho, intensity, h, x, mis, sampler);
        let d2 = (x.length_squared() + h * h) as f64;
        let cos = h as f64 / d2.sqrt();
        let expected = rho as f64 / std::f64::consts::PI * intensity as f64 * cos / d2;
        assert!(
            (off / expected - 1.0).abs() < 1e-3,
            "{mis:?}, {sampler:?}: offset {off} vs {expected}"
        );
    }
}

/// An orthographic camera sees sizes as they are, whatever the distance. It looks down −y
/// at an emitting square of side 1 (radiance 1, nothing else in the scene) over a view 4
/// high on a 32 × 32 film, so 8 × 8 pixels, aligned with the square's edges, see the
/// square and the rest see nothing: with the box filter every pixel is exactly 1 or 0
/// (up to the f32 rounding of a sample on an edge), at distance 1 and at 20 alike. A
/// perspective camera's square would shrink 20-fold between the two, and a view half or
/// twice as high would cover 4 or 16 times the pixels.
#[test]
fn an_orthographic_camera_sees_true_sizes_at_any_distance() {
    for distance in [1.0, 20.0] {
        for sampler in SAMPLERS {
            let mut desc = SceneDesc {
                camera: CameraDesc {
                    position: Vec3::new(0.0, distance, 0.0),
                    look_at: Vec3::ZERO,
                    up: Vec3::Z,
                    ortho_height: Some(4.0),
                    span: Span::code(),
                    ..Default::default()
                },
                render: settings(sampler, MisMode::Balance, 1, 4, 9),
                ..Default::default()
            };
            desc.materials.push(material("black", 0.0));
            desc.shapes.push(
                shape(GeometryDesc::Rectangle, "black", Some(1.0), false).transformed(
                    Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2)
                        * Mat4::from_scale(Vec3::splat(0.5)),
                ),
            );
            let px = render_pixels(&desc);
            let side = 32;
            for (i, v) in px.iter().enumerate() {
                let (x, y) = (i % side, i / side);
                let inside = (12..20).contains(&x) && (12..20).contains(&y);
                let want = if inside { 1.0 } else { 0.0 };
                assert!(
                    (v - want).abs() < 1e-3,
                    "distance {distance}, {sampler:?}: pixel ({x}, {y}) = {v}, want {want}"
                );
            }
        }
    }
}

/// The configuration factor from a point to the rectangle [0, x] × [0, z] of a parallel
/// plane at height `h`, one corner over the point (Siegel & Howell, *Thermal Radiation
/// Heat Transfer*, the point-to-parallel-rectangle factor), signed: odd in x and in z, so
/// that corner rectangles add and subtract to any rectangle of the plane.
fn corner_factor(x: f64, z: f64, h: f64) -> f64 {
    let (a, b) = (x / h, z / h);
    let (ra, rb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
    (a / ra * (b / ra).atan() + b / rb * (a / rb).atan()) / (2.0 * std::f64::consts::PI)
}

/// The factor from the origin of the plane y = 0 to [x1, x2] × [z1, z2] at height `h`.
fn rect_factor(x1: f64, x2: f64, z1: f64, z2: f64, h: f64) -> f64 {
    corner_factor(x2, z2, h) - corner_factor(x1, z2, h) - corner_factor(x2, z1, h)
        + corner_factor(x1, z1, h)
}

#[test]
fn a_checkered_emitter_lights_a_plane_square_by_square() {
    // A square emitter of half-side s at height h faces down over a diffuse plane, its
    // radiance a checker: `hi` on the quadrants x < 0, z < 0 and x > 0, z > 0, `lo` on the
    // other two. Direct light only: the plane's radiance at (x0, 0, z0) is
    // ρ/π · Σ L_q · π·F_q, F_q the configuration factor of quadrant q seen from there.
    // The point is off centre so that swapping the squares (or the uvs' axes) moves the
    // answer: by 18 % at the point below. Every MIS mode checks a different half of the
    // texture's path: NEE looks the texture up at the sampled point's barycentrics, BSDF
    // sampling at the hit's interpolated uvs. Tolerance as `check_uniform`'s.
    let (rho, s, h, hi, lo) = (0.7f32, 1.0f32, 0.8f32, 3.0f32, 0.5f32);
    let (x0, z0) = (0.4f64, -0.25f64);
    let quadrant = |x1: f64, x2: f64, z1: f64, z2: f64| {
        rect_factor(x1 - x0, x2 - x0, z1 - z0, z2 - z0, h as f64)
    };
    let s64 = s as f64;
    let irradiance = std::f64::consts::PI
        * (hi as f64 * (quadrant(-s64, 0.0, -s64, 0.0) + quadrant(0.0, s64, 0.0, s64))
            + lo as f64 * (quadrant(0.0, s64, -s64, 0.0) + quadrant(-s64, 0.0, 0.0, s64)));
    let expected = rho as f64 / std::f64::consts::PI * irradiance;
    let swapped = rho as f64
        * (lo as f64 * (quadrant(-s64, 0.0, -s64, 0.0) + quadrant(0.0, s64, 0.0, s64))
            + hi as f64 * (quadrant(0.0, s64, -s64, 0.0) + quadrant(-s64, 0.0, 0.0, s64)));
    assert!(
        (swapped / expected - 1.0).abs() > 0.15,
        "{swapped} vs {expected}"
    );
    let target = Vec3::new(x0 as f32, 0.0, z0 as f32);
    for (mis, sampler) in MIS_MODES.into_iter().flat_map(|m| SAMPLERS.map(|s| (m, s))) {
        let mut desc = SceneDesc {
            camera: narrow_camera(target, Vec3::new(0.1, 0.5, 0.05)),
            render: settings(sampler, mis, 1, 64, 11),
            ..Default::default()
        };
        desc.materials.push(material("plane", rho));
        desc.materials.push(material("black", 0.0));
        desc.shapes.push(floor_plane("plane"));
        desc.shapes.push(
            shape(GeometryDesc::Rectangle, "black", Some(1.0), false)
                .transformed(
                    Mat4::from_translation(Vec3::new(0.0, h, 0.0))
                        * Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2)
                        * Mat4::from_scale(Vec3::splat(s)),
                )
                .with_emission_texture(TextureDesc::Checker {
                    a: Vec3::splat(hi),
                    b: Vec3::splat(lo),
                    uv_transform: glam::Affine2::from_scale(glam::Vec2::splat(2.0)),
                }),
        );
        let px = render_pixels(&desc);
        check_uniform(
            &format!("checkered emitter, {mis:?}, {sampler:?}"),
            &px,
            expected,
            true,
        );
    }
}

/// Lamps close over a diffuse plane, a square of side 2 (one parallelogram light) and a
/// triangle (half of it), 0.6 above a point off their centres, drawn by area and, under
/// [`LampSampling::SolidAngle`], in the solid angle they cover (area / d² ≈ 8 and 4, far
/// above the 0.04 where that starts). Direct light only: the plane's radiance is
/// ρ/π · L · E, E Lambert's closed form for the polygon (`polygon_irradiance`). Every MIS
/// mode runs: `NeeOnly` checks the drawn points' density alone, `BsdfOnly` none of it, and
/// the two heuristics `pdf_li`'s inverse map against it. Tolerance as `check_uniform`'s.
#[test]
fn near_lamps_light_a_plane_as_lamberts_formula_says() {
    let (rho, h, le) = (0.7f32, 0.6f32, 2.0f32);
    let target = Vec3::new(0.3, 0.0, -0.2);
    let corner = |x: f32, z: f32| Vec3::new(x, h, z);
    let square = [
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ];
    // Wound so that its normal points down, at the plane.
    let triangle = [square[0], square[1], square[3]];
    let triangle_mesh = MeshDesc {
        positions: triangle.to_vec(),
        indices: vec![[0, 1, 2]],
        ..Default::default()
    };
    let lamps = [
        (
            "square",
            GeometryDesc::Rectangle,
            Mat4::from_translation(Vec3::Y * h)
                * Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2),
            &square[..],
        ),
        (
            "triangle",
            GeometryDesc::Mesh(std::sync::Arc::new(triangle_mesh)),
            Mat4::IDENTITY,
            &triangle[..],
        ),
    ];
    for (what, geometry, transform, polygon) in lamps {
        let irradiance = candela_core::light::polygon_irradiance(polygon, target, Vec3::Y);
        let expected = rho as f64 / std::f64::consts::PI * le as f64 * irradiance;
        for lamp_sampling in [LampSampling::Area, LampSampling::SolidAngle] {
            for (mis, sampler) in MIS_MODES.into_iter().flat_map(|m| SAMPLERS.map(|s| (m, s))) {
                let mut desc = SceneDesc {
                    camera: narrow_camera(target, Vec3::new(0.1, 0.4, 0.05)),
                    render: RenderSettings {
                        lamp_sampling,
                        ..settings(sampler, mis, 1, 64, 13)
                    },
                    ..Default::default()
                };
                desc.materials.push(material("plane", rho));
                desc.materials.push(material("black", 0.0));
                desc.shapes.push(floor_plane("plane"));
                desc.shapes
                    .push(shape(geometry.clone(), "black", Some(le), false).transformed(transform));
                let px = render_pixels(&desc);
                let name = format!("near {what}, {lamp_sampling:?}, {mis:?}, {sampler:?}");
                check_uniform(&name, &px, expected, true);
            }
        }
    }
}
