//! The many-lights benchmark (run by `bench/many_lights/run.sh`, not by CI).
//!
//! 1. Build cost of the alias table, the light array and the light BVH for 10⁶ emissive
//!    triangles on 2 threads, with their memory.
//! 2. Two scenes rendered at equal time with every light sampler, relMSE against a long
//!    reference: a floor with boxes under a grid of 1024 small lights of random colour
//!    and power, and a long street lit by 10⁴+ emissive triangles, most far from most
//!    points. 3. The RIS candidate count swept on both scenes at equal time.
//!
//! `cargo run --release -p candela-bench --bin many_lights -- [SECONDS]`
//! (seconds per equal-time render, default 3; the reference takes 8×).

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use candela_bench::cpu_seconds;
use candela_core::desc::*;
use candela_core::film::Film;
use candela_core::integrator::render;
use candela_core::light::{Light, TriangleLight};
use candela_core::light_sampler::LightSampler;
use candela_core::math::luminance;
use candela_core::sampler::Pcg32;
use candela_core::Scene;
use glam::{Mat4, Vec3};

const KINDS: [(LightSamplerKind, &str); 6] = [
    (LightSamplerKind::Uniform, "uniform"),
    (LightSamplerKind::Power, "power"),
    (LightSamplerKind::Array, "array"),
    (LightSamplerKind::Ris, "ris"),
    (LightSamplerKind::Bvh, "bvh"),
    (LightSamplerKind::RisBvh, "ris-bvh"),
];

fn build_cost() {
    let n = 1_000_000;
    let mut rng = Pcg32::new(1, 1);
    let mut u = move || rng.uniform_f32();
    let t0 = Instant::now();
    let lights: Vec<Light> = (0..n)
        .map(|i| {
            let c = Vec3::new((i % 1000) as f32, 10.0 * u(), (i / 1000) as f32);
            let n = Vec3::new(u() - 0.5, -1.0, u() - 0.5).normalize();
            let t = n.cross(Vec3::X).normalize() * 0.3;
            let b = n.cross(t);
            let le = Vec3::new(u(), u(), u()) * 10f32.powf(2.0 * u());
            Light::Triangle(TriangleLight::new([c, c + t, c + b], n, le))
        })
        .collect();
    println!(
        "build cost, {n} emissive triangles, 2 threads (light list made in {:.2} s)",
        t0.elapsed().as_secs_f64()
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    pool.install(|| {
        for (kind, name) in [
            (LightSamplerKind::Power, "alias table"),
            (LightSamplerKind::Array, "light array"),
            (LightSamplerKind::Bvh, "light BVH"),
        ] {
            let (t, cpu) = (Instant::now(), cpu_seconds());
            let s = LightSampler::new(kind, 8, &lights);
            let secs = t.elapsed().as_secs_f64();
            let cpu = cpu_seconds() - cpu;
            let bytes = match &s {
                LightSampler::Power(a) => a.len() * 12,
                LightSampler::Array(a) => a.memory_bytes(),
                LightSampler::Bvh(b) => b.memory_bytes(),
                _ => 0,
            };
            println!(
                "  {name:12} {secs:6.3} s wall, {cpu:6.2} s CPU, {:7.1} MB",
                bytes as f64 / (1 << 20) as f64
            );
        }
    });
}

fn material(d: &mut SceneDesc) {
    d.materials
        .push(MaterialDesc::diffuse("white", Vec3::splat(0.6)));
}

fn shape(geometry: GeometryDesc, transform: Mat4, emission: Option<Vec3>) -> ShapeDesc {
    ShapeDesc::new(geometry, "white")
        .transformed(transform)
        .with_emission(emission)
}

/// A downward-facing quad of half-size `h` at `c` (two triangle lights).
fn lamp(c: Vec3, h: f32, le: Vec3) -> ShapeDesc {
    let t = Mat4::from_translation(c)
        * Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2)
        * Mat4::from_scale(Vec3::splat(h));
    shape(GeometryDesc::Rectangle, t, Some(le))
}

fn settings(width: u32, height: u32) -> RenderSettings {
    RenderSettings {
        width,
        height,
        spp: 1,
        max_depth: 3,
        ..Default::default()
    }
}

/// A 20×20 floor with boxes under a 32×32 grid of small lamps (1024 lights, 2048
/// triangles) of random colour and log-uniform power over two decades.
fn grid_scene() -> SceneDesc {
    let mut d = SceneDesc {
        render: settings(160, 120),
        ..Default::default()
    };
    material(&mut d);
    d.camera = CameraDesc {
        position: Vec3::new(0.0, 7.0, 12.0),
        look_at: Vec3::new(0.0, 0.0, 0.0),
        fov_y_deg: 55.0,
        ..Default::default()
    };
    let floor =
        Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2) * Mat4::from_scale(Vec3::splat(10.0));
    d.shapes.push(shape(GeometryDesc::Rectangle, floor, None));
    let mut rng = Pcg32::new(3, 3);
    let mut u = move || rng.uniform_f32();
    for _ in 0..12 {
        let c = Vec3::new(16.0 * u() - 8.0, 0.0, 16.0 * u() - 8.0);
        let s = Vec3::new(0.3 + 0.7 * u(), 0.3 + 1.5 * u(), 0.3 + 0.7 * u());
        let t = Mat4::from_translation(c + Vec3::Y * s.y) * Mat4::from_scale(s);
        d.shapes.push(shape(GeometryDesc::Cube, t, None));
    }
    for i in 0..32 {
        for j in 0..32 {
            let c = Vec3::new(-9.7 + i as f32 * 0.625, 4.0, -9.7 + j as f32 * 0.625);
            let le = Vec3::new(0.2 + u(), 0.2 + u(), 0.2 + u()) * 10f32.powf(2.0 * u()) * 2.0;
            d.shapes.push(lamp(c, 0.08, le));
        }
    }
    d
}

