//! Memory and build time of N instances of an M-triangle mesh, instanced or flattened.
//!
//! ```text
//! cargo run --release -p candela-bench --bin instancing -- [N] [M] [flatten]
//! ```
//!
//! Builds the scene (a grid of N placements of one bumpy sphere of about M triangles),
//! prints the build time, the triangles stored and rendered, the growth of the process's
//! peak resident memory over the build (`VmHWM`, Linux), and closest-hit rays/s on random
//! camera-like rays. Run one configuration per process so that the peaks are its own.

use std::sync::Arc;
use std::time::Instant;

use candela_core::desc::*;
use candela_core::geometry::Ray;
use candela_core::sampler::mix64;
use glam::{Mat4, Quat, Vec2, Vec3};

fn peak_rss_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// A bumpy sphere of 2·rings·segments triangles with normals and uvs.
fn bumpy_sphere(triangles: usize) -> MeshDesc {
    let rings = ((triangles as f64 / 4.0).sqrt() as u32).max(2);
    let segments = (triangles as u32 / (2 * rings)).max(3);
    let mut m = MeshDesc::default();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            let dir = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            m.positions
                .push(dir * (1.0 + 0.1 * (5.0 * phi).sin() * (7.0 * theta).sin()));
            m.normals.push(dir);
            m.uvs.push(Vec2::new(
                j as f32 / segments as f32,
                i as f32 / rings as f32,
            ));
        }
    }
    let row = segments + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b) = (i * row + j, (i + 1) * row + j);
            m.indices.push([a, b, a + 1]);
            m.indices.push([a + 1, b, b + 1]);
        }
    }
    m
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(1000, |a| a.parse().expect("N"));
    let m: usize = args.get(2).map_or(100_000, |a| a.parse().expect("M"));
    let flatten = args.get(3).is_some_and(|a| a == "flatten");

    let mesh = Arc::new(bumpy_sphere(m));
    let mut desc = SceneDesc::default();
    desc.materials
        .push(MaterialDesc::diffuse("white", Vec3::splat(0.5)));
    let side = (n as f64).sqrt().ceil() as usize;
    for k in 0..n {
        let (x, z) = ((k % side) as f32 * 3.0, (k / side) as f32 * 3.0);
        let geometry = if flatten {
            Arc::new(MeshDesc::clone(&mesh))
        } else {
            mesh.clone()
        };
        desc.shapes
            .push(ShapeDesc::mesh(geometry, "white").transformed(
                Mat4::from_scale_rotation_translation(
                    Vec3::splat(1.0 + 0.2 * (k % 3) as f32),
                    Quat::from_rotation_y(k as f32),
                    Vec3::new(x, 0.0, z),
                ),
            ));
    }
    let before = peak_rss_mb();
    let t0 = Instant::now();
    let scene = candela_core::build::build(&desc).expect("builds");
    let build_s = t0.elapsed().as_secs_f64();
    let after = peak_rss_mb();

    // Rays from above the grid's corner towards random points of it (the grid's box from
    // the placements, not the scene's, whose instance boxes are looser).
    let b = candela_core::geometry::Aabb {
        min: Vec3::new(-1.5, -1.5, -1.5),
        max: Vec3::new(3.0 * side as f32, 1.5, 3.0 * n.div_ceil(side) as f32),
    };
    let o = Vec3::new(b.min.x - 5.0, b.max.y + 10.0, b.min.z - 5.0);
    let rays = 200_000;
    let mut hits = 0;
    let t1 = Instant::now();
    for i in 0..rays {
        let u = |k: u64| (mix64(i * 4 + k) >> 40) as f32 / (1u64 << 24) as f32;
        let target = b.min + (b.max - b.min) * Vec3::new(u(0), u(1), u(2));
        hits += scene
            .intersect(&Ray::new(o, target - o), f32::INFINITY)
            .is_some() as u32;
    }
    let trace_s = t1.elapsed().as_secs_f64();
    println!(
        "{} N={n} M={} stored={} rendered={} build={build_s:.3}s peak_rss_growth={:.0}MB \
         peak_rss={after:.0}MB closest_hit={:.2}Mrays/s hits={hits}/{rays}",
        if flatten { "flattened" } else { "instanced" },
        mesh.indices.len(),
        scene.stored_triangle_count(),
        scene.triangle_count(),
        after - before,
        rays as f64 / trace_s / 1e6,
    );
}
