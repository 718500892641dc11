//! The environment light in the path tracer: a furnace, irradiance on a plane against
//! numerical integration of the map, equirect against cube map of the same content
//! (Welch), and camera visibility.

use std::f32::consts::PI;

use candela_core::desc::*;
use candela_core::geometry::Ray;
use candela_core::integrator::li;
use candela_core::light::envmap::{cubemap, equirect};
use candela_core::sampler::{IndependentSampler, Sampler};
use candela_core::Scene;
use glam::{Mat3, Mat4, UVec2, Vec2, Vec3};

fn material(name: &str, albedo: Vec3) -> MaterialDesc {
    MaterialDesc::diffuse(name, albedo)
}

fn sphere(center: Vec3, radius: f32, material: &str) -> ShapeDesc {
    ShapeDesc::sphere(center, radius, material)
}

/// A 20 × 20 square in the plane y = 0, facing +y. (Much larger squares lose about 1% of
/// grazing rays to self-intersection: the hit point's error grows with the vertices'
/// magnitude, the ray offset only with the point's.)
fn ground(material: &str) -> ShapeDesc {
    ShapeDesc::new(GeometryDesc::Rectangle, material)
        .transformed(Mat4::from_rotation_x(-PI / 2.0) * Mat4::from_scale(Vec3::splat(10.0)))
}

fn build(
    env: EnvironmentDesc,
    materials: Vec<MaterialDesc>,
    shapes: Vec<ShapeDesc>,
    mis: MisMode,
) -> Scene {
    let desc = SceneDesc {
        materials,
        shapes,
        environment: Some(env),
        render: RenderSettings {
            mis,
            ..Default::default()
        },
        ..Default::default()
    };
    candela_core::build::build(&desc).expect("scene builds")
}

fn env(map: EnvironmentMapDesc) -> EnvironmentDesc {
    EnvironmentDesc {
        map,
        ..Default::default()
    }
}

/// Mean and standard error of `n` one-path estimates along `ray`.
fn estimate(scene: &Scene, ray: Ray, n: u32, seed: u64) -> (Vec3, Vec3) {
    let mut sampler = IndependentSampler::new(seed);
    let (mut sum, mut sum2) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
    let mut rays = 0;
    for i in 0..n {
        sampler.start_pixel_sample(UVec2::new(0, 0), i);
        let l = li(scene, ray, &mut sampler, &mut rays).as_dvec3();
        sum += l;
        sum2 += l * l;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(glam::DVec3::ZERO) * n as f64 / (n - 1) as f64;
    (mean.as_vec3(), (var / n as f64).as_vec3().map(f32::sqrt))
}

fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> Vec3) -> ImageDesc {
    ImageDesc {
        width: w,
        height: h,
        pixels: (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect(),
    }
}

#[test]
fn furnace_diffuse_sphere_in_unit_environment_has_radiance_albedo() {
    // A convex diffuse sphere under radiance 1 from everywhere reflects exactly ρ. Each
    // (map, strategy, direction) is a z-test at |z| < 4.5 (α ≈ 7·10⁻⁶ each, under 10⁻³
    // for all 72); a zero-variance estimate must match to 1e-4.
    let rho = Vec3::new(0.2, 0.5, 0.8);
    let maps = [
        EnvironmentMapDesc::Constant(Vec3::ONE),
        EnvironmentMapDesc::Equirect(image(16, 8, |_, _| Vec3::ONE)),
        EnvironmentMapDesc::Cubemap(Box::new(std::array::from_fn(|_| {
            image(8, 8, |_, _| Vec3::ONE)
        }))),
    ];
    for map in maps {
        for mis in [MisMode::Balance, MisMode::NeeOnly, MisMode::BsdfOnly] {
            let scene = build(
                env(map.clone()),
                vec![material("m", rho)],
                vec![sphere(Vec3::ZERO, 1.0, "m")],
                mis,
            );
            for k in 0..8 {
                let z = -1.0 + (k as f32 + 0.5) / 4.0;
                let phi = k as f32 * 2.4;
                let r = (1.0 - z * z).sqrt();
                let n = Vec3::new(r * phi.cos(), z, r * phi.sin());
                let (mean, se) = estimate(&scene, Ray::new(3.0 * n, -n), 2048, k);
                let zs = (mean - rho) / se.max(Vec3::splat(1e-4 / 4.5));
                assert!(
                    zs.abs().max_element() < 4.5,
                    "{mis:?}: {mean} ± {se} against {rho} at {n}"
                );
            }
        }
    }
}

/// The sky of the irradiance and Welch tests: smooth, coloured, with a bright lobe.
fn sky(d: Vec3) -> Vec3 {
    let a = Vec3::new(0.3, 0.8, -0.5).normalize();
    Vec3::new(0.2, 0.3, 0.5) * (1.2 + d.y) + Vec3::new(3.0, 2.0, 1.0) * d.dot(a).max(0.0).powi(4)
}

fn sky_equirect(w: u32, h: u32, sun: Option<Vec3>) -> ImageDesc {
    let cos_sun = 0.5f32.to_radians().cos();
    image(w, h, |x, y| {
        let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
        let d = equirect::uv_to_direction(uv);
        let s = sun.map_or(0.0, |s| if d.dot(s) > cos_sun { 1e4 } else { 0.0 });
        sky(d) + Vec3::splat(s)
    })
}

#[test]
fn irradiance_on_a_diffuse_plane_matches_numerical_integration() {
    // L_o = ρ/π · E, E = ∫ L(d) max(0, d·n) dω integrated from the bilinear map on a
    // grid 4× finer than its texels. Tolerance: |z| < 4 per channel (α ≈ 6·10⁻⁵ each)
    // plus 0.2% for the quadrature.
    let (w, h) = (360, 180);
    let sun = Vec3::new(0.5, 0.6, -0.4).normalize();
    let img = sky_equirect(w, h, Some(sun));
    let lookup = candela_core::light::envmap::Image::from_desc(&img);
    let rho = 0.6;
    for rot_deg in [0.0f32, 30.0] {
        let rotation = Mat3::from_rotation_x(rot_deg.to_radians());
        let n_map = rotation.transpose() * Vec3::Y; // the plane's normal in the map's frame
        let (fw, fh) = (4 * w, 4 * h);
        let mut e = glam::DVec3::ZERO;
        for j in 0..fh {
            let v = (j as f32 + 0.5) / fh as f32;
            let sin_t = (PI * v).sin();
            for i in 0..fw {
                let uv = Vec2::new((i as f32 + 0.5) / fw as f32, v);
                let c = equirect::uv_to_direction(uv).dot(n_map).max(0.0);
                if c > 0.0 {
                    e += (lookup.bilinear(uv, true) * c * sin_t).as_dvec3();
                }
            }
        }
        let e = (e * 2.0 * (PI as f64).powi(2) / (fw * fh) as f64).as_vec3();
        let expected = e * rho / PI;
        let scene = build(
            EnvironmentDesc {
                rotation,
                ..env(EnvironmentMapDesc::Equirect(img.clone()))
            },
            vec![material("m", Vec3::splat(rho))],
            vec![ground("m")],
            MisMode::Balance,
        );
        let ray = Ray::new(
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.1, -1.0, 0.05).normalize(),
        );
        let (mean, se) = estimate(&scene, ray, 100_000, 42);
        let err = (mean - expected).abs() - 0.002 * expected;
        assert!(
            (err / se).max_element() < 4.0,
            "rotation {rot_deg}°: {mean} ± {se}, numerical {expected}"
        );
    }
}

