//! What one next-event sample of a flat lamp costs, by area and in solid angle (see
//! `LampSampling`): `sample_li` and `pdf_li` of a unit square and of half of it, 0.6 above
//! 1024 shading points spread under them (every one near, in the sense of
//! `LampSampling::SolidAngle`), 4·10⁶ calls each on one thread.
//!
//! ```text
//! cargo run --release -p candela-bench --bin lamp_sample_cost
//! ```
//!
//! Not part of CI; bench/RESULTS.md quotes it (lamp_sample_cost). Wall time per call, so
//! run it on a quiet machine.

use std::hint::black_box;
use std::time::Instant;

use candela_core::desc::LampSampling;
use candela_core::light::{Light, ParallelogramLight, ShadingCtx, TriangleLight};
use candela_core::sampler::Pcg32;
use glam::{Vec2, Vec3};

const CALLS: usize = 4_000_000;

fn lamps(sampling: LampSampling) -> [(&'static str, Light); 2] {
    let corner = Vec3::new(-0.5, 0.6, -0.5);
    let mut square =
        ParallelogramLight::new(corner, Vec3::X, Vec3::Z, -Vec3::Y, Vec3::ONE).expect("a square");
    square.sampling = sampling;
    let mut triangle = TriangleLight::new(
        [corner, corner + Vec3::X, corner + Vec3::Z],
        -Vec3::Y,
        Vec3::ONE,
    );
    triangle.sampling = sampling;
    [
        ("square", Light::Parallelogram(square)),
        ("triangle", Light::Triangle(triangle)),
    ]
}

fn main() {
    let mut rng = Pcg32::new(1, 1);
    let mut uniform = || rng.uniform_f32();
    let points: Vec<ShadingCtx> = (0..1024)
        .map(|_| ShadingCtx {
            p: Vec3::new(uniform() - 0.5, 0.5 * uniform(), uniform() - 0.5),
            n: Vec3::Y,
        })
        .collect();
    let us: Vec<Vec2> = (0..4096).map(|_| Vec2::new(uniform(), uniform())).collect();
    println!("| lamp | sampling | sample_li ns | pdf_li ns |\n|---|---|--:|--:|");
    for sampling in [LampSampling::Area, LampSampling::SolidAngle] {
        for (name, light) in lamps(sampling) {
            let start = Instant::now();
            let mut seen = Vec::new();
            for i in 0..CALLS {
                let ctx = &points[i % points.len()];
                if let Some(s) = black_box(light.sample_li(ctx, us[i % us.len()])) {
                    if seen.len() < 4096 {
                        seen.push((i % points.len(), s.wi));
                    }
                }
            }
            let sample_ns = start.elapsed().as_secs_f64() * 1e9 / CALLS as f64;
            let start = Instant::now();
            for i in 0..CALLS {
                let (k, wi) = seen[i % seen.len()];
                black_box(light.pdf_li(&points[k], wi));
            }
            let pdf_ns = start.elapsed().as_secs_f64() * 1e9 / CALLS as f64;
            println!("| {name} | {sampling:?} | {sample_ns:.1} | {pdf_ns:.1} |");
        }
    }
}
