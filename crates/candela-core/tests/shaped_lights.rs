//! Closed-form tests of the spot, goniometric (IES point), projector, directional and
//! IES-shaped area lights, and of the build's unit conversions.
//!
//! The irradiance tests render with next event estimation: one delta light, a diffuse
//! plane of albedo ρ and `max_depth = 1` make the path tracer's estimate deterministic,
//! L = ρ/π · E with E = I(ω)·cos θ/d², so the tolerance is float rounding (10⁻⁴
//! relative), not noise.

use std::f32::consts::PI;
use std::sync::Arc;

use candela_core::build::{build, LUMENS_PER_WATT};
use candela_core::desc::*;
use candela_core::geometry::Ray;
use candela_core::integrator::li;
use candela_core::light::{Light, LightProfile, LightSource, ShadingCtx, SpotLight, TriangleLight};
use candela_core::photometry::GoniometricTable;
use candela_core::sampler::{IndependentSampler, Pcg32, Sampler};
use candela_core::Scene;
use glam::{Mat4, UVec2, Vec2, Vec3};

const RHO: f32 = 0.6;

/// An asymmetric synthetic profile: a lobe around 20° from the nadir, brighter towards
/// C90 than towards C270.
fn asymmetric_table() -> Arc<GoniometricTable> {
    let v: Vec<f64> = (0..=18).map(|i| i as f64 * 10.0).collect();
    let h: Vec<f64> = (0..=8).map(|i| i as f64 * 45.0).collect();
    let mut cd = Vec::new();
    for &phi in &h {
        for &theta in &v {
            let lobe = (-((theta - 20.0) / 25.0).powi(2)).exp();
            cd.push(1000.0 * lobe * (1.5 + phi.to_radians().sin()) + 5.0);
        }
    }
    Arc::new(GoniometricTable::new(&v, &h, &cd).unwrap())
}

fn plane_scene(lights: Vec<LightDesc>) -> Scene {
    let mut desc = SceneDesc {
        render: RenderSettings {
            max_depth: 1,
            mis: MisMode::NeeOnly,
            ..Default::default()
        },
        ..Default::default()
    };
    desc.materials
        .push(MaterialDesc::diffuse("wall", Vec3::splat(RHO)));
    // The floor y = 0, 20 × 20, facing +y.
    desc.shapes.push(
        ShapeDesc::new(GeometryDesc::Rectangle, "wall")
            .transformed(Mat4::from_rotation_x(-PI / 2.0) * Mat4::from_scale(Vec3::splat(10.0))),
    );
    desc.lights = lights;
    build(&desc).unwrap()
}

fn light(kind: LightKindDesc) -> LightDesc {
    LightDesc::new(kind)
}

/// Radiance the path tracer sees at floor point `p` from straight above it.
fn rendered(scene: &Scene, p: Vec3) -> Vec3 {
    let mut s = IndependentSampler::new(1);
    s.start_pixel_sample(UVec2::ZERO, 0);
    let ray = Ray::new(p + Vec3::Y * 0.01, -Vec3::Y);
    li(scene, ray, &mut s, &mut 0)
}

fn floor_grid() -> impl Iterator<Item = Vec3> {
    (-4..=4).flat_map(|i| (-4..=4).map(move |k| Vec3::new(i as f32 * 0.7, 0.0, k as f32 * 0.6)))
}

fn assert_close(got: Vec3, want: Vec3, what: &str) {
    let tol = 1e-4 * want.max_element().max(1e-6);
    assert!(
        (got - want).abs().max_element() <= tol,
        "{what}: got {got}, want {want}"
    );
}

#[test]
fn point_light_with_ies_profile_gives_e_equals_i_cos_over_d2() {
    let table = asymmetric_table();
    let pos = Vec3::new(0.3, 2.0, -0.2);
    let scene = plane_scene(vec![light(LightKindDesc::ShapedPoint(ShapedPointDesc {
        position: pos,
        color: LightColorDesc::Rgb(Vec3::ONE),
        amount: LightAmountDesc::ProfileCandela,
        profile: Some(ProfileDesc {
            table: table.clone(),
            nadir: -Vec3::Y,
            c0: Vec3::X,
            span: Span::code(),
        }),
    }))]);
    for p in floor_grid() {
        let to = p - pos;
        let d2 = to.length_squared();
        let w = to / d2.sqrt();
        // Table frame: nadir −y, C0 +x, so C90 = nadir × C0 = +z.
        let cd = table.intensity(Vec3::new(w.x, w.z, -w.y));
        let e = cd / LUMENS_PER_WATT * (-w.y) / d2;
        assert_close(rendered(&scene, p), Vec3::splat(RHO / PI * e), "IES point");
    }
}