#[test]
fn equirect_and_cubemap_of_the_same_sky_render_the_same() {
    // The sky sampled at texel centres into a 512×256 panorama and six 128² faces.
    // Welch's t on each ray's luminance estimates, |t| < 4 (α ≈ 6·10⁻⁵ per ray, 5·10⁻⁴
    // for all 8); resampling differences are far below the noise.
    let pano = sky_equirect(512, 256, None);
    let n = 128;
    let faces: [ImageDesc; 6] = std::array::from_fn(|f| {
        image(n, n, |x, y| {
            let st = Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            sky(cubemap::face_to_direction(f, st))
        })
    });
    let rot = Mat3::from_rotation_y(0.4);
    let scenes = [
        EnvironmentMapDesc::Equirect(pano),
        EnvironmentMapDesc::Cubemap(Box::new(faces)),
    ]
    .map(|m| {
        build(
            EnvironmentDesc {
                rotation: rot,
                ..env(m)
            },
            vec![
                material("m", Vec3::splat(0.7)),
                material("g", Vec3::new(0.4, 0.5, 0.3)),
            ],
            vec![sphere(Vec3::new(0.0, 1.0, 0.0), 1.0, "m"), ground("g")],
            MisMode::Balance,
        )
    });
    let lum = |c: Vec3| candela_core::math::luminance(c);
    for k in 0..8 {
        let target = Vec3::new(-1.5 + 0.4 * k as f32, (k % 3) as f32 * 0.7, 0.3);
        let o = Vec3::new(0.0, 2.5, 5.0);
        let ray = Ray::new(o, (target - o).normalize());
        let [(m1, s1), (m2, s2)] = [0, 1].map(|i| estimate(&scenes[i], ray, 20_000, 100 + k));
        let t = (lum(m1) - lum(m2)) / (lum(s1).powi(2) + lum(s2).powi(2)).sqrt().max(1e-6);
        assert!(
            t.abs() < 4.0,
            "ray {k}: equirect {m1} ± {s1}, cube map {m2} ± {s2}, t = {t}"
        );
    }
}

