//! Benchmark of environment-light sampling strategies (issue 12): a sun-and-sky scene
//! rendered at equal spp with BSDF (cosine) sampling only, uniform-sphere NEE only,
//! importance-sampled NEE only, and importance-sampled NEE with MIS (balance heuristic),
//! each compared with a long MIS reference by relMSE = mean((x − ref)² / (ref² + 10⁻²)).
//!
//! Not part of CI. Run it through `bench/env_mis.sh [spp] [reference spp]`.
//!
//! The sky is synthetic (no I/O in the core): a 1° sun of 10⁴ times the sky's radiance
//! over a blue gradient, on a 1024 × 512 panorama. The scene has a ground square and
//! three diffuse spheres (the core has only diffuse BSDFs so far; metal and glass spheres
//! belong here once the materials branch lands).

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use candela_bench::rel_mse;
use candela_core::desc::*;
use candela_core::light::envmap::equirect;
use candela_core::light::{EnvironmentSampling, Light};
use candela_core::Scene;
use glam::{Mat4, Vec2, Vec3};

fn sky(w: u32, h: u32) -> ImageDesc {
    let sun = Vec3::new(0.5, 0.45, -0.6).normalize();
    let cos_sun = 0.5f32.to_radians().cos();
    let mut pixels = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let mut cover = 0.0;
            for k in 0..16 {
                let uv = Vec2::new(
                    (x as f32 + (k % 4) as f32 / 4.0 + 0.125) / w as f32,
                    (y as f32 + (k / 4) as f32 / 4.0 + 0.125) / h as f32,
                );
                if equirect::uv_to_direction(uv).dot(sun) > cos_sun {
                    cover += 1.0 / 16.0;
                }
            }
            let d = equirect::uv_to_direction(Vec2::new(
                (x as f32 + 0.5) / w as f32,
                (y as f32 + 0.5) / h as f32,
            ));
            let sky = Vec3::new(0.25, 0.45, 0.9) * (0.4 + 0.6 * d.y.max(0.0))
                + Vec3::splat(0.1) * (1.0 - d.y.abs());
            pixels.push(sky + Vec3::new(1.0, 0.95, 0.85) * 1e4 * 0.5 * cover);
        }
    }
    ImageDesc {
        width: w,
        height: h,
        pixels,
    }
}

fn scene(width: u32, height: u32) -> SceneDesc {
    let mat = |name: &str, albedo: Vec3| MaterialDesc::diffuse(name, albedo);
    let shape = |geometry, material: &str, transform| {
        ShapeDesc::new(geometry, material).transformed(transform)
    };
    let sphere = |x: f32, r: f32, m: &str| {
        shape(
            GeometryDesc::Sphere {
                center: Vec3::new(x, r, 0.0),
                radius: r,
            },
            m,
            Mat4::IDENTITY,
        )
    };
    SceneDesc {
        camera: CameraDesc {
            position: Vec3::new(0.0, 1.5, 5.0),
            look_at: Vec3::new(0.0, 0.6, 0.0),
            fov_y_deg: 40.0,
            ..Default::default()
        },
        materials: vec![
            mat("ground", Vec3::splat(0.4)),
            mat("red", Vec3::new(0.7, 0.2, 0.1)),
            mat("white", Vec3::splat(0.8)),
        ],
        shapes: vec![
            shape(
                GeometryDesc::Rectangle,
                "ground",
                Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2)
                    * Mat4::from_scale(Vec3::splat(10.0)),
            ),
            sphere(-1.3, 0.6, "red"),
            sphere(0.0, 0.6, "white"),
            sphere(1.3, 0.6, "ground"),
        ],
        environment: Some(EnvironmentDesc {
            map: EnvironmentMapDesc::Equirect(sky(1024, 512)),
            ..Default::default()
        }),
        render: RenderSettings {
            width,
            height,
            max_depth: 4,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn render(
    desc: &SceneDesc,
    mis: MisMode,
    sampling: EnvironmentSampling,
    spp: u32,
    seed: u64,
) -> (Vec<Vec3>, f64) {
    let mut desc = desc.clone();
    desc.render.mis = mis;
    desc.render.seed = seed;
    let mut scene: Scene = candela_core::build::build(&desc).expect("scene builds");
    for l in &mut scene.lights {
        if let Light::Environment(env) = l {
            env.sampling = sampling;
        }
    }
    let t = Instant::now();
    let r = candela_core::integrator::render(&scene, 0..spp, &AtomicBool::new(false), &|_| {});
    (r.film.resolve(), t.elapsed().as_secs_f64())
}

fn main() {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("a number"))
        .collect();
    let spp = args.first().copied().unwrap_or(16);
    let ref_spp = args.get(1).copied().unwrap_or(1024);
    let desc = scene(160, 90);
    let (reference, t_ref) = render(
        &desc,
        MisMode::Balance,
        EnvironmentSampling::Importance,
        ref_spp,
        999,
    );
    println!("reference: MIS, {ref_spp} spp, {t_ref:.1} s");
    let strategies = [
        (
            "BSDF (cosine) sampling only",
            MisMode::BsdfOnly,
            EnvironmentSampling::Importance,
        ),
        (
            "uniform-sphere NEE only",
            MisMode::NeeOnly,
            EnvironmentSampling::Uniform,
        ),
        (
            "importance-sampled NEE only",
            MisMode::NeeOnly,
            EnvironmentSampling::Importance,
        ),
        (
            "importance-sampled NEE + MIS",
            MisMode::Balance,
            EnvironmentSampling::Importance,
        ),
    ];
    let mut results = Vec::new();
    for (name, mis, sampling) in strategies {
        let (img, t) = render(&desc, mis, sampling, spp, 1);
        let e = rel_mse(&img, &reference);
        println!("{name:<30} {spp:>5} spp  relMSE {e:.4e}  {t:.2} s");
        results.push(e);
    }
    let best = results[3];
    println!(
        "relMSE ratios to MIS: cosine {:.1}x, uniform NEE {:.1}x, importance NEE {:.2}x",
        results[0] / best,
        results[1] / best,
        results[2] / best
    );
}