fn spot_desc(falloff: SpotFalloff, amount: LightAmountDesc) -> SpotLightDesc {
    SpotLightDesc {
        position: Vec3::new(-0.5, 3.0, 0.4),
        direction: Vec3::new(0.3, -1.0, -0.1),
        inner_angle_deg: 20.0,
        outer_angle_deg: 45.0,
        falloff,
        color: LightColorDesc::Rgb(Vec3::new(1.0, 0.8, 0.5)),
        amount,
        profile: None,
    }
}

/// The stated curves, written out again independently of the light.
fn falloff_reference(f: SpotFalloff, theta: f32, inner: f32, outer: f32) -> f32 {
    if theta <= inner {
        return 1.0;
    }
    if theta >= outer {
        return 0.0;
    }
    let t = (theta.cos() - outer.cos()) / (inner.cos() - outer.cos());
    match f {
        SpotFalloff::Smoothstep => 3.0 * t * t - 2.0 * t * t * t,
        SpotFalloff::Gltf => t * t,
        SpotFalloff::Mitsuba => (outer - theta) / (outer - inner),
    }
}

#[test]
fn spot_light_gives_e_equals_i_cos_over_d2() {
    for falloff in [
        SpotFalloff::Smoothstep,
        SpotFalloff::Mitsuba,
        SpotFalloff::Gltf,
    ] {
        let d = spot_desc(falloff, LightAmountDesc::WattsPerSr(5.0));
        let scene = plane_scene(vec![light(LightKindDesc::Spot(d.clone()))]);
        let axis = d.direction.normalize();
        let (mut lit, mut dark) = (0, 0);
        for p in floor_grid() {
            let to = p - d.position;
            let d2 = to.length_squared();
            let w = to / d2.sqrt();
            let theta = w.dot(axis).clamp(-1.0, 1.0).acos();
            let f = falloff_reference(falloff, theta, 20f32.to_radians(), 45f32.to_radians());
            let e = Vec3::new(1.0, 0.8, 0.5) * 5.0 * f * (-w.y) / d2;
            let got = rendered(&scene, p);
            assert_close(got, RHO / PI * e, &format!("{falloff:?} spot at {p}"));
            if f == 0.0 {
                assert_eq!(got, Vec3::ZERO);
                dark += 1;
            } else {
                lit += 1;
            }
        }
        assert!(
            lit > 10 && dark > 10,
            "the grid must cover both sides of the cone"
        );
    }
}

#[test]
fn spot_power_matches_numerical_integration() {
    for falloff in [
        SpotFalloff::Smoothstep,
        SpotFalloff::Mitsuba,
        SpotFalloff::Gltf,
    ] {
        for (inner, outer) in [(10.0f32, 30.0f32), (0.0, 60.0), (25.0, 25.0), (40.0, 120.0)] {
            let spot = SpotLight::new(
                Vec3::ZERO,
                Vec3::new(0.2, -1.0, 0.3),
                inner.to_radians(),
                outer.to_radians(),
                falloff,
                Vec3::splat(3.0),
                None,
            );
            // Midpoint rule over θ ∈ [0, π] with the reference curve, 10⁵ steps.
            let n = 100_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let theta = std::f64::consts::PI * (i as f64 + 0.5) / n as f64;
                let f = falloff_reference(
                    falloff,
                    theta as f32,
                    inner.to_radians(),
                    outer.to_radians(),
                ) as f64;
                sum += f * theta.sin();
            }
            let numeric = 3.0 * 2.0 * std::f64::consts::PI * sum * std::f64::consts::PI / n as f64;
            let rel = (spot.power() as f64 - numeric).abs() / numeric;
            assert!(
                rel < 1e-3,
                "{falloff:?} {inner}–{outer}°: {} vs {numeric} ({rel:.2e})",
                spot.power()
            );
        }
    }
}