#[test]
fn hidden_environment_lights_the_scene_but_the_camera_sees_the_background() {
    let bg = Vec3::new(0.1, 0.2, 0.3);
    let scene = build(
        EnvironmentDesc {
            visible: false,
            background: bg,
            ..env(EnvironmentMapDesc::Constant(Vec3::splat(2.0)))
        },
        vec![material("m", Vec3::splat(0.5))],
        vec![sphere(Vec3::ZERO, 1.0, "m")],
        MisMode::Balance,
    );
    let (miss, _) = estimate(&scene, Ray::new(Vec3::new(0.0, 0.0, 3.0), Vec3::Y), 16, 0);
    assert_eq!(miss, bg);
    let (hit, se) = estimate(
        &scene,
        Ray::new(Vec3::new(0.0, 0.0, 3.0), -Vec3::Z),
        4096,
        0,
    );
    assert!(
        ((hit - Vec3::ONE) / se.max(Vec3::splat(1e-5)))
            .abs()
            .max_element()
            < 4.5,
        "{hit} ± {se}"
    );
}

#[test]
fn environment_power_follows_scene_size_and_drives_light_selection() {
    // Φ = π r² ∫ L dω: a unit sky around a scene of bounding radius r gives 4π² r².
    let small = build(
        env(EnvironmentMapDesc::Constant(Vec3::ONE)),
        vec![material("m", Vec3::ONE)],
        vec![sphere(Vec3::ZERO, 1.0, "m")],
        MisMode::Balance,
    );
    let r = 3f32.sqrt(); // half the diagonal of the sphere's box
    let p = small.lights[0].power();
    assert!((p - 4.0 * PI * PI * r * r).abs() < 1e-3 * p, "{p}");
    assert!(small.lights[0].is_infinite());
    assert_eq!(small.infinite_lights.len(), 1);

    // With a point light beside it, the power sampler picks each in proportion.
    let mut desc = SceneDesc {
        materials: vec![material("m", Vec3::ONE)],
        shapes: vec![sphere(Vec3::ZERO, 1.0, "m")],
        environment: Some(env(EnvironmentMapDesc::Constant(Vec3::ONE))),
        render: RenderSettings {
            light_sampler: LightSamplerKind::Power,
            ..Default::default()
        },
        ..Default::default()
    };
    desc.lights.push(LightDesc::point(
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::splat(10.0),
    ));
    let scene = candela_core::build::build(&desc).unwrap();
    let powers: Vec<f32> = scene.lights.iter().map(|l| l.power()).collect();
    let ctx = candela_core::light::ShadingCtx {
        p: Vec3::ZERO,
        n: Vec3::Y,
    };
    for (i, l) in scene.lights.iter().enumerate() {
        let pmf = scene
            .light_sampler
            .pmf(&ctx, candela_core::light::LightId(i as u32));
        let share = l.power() / powers.iter().sum::<f32>();
        assert!(
            (pmf - share).abs() < 1e-5,
            "light {i}: pmf {pmf}, share {share}"
        );
    }
}

#[test]
fn bad_environment_descriptions_are_build_errors() {
    let cases: Vec<(EnvironmentDesc, &str)> = vec![
        (
            EnvironmentDesc {
                strength: f32::NAN,
                ..Default::default()
            },
            "strength",
        ),
        (
            EnvironmentDesc {
                rotation: Mat3::from_diagonal(Vec3::new(1.0, 2.0, 1.0)),
                ..Default::default()
            },
            "rotation",
        ),
        (
            env(EnvironmentMapDesc::Equirect(ImageDesc::default())),
            "empty",
        ),
        (
            env(EnvironmentMapDesc::Equirect(ImageDesc {
                width: 2,
                height: 1,
                pixels: vec![Vec3::ONE],
            })),
            "pixels",
        ),
        (
            env(EnvironmentMapDesc::Equirect(image(2, 1, |_, _| {
                Vec3::splat(-1.0)
            }))),
            "negative",
        ),
        (
            env(EnvironmentMapDesc::Cubemap(Box::new(std::array::from_fn(
                |f| image(4, if f == 2 { 3 } else { 4 }, |_, _| Vec3::ONE),
            )))),
            "square",
        ),
    ];
    for (e, what) in cases {
        let desc = SceneDesc {
            environment: Some(EnvironmentDesc {
                span: Span::new("sky.toml", 3, 1),
                ..e
            }),
            ..Default::default()
        };
        let err = candela_core::build::build(&desc).expect_err(what);
        assert!(err.to_string().starts_with("sky.toml:3:1: "), "{err}");
        assert!(err.message.contains(what), "{err}");
    }
}
