//! Unbiasedness of every light sampler on a scene of 64 lights whose powers are
//! log-uniform over three decades: per-tile means of each sampler's render agree with a
//! long render of the uniform sampler (Welch's z on tile means), with MIS on.

use std::sync::Arc;

use candela_core::desc::*;
use candela_core::integrator::li;
use candela_core::math::luminance;
use candela_core::sampler::{IndependentSampler, Pcg32, Sampler};
use glam::{Mat4, UVec2, Vec2, Vec3};
use rayon::prelude::*;

const RES: u32 = 24;
const TILE: u32 = 6;

fn scene(kind: LightSamplerKind, mis: MisMode, seed: u64) -> candela_core::Scene {
    let mut d = SceneDesc {
        render: RenderSettings {
            width: RES,
            height: RES,
            spp: 1,
            max_depth: 2,
            seed,
            mis,
            light_sampler: kind,
            ris_candidates: 4,
            ..Default::default()
        },
        ..Default::default()
    };
    d.camera = CameraDesc {
        position: Vec3::new(0.0, 6.0, 7.0),
        look_at: Vec3::new(0.0, 0.0, 0.0),
        fov_y_deg: 60.0,
        ..Default::default()
    };
    d.materials
        .push(MaterialDesc::diffuse("white", Vec3::splat(0.7)));
    let shape = |geometry, transform, emission| {
        ShapeDesc::new(geometry, "white")
            .transformed(transform)
            .with_emission(emission)
    };
    // Floor, and two boxes that cast shadows.
    d.shapes.push(shape(
        GeometryDesc::Rectangle,
        Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2) * Mat4::from_scale(Vec3::splat(6.0)),
        None,
    ));
    for (x, z) in [(-1.5f32, 0.5f32), (1.5, -1.0)] {
        d.shapes.push(shape(
            GeometryDesc::Cube,
            Mat4::from_translation(Vec3::new(x, 0.5, z)) * Mat4::from_scale(Vec3::splat(0.5)),
            None,
        ));
    }
    let mut rng = Pcg32::new(2024, 7);
    let mut u = move || rng.uniform_f32();
    for i in 0..64 {
        let c = Vec3::new(10.0 * u() - 5.0, 1.2 + 2.0 * u(), 10.0 * u() - 5.0);
        let color = Vec3::new(0.3 + u(), 0.3 + u(), 0.3 + u()) * 10f32.powf(3.0 * u()) * 0.05;
        match i % 3 {
            0 => {
                // A small downward-facing triangle, tilted at random.
                // Large enough (~0.5 m²) that BSDF-sampled rays often hit them, so that
                // the MIS weights matter.
                let a = Vec3::new(0.6 * u() - 0.3, 0.0, 0.6 * u() - 0.3);
                let positions = vec![c, c + Vec3::new(1.0, 0.3 * u(), 0.0) + a, c + Vec3::Z];
                let mesh = MeshDesc {
                    positions,
                    indices: vec![[0, 1, 2]],
                    ..Default::default()
                };
                // Wound so that the normal faces down (towards the floor) for most.
                d.shapes.push(
                    shape(
                        GeometryDesc::Mesh(Arc::new(mesh)),
                        Mat4::IDENTITY,
                        Some(color * 2.0),
                    )
                    .with_flipped_normals(u() < 0.8),
                );
            }
            1 => d.shapes.push(shape(
                GeometryDesc::Sphere {
                    center: c,
                    radius: 0.05 + 0.05 * u(),
                },
                Mat4::IDENTITY,
                Some(color * 10.0),
            )),
            _ => d.lights.push(LightDesc::point(c, color)),
        }
    }
    let s = candela_core::build::build(&d).unwrap();
    assert_eq!(s.lights.len(), 64);
    s
}

/// Per tile: (mean, variance of the mean) of the tile's average luminance, over `spp`
/// independent samples per pixel.
fn tile_stats(kind: LightSamplerKind, mis: MisMode, spp: u32, seed: u64) -> Vec<(f64, f64)> {
    let scene = scene(kind, mis, seed);
    let tiles = RES / TILE;
    (0..tiles * tiles)
        .into_par_iter()
        .map(|t| {
            let (tx, ty) = (t % tiles * TILE, t / tiles * TILE);
            let mut sampler = IndependentSampler::new(seed);
            let mut rays = 0u64;
            let (mut s1, mut s2) = (0.0f64, 0.0f64);
            for s in 0..spp {
                let mut v = 0.0f64;
                for y in ty..ty + TILE {
                    for x in tx..tx + TILE {
                        sampler.start_pixel_sample(UVec2::new(x, y), s);
                        let film = Vec2::new(x as f32, y as f32) + sampler.get_pixel_2d();
                        let l = li(
                            &scene,
                            scene.camera.generate_ray(film),
                            &mut sampler,
                            &mut rays,
                        );
                        v += luminance(l) as f64;
                    }
                }
                v /= (TILE * TILE) as f64;
                s1 += v;
                s2 += v * v;
            }
            let n = spp as f64;
            let mean = s1 / n;
            (mean, (s2 / n - mean * mean).max(0.0) / (n - 1.0))
        })
        .collect()
}

#[test]
#[ignore = "slow: ~13M paths, ~15 s in release on 2 idle cores; run with --release -- --include-ignored"]
fn every_sampler_agrees_with_a_long_uniform_render() {
    let reference = tile_stats(LightSamplerKind::Uniform, MisMode::Balance, 8192, 1);
    // 9 runs × 16 tiles = 144 two-sided tests at α = 5·10⁻⁵ each (|z| < 4.06):
    // family-wise false alarm rate under 1%.
    let z_max = 4.06;
    // Power of the test: the smallest relative bias of a tile mean it would flag.
    let detectable = reference
        .iter()
        .map(|&(m, v)| z_max * (2.0 * v).sqrt() / m)
        .fold(f64::INFINITY, f64::min);
    eprintln!("smallest detectable relative bias (equal variances): {detectable:.4}");
    // Every sampler with the balance heuristic; the RIS samplers, whose MIS weights use
    // a surrogate pmf, also with the power heuristic and with NEE alone.
    let mut runs: Vec<(LightSamplerKind, MisMode)> = [
        LightSamplerKind::Power,
        LightSamplerKind::Array,
        LightSamplerKind::Ris,
        LightSamplerKind::Bvh,
        LightSamplerKind::RisBvh,
    ]
    .map(|k| (k, MisMode::Balance))
    .to_vec();
    for k in [LightSamplerKind::Ris, LightSamplerKind::RisBvh] {
        runs.push((k, MisMode::Power));
        runs.push((k, MisMode::NeeOnly));
    }
    for (kind, mis) in runs {
        let stats = tile_stats(kind, mis, 2048, 2);
        let mut worst: f64 = 0.0;
        let mut var_ratio = 0.0;
        for (t, (&(m, v), &(mr, vr))) in stats.iter().zip(&reference).enumerate() {
            let z = (m - mr) / (v + vr).sqrt();
            worst = worst.max(z.abs());
            var_ratio += v * 2048.0 / (vr * 8192.0) / reference.len() as f64;
            assert!(
                z.abs() < z_max,
                "{kind:?} {mis:?} tile {t}: {m} vs {mr}, z = {z}"
            );
        }
        eprintln!(
            "{kind:?} {mis:?}: max |z| = {worst:.2}, variance vs uniform (same spp) = {var_ratio:.3}"
        );
    }
}