#[test]
fn a_spot_facing_away_contributes_exactly_nothing() {
    let spot = SpotLight::new(
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::Y,
        30f32.to_radians(),
        60f32.to_radians(),
        SpotFalloff::Smoothstep,
        Vec3::splat(100.0),
        None,
    );
    let ctx = ShadingCtx {
        p: Vec3::ZERO,
        n: Vec3::Y,
    };
    assert!(!spot.reaches(ctx.p));
    // Zero potential contribution, for the light samplers: exact and bounded.
    assert_eq!(spot.importance(&ctx), 0.0);
    assert_eq!(spot.bounds().unwrap().importance(&ctx), 0.0);
    let lit = ShadingCtx {
        p: Vec3::new(0.0, 4.0, 0.0),
        n: -Vec3::Y,
    };
    assert!(spot.importance(&lit) > 0.0 && spot.bounds().unwrap().importance(&lit) > 0.0);
    assert!(Light::Spot(spot)
        .sample_li(&ctx, Vec2::splat(0.5))
        .is_none());
    let d = SpotLightDesc {
        direction: Vec3::Y,
        ..spot_desc(SpotFalloff::Smoothstep, LightAmountDesc::WattsPerSr(100.0))
    };
    let scene = plane_scene(vec![light(LightKindDesc::Spot(d))]);
    for p in floor_grid() {
        assert_eq!(rendered(&scene, p), Vec3::ZERO);
    }
}

#[test]
fn projector_reproduces_its_image_on_a_wall() {
    // A 4 × 3 image of distinct colours; the projector at height 2 looks straight down.
    let (w, h) = (4u32, 3u32);
    let pixels: Vec<Vec3> = (0..w * h)
        .map(|i| {
            Vec3::new(
                0.1 + i as f32 * 0.07,
                1.0 - i as f32 * 0.05,
                (i % 3) as f32 * 0.4,
            )
        })
        .collect();
    let image = Arc::new(ImageDesc {
        width: w,
        height: h,
        pixels: pixels.clone(),
    });
    let (fov_x, fov_y) = (70.0f32, 50.0f32);
    let pos = Vec3::new(0.2, 2.0, 0.1);
    let scene = plane_scene(vec![light(LightKindDesc::Projector(ProjectorLightDesc {
        position: pos,
        direction: -Vec3::Y,
        up: -Vec3::Z,
        fov_x_deg: fov_x,
        fov_y_deg: fov_y,
        image,
        color: LightColorDesc::Rgb(Vec3::ONE),
        amount: LightAmountDesc::WattsPerSr(2.0),
        projection: Default::default(),
    }))]);
    // forward −y, up −z, so right = forward × up = +x... (−y) × (−z) = +x.
    let (tx, ty) = (
        (fov_x / 2.0).to_radians().tan(),
        (fov_y / 2.0).to_radians().tan(),
    );
    for row in 0..h {
        for col in 0..w {
            for (a, b) in [(0.5, 0.5), (0.1, 0.2), (0.9, 0.85)] {
                let x = tx * (2.0 * (col as f32 + a) / w as f32 - 1.0);
                let y = ty * (1.0 - 2.0 * (row as f32 + b) / h as f32);
                let dir = (Vec3::X * x - Vec3::Z * y - Vec3::Y).normalize();
                let p = pos + dir * (2.0 / -dir.y);
                let d2 = (p - pos).length_squared();
                let e = 2.0 * pixels[(row * w + col) as usize] * (-dir.y) / d2;
                assert_close(
                    rendered(&scene, p),
                    RHO / PI * e,
                    &format!("pixel {col},{row}"),
                );
            }
        }
    }
    // Outside the frustum: dark.
    let outside = pos + Vec3::new(2.0 * tx * 1.05, -2.0, 0.0);
    assert_eq!(rendered(&scene, outside), Vec3::ZERO);
}

#[test]
fn directional_light_gives_e_cos() {
    let dir = Vec3::new(0.3, -1.0, 0.2).normalize();
    let scene = plane_scene(vec![light(LightKindDesc::Directional(
        DirectionalLightDesc {
            direction: dir,
            color: LightColorDesc::Rgb(Vec3::new(1.0, 0.9, 0.8)),
            amount: LightAmountDesc::WattsPerSr(3.0),
        },
    ))]);
    for p in floor_grid() {
        let e = Vec3::new(1.0, 0.9, 0.8) * 3.0 * (-dir.y);
        assert_close(rendered(&scene, p), RHO / PI * e, "directional");
    }
    assert!(scene.lights[0].power() > 0.0);
}