/// A street 400 long and 10 wide between two walls, lit by 6000 small lamps (12 000
/// emissive triangles) along both walls; the camera stands near one end, so most lamps
/// are far from most shading points.
fn street_scene() -> SceneDesc {
    let mut d = SceneDesc {
        render: settings(192, 96),
        ..Default::default()
    };
    material(&mut d);
    d.camera = CameraDesc {
        position: Vec3::new(0.0, 2.0, 195.0),
        look_at: Vec3::new(0.0, 1.5, 150.0),
        fov_y_deg: 50.0,
        ..Default::default()
    };
    let half = |s: Vec3| Mat4::from_scale(s);
    let floor =
        Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2) * half(Vec3::new(5.0, 200.0, 1.0));
    d.shapes.push(shape(GeometryDesc::Rectangle, floor, None));
    for side in [-1.0f32, 1.0] {
        let wall = Mat4::from_translation(Vec3::new(side * 5.0, 4.0, 0.0))
            * Mat4::from_rotation_y(-side * std::f32::consts::FRAC_PI_2)
            * half(Vec3::new(200.0, 4.0, 1.0));
        d.shapes.push(shape(GeometryDesc::Rectangle, wall, None));
    }
    let mut rng = Pcg32::new(5, 5);
    let mut u = move || rng.uniform_f32();
    for k in 0..3000 {
        for side in [-1.0f32, 1.0] {
            let z = -200.0 + (k as f32 + u()) * (400.0 / 3000.0);
            let c = Vec3::new(side * 4.7, 1.0 + 6.0 * u(), z);
            let le = Vec3::new(0.3 + u(), 0.3 + u(), 0.3 + u()) * 10f32.powf(2.0 * u()) * 4.0;
            d.shapes.push(lamp(c, 0.1, le));
        }
    }
    d
}

fn scene_with(desc: &SceneDesc, kind: LightSamplerKind, candidates: u32, seed: u64) -> Scene {
    let mut d = desc.clone();
    d.render.light_sampler = kind;
    d.render.ris_candidates = candidates;
    d.render.seed = seed;
    candela_core::build::build(&d).expect("benchmark scene builds")
}

/// Renders one sample per pixel at a time until `seconds` have passed.
fn render_for(scene: &Scene, seconds: f64) -> (Film, u32) {
    let cancel = AtomicBool::new(false);
    let mut film = Film::new(scene.settings.width, scene.settings.height);
    let start = Instant::now();
    let mut spp = 0;
    while start.elapsed().as_secs_f64() < seconds {
        let r = render(scene, spp..spp + 1, &cancel, &|_| {});
        film.merge(&r.film);
        spp += 1;
    }
    (film, spp)
}

/// Mean over pixels of (x − ref)² / (ref² + 10⁻²), on luminance.
fn rel_mse(film: &Film, reference: &[f32]) -> f64 {
    let img = film.resolve();
    img.iter()
        .zip(reference)
        .map(|(x, &r)| {
            let d = (luminance(*x) - r) as f64;
            d * d / ((r * r) as f64 + 1e-2)
        })
        .sum::<f64>()
        / img.len() as f64
}

fn main() {
    let arg = std::env::args().nth(1);
    build_cost();
    if arg.as_deref() == Some("build") {
        return;
    }
    let seconds: f64 = arg.and_then(|s| s.parse().ok()).unwrap_or(3.0);
    for (name, desc) in [
        ("grid (1024 lamps)", grid_scene()),
        ("street (12k triangles)", street_scene()),
    ] {
        let t = Instant::now();
        let reference_scene = scene_with(&desc, LightSamplerKind::Bvh, 8, 999);
        println!(
            "\n{name}: {} lights, built in {:.2} s; reference: bvh, {:.0} s",
            reference_scene.lights.len(),
            t.elapsed().as_secs_f64(),
            8.0 * seconds
        );
        let (rf, rspp) = render_for(&reference_scene, 8.0 * seconds);
        let reference: Vec<f32> = rf.resolve().iter().map(|c| luminance(*c)).collect();
        println!("  reference spp {rspp}");
        println!("  {:8} {:>6} {:>10}", "sampler", "spp", "relMSE");
        for (kind, kname) in KINDS {
            let scene = scene_with(&desc, kind, DEFAULT_RIS_CANDIDATES, 1);
            let (film, spp) = render_for(&scene, seconds);
            println!("  {kname:8} {spp:6} {:10.5}", rel_mse(&film, &reference));
        }
        for (kind, kname) in [
            (LightSamplerKind::Ris, "ris"),
            (LightSamplerKind::RisBvh, "ris-bvh"),
        ] {
            println!("  {kname} candidates at equal time:");
            for m in [1, 2, 4, 8, 16] {
                let scene = scene_with(&desc, kind, m, 1);
                let (film, spp) = render_for(&scene, seconds);
                println!("  M = {m:2}   {spp:6} {:10.5}", rel_mse(&film, &reference));
            }
        }
    }
}