#[test]
fn units_convert_at_683_lm_per_w_and_powers_normalize_by_solid_angle() {
    let white = LightColorDesc::Rgb(Vec3::ONE);
    let point = |amount| {
        let s = plane_scene(vec![light(LightKindDesc::ShapedPoint(ShapedPointDesc {
            position: Vec3::Y,
            color: white,
            amount,
            profile: None,
        }))]);
        match &s.lights[0] {
            Light::Point(p) => p.intensity,
            other => panic!("{other:?}"),
        }
    };
    assert_close(point(LightAmountDesc::Candela(683.0)), Vec3::ONE, "cd");
    assert_close(point(LightAmountDesc::Watts(4.0 * PI)), Vec3::ONE, "W");
    assert_close(
        point(LightAmountDesc::Lumens(683.0 * 4.0 * PI)),
        Vec3::ONE,
        "lm",
    );
    // A photometric amount fixes the luminance, whatever the colour.
    let red = plane_scene(vec![light(LightKindDesc::ShapedPoint(ShapedPointDesc {
        position: Vec3::Y,
        color: LightColorDesc::Rgb(Vec3::new(2.0, 0.5, 0.1)),
        amount: LightAmountDesc::Lumens(1000.0),
        profile: None,
    }))]);
    assert!((red.lights[0].power() * LUMENS_PER_WATT / 1000.0 - 1.0).abs() < 1e-5);
    // Spots and profiles: a power amount is the light's power.
    for falloff in [
        SpotFalloff::Smoothstep,
        SpotFalloff::Mitsuba,
        SpotFalloff::Gltf,
    ] {
        let s = plane_scene(vec![light(LightKindDesc::Spot(SpotLightDesc {
            color: white,
            ..spot_desc(falloff, LightAmountDesc::Lumens(800.0))
        }))]);
        assert!((s.lights[0].power() * LUMENS_PER_WATT / 800.0 - 1.0).abs() < 1e-5);
    }
    let s = plane_scene(vec![light(LightKindDesc::ShapedPoint(ShapedPointDesc {
        position: Vec3::Y,
        color: white,
        amount: LightAmountDesc::Watts(7.0),
        profile: Some(ProfileDesc {
            table: asymmetric_table(),
            nadir: -Vec3::Y,
            c0: Vec3::X,
            span: Span::code(),
        }),
    }))]);
    assert!((s.lights[0].power() / 7.0 - 1.0).abs() < 1e-5);
    // Temperature: a luminance-1 colour, so candela still fix the luminance.
    let s = plane_scene(vec![light(LightKindDesc::ShapedPoint(ShapedPointDesc {
        position: Vec3::Y,
        color: LightColorDesc::Temperature(2700.0),
        amount: LightAmountDesc::Candela(683.0),
        profile: None,
    }))]);
    let Light::Point(p) = &s.lights[0] else {
        panic!()
    };
    assert!((candela_core::math::luminance(p.intensity) - 1.0).abs() < 1e-5);
    assert!(p.intensity.x > p.intensity.z);
}

#[test]
fn bad_lights_are_build_errors() {
    let build_one = |kind| {
        let mut desc = SceneDesc::default();
        desc.lights.push(LightDesc {
            kind,
            span: Span::new("s.toml", 7, 3),
        });
        build(&desc).map(|_| ()).unwrap_err().to_string()
    };
    let spot = spot_desc(SpotFalloff::Smoothstep, LightAmountDesc::WattsPerSr(1.0));
    let e = build_one(LightKindDesc::Spot(SpotLightDesc {
        inner_angle_deg: 50.0,
        ..spot.clone()
    }));
    assert!(
        e.starts_with("s.toml:7:3: inner_angle 50° must lie within 0–45°"),
        "{e}"
    );
    let e = build_one(LightKindDesc::Spot(SpotLightDesc {
        direction: Vec3::ZERO,
        ..spot.clone()
    }));
    assert!(e.contains("direction must not be zero"), "{e}");
    let e = build_one(LightKindDesc::Spot(SpotLightDesc {
        amount: LightAmountDesc::ProfileCandela,
        ..spot.clone()
    }));
    assert!(e.contains("IES profile"), "{e}");
    let e = build_one(LightKindDesc::ShapedPoint(ShapedPointDesc {
        position: Vec3::ZERO,
        color: LightColorDesc::Temperature(-5.0),
        amount: LightAmountDesc::Candela(1.0),
        profile: None,
    }));
    assert!(e.contains("temperature"), "{e}");
    let e = build_one(LightKindDesc::Directional(DirectionalLightDesc {
        direction: -Vec3::Y,
        color: LightColorDesc::Rgb(Vec3::ONE),
        amount: LightAmountDesc::Lumens(1.0),
    }));
    assert!(e.contains("irradiance"), "{e}");
    let e = build_one(LightKindDesc::Projector(ProjectorLightDesc {
        position: Vec3::ZERO,
        direction: -Vec3::Y,
        up: Vec3::Y,
        fov_x_deg: 30.0,
        fov_y_deg: 30.0,
        image: Arc::new(ImageDesc {
            width: 1,
            height: 1,
            pixels: vec![Vec3::ONE],
        }),
        color: LightColorDesc::Rgb(Vec3::ONE),
        amount: LightAmountDesc::WattsPerSr(1.0),
        projection: Default::default(),
    }));
    assert!(e.contains("parallel"), "{e}");
}

/// The IES-shaped triangle: its NEE estimator ⟨L cos θ / pdf⟩ is unbiased for the
/// irradiance ∫ L·I(ω)/I_max·cos θ_l·cos θ/d² dA (computed by a 400 × 400 midpoint rule
/// over the triangle), tested with a z test at α = 10⁻⁴ (|z| < 3.9); its radiance is
/// `le` · I(ω)/I_max and its power A·L·∫ I/I_max cos θ dω.
#[test]
fn ies_shaped_triangle_light_is_unbiased_and_scaled_by_the_profile() {
    let table = asymmetric_table();
    let p = [
        Vec3::new(-0.5, 1.0, -0.5),
        Vec3::new(0.5, 1.0, -0.5),
        Vec3::new(0.0, 1.0, 0.6),
    ];
    let n = -Vec3::Y;
    let profile = LightProfile::new(table.clone(), n, Vec3::X).unwrap();
    let projected = profile.projected_solid_angle();
    let le = Vec3::splat(2.0);
    let tri = TriangleLight::new(p, n, le).with_profile(profile.clone(), projected);
    let w = Vec3::new(0.3, -1.0, 0.2).normalize();
    assert_close(
        tri.radiance(n, Vec2::ZERO, w),
        le * profile.relative(w),
        "radiance",
    );
    assert_eq!(tri.radiance(n, Vec2::ZERO, -w), Vec3::ZERO);
    let expected_power = tri.area * 2.0 * projected;
    assert!((tri.power() - expected_power).abs() < 1e-5 * expected_power);
    assert!(projected > 0.0 && projected < PI);

    let x = Vec3::new(0.7, 0.0, 0.3);
    let ctx = ShadingCtx { p: x, n: Vec3::Y };
    let m = 400;
    let mut reference = 0.0f64;
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let area = tri.area as f64;
    for i in 0..m {
        for j in 0..m - i {
            // Midpoints of the sub-triangles of a regular subdivision (upright ones) and
            // the inverted ones, each of area A/m².
            let mut pts = vec![((i as f32 + 1.0 / 3.0), (j as f32 + 1.0 / 3.0))];
            if i + j + 1 < m {
                pts.push((i as f32 + 2.0 / 3.0, j as f32 + 2.0 / 3.0));
            }
            for (a, b) in pts {
                let q = p[0] + e1 * (a / m as f32) + e2 * (b / m as f32);
                let to = q - x;
                let d2 = to.length_squared();
                let wi = to / d2.sqrt();
                let l = 2.0 * profile.relative(-wi) as f64;
                reference += l * (-wi.dot(n)) as f64 * wi.y as f64 / d2 as f64;
            }
        }
    }
    reference *= area / (m * m) as f64;

    let mut rng = Pcg32::new(7, 0);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    let k = 200_000;
    for _ in 0..k {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let v = Light::Triangle(tri.clone())
            .sample_li(&ctx, u)
            .map_or(0.0, |s| (s.radiance.x * s.wi.y / s.pdf) as f64);
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / k as f64;
    let sd = ((sum2 / k as f64 - mean * mean) / k as f64).sqrt();
    let z = (mean - reference) / sd;
    assert!(z.abs() < 3.9, "mean {mean} vs {reference}, z = {z:.2}");
}
