//! The ray-traversal benchmark behind `bench/traversal.sh` (not run by CI).
//!
//! `traversal rays SCENE OUT_DIR [RAYS]` makes a triangle soup and diffuse-bounce rays and
//! times Candela's closest-hit and any-hit queries on them, single-threaded:
//! - `SCENE` is `cornell` (scenes/cornell.toml, its camera), `room` (a generated room of
//!   16 displaced spheres, 589 836 triangles, seen from inside) or `mixed` (a coarser room
//!   with analytic spheres and alpha-masked triangles mixed into its leaf blocks: Candela
//!   only, as embreex has only triangles);
//! - rays: one primary ray per jittered pixel sample, and from each primary hit a
//!   cosine-distributed bounce ray about the geometric normal, origin offset as the
//!   renderer does; only the bounce rays are timed and written.
//!
//! OUT_DIR receives `tris.f32` (9 floats a triangle), `rays.f32` (origin, direction),
//! `candela_hits.bin` (per ray: u32 triangle or u32::MAX, f32 t) for
//! `bench/traversal.py`, which traces the same rays with Embree and compares.
//!
//! `CANDELA_SIMD=scalar|sse|avx2` forces the kernels (default: the best the CPU has; the
//! JSON line says which ran), `CANDELA_NODES=full|quantized` the BVH's node layout and
//! `CANDELA_LEAVES=inline|indexed` its leaf layout (default: the library's; indexed
//! leaves here get three vertices of their own a triangle, stored in leaf order).
//!
//! `traversal build [TRIANGLES]` times the BVH build of a generated displaced-sphere mesh
//! (default 10⁶ triangles) on the rayon pool (`RAYON_NUM_THREADS=2` for two cores).

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use candela_bench::cpu_seconds;
use candela_core::accel::{Accel, AccelLayout, LeafLayout, NodeLayout, PacketMode, Shape, Simd};
use candela_core::geometry::{Ray, TriangleHit};
use candela_core::math::{offset_ray_origin, Frame};
use candela_core::sampler::Pcg32;
use candela_core::sampling::sample_cosine_hemisphere;
use glam::{Vec2, Vec3};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("rays") if args.len() >= 3 => {
            let rays = args.get(3).map_or(1 << 20, |s| s.parse().expect("RAYS"));
            rays_bench(&args[1], Path::new(&args[2]), rays);
        }
        Some("build") => {
            let n = args
                .get(1)
                .map_or(1_000_000, |s| s.parse().expect("TRIANGLES"));
            build_bench(n);
        }
        _ => {
            eprintln!(
                "usage: traversal rays cornell|room OUT_DIR [RAYS] | traversal build [TRIANGLES]"
            );
            std::process::exit(2);
        }
    }
}

/// A displaced UV sphere: `n_phi` × `n_theta` quads, radius modulated by a sum of sines
/// so that the surface is bumpy at several scales (triangles of all orientations).
fn displaced_sphere(
    center: Vec3,
    radius: f32,
    n_phi: usize,
    n_theta: usize,
    seed: f32,
) -> Vec<[Vec3; 3]> {
    let point = |i: usize, j: usize| {
        let phi = std::f32::consts::TAU * i as f32 / n_phi as f32;
        let theta = std::f32::consts::PI * j as f32 / n_theta as f32;
        let d = Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        );
        let bump = 0.08 * (7.0 * phi + seed).sin() * (5.0 * theta).sin()
            + 0.03 * (23.0 * phi).sin() * (19.0 * theta + seed).cos()
            + 0.01 * (71.0 * phi + 2.0 * seed).sin() * (67.0 * theta).sin();
        center + d * radius * (1.0 + bump)
    };
    let mut tris = Vec::with_capacity(2 * n_phi * n_theta);
    for i in 0..n_phi {
        for j in 0..n_theta {
            let (a, b) = (point(i, j), point(i + 1, j));
            let (c, d) = (point(i + 1, j + 1), point(i, j + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    tris
}

/// A 20 × 8 × 20 room (floor at y = 0) with a 4 × 4 grid of displaced spheres.
fn room(n_phi: usize, n_theta: usize) -> Vec<[Vec3; 3]> {
    let (lo, hi) = (Vec3::new(-10.0, 0.0, -10.0), Vec3::new(10.0, 8.0, 10.0));
    let c =
        |x: usize, y: usize, z: usize| Vec3::new([lo.x, hi.x][x], [lo.y, hi.y][y], [lo.z, hi.z][z]);
    let mut tris = Vec::new();
    // Two triangles for each face of the box.
    for (a, b, cc, d) in [
        (c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)),
        (c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)),
        (c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)),
        (c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)),
        (c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)),
        (c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)),
    ] {
        tris.push([a, b, cc]);
        tris.push([a, cc, d]);
    }
    for i in 0..4 {
        for k in 0..4 {
            let center = Vec3::new(
                -6.0 + 4.0 * i as f32,
                1.6 + 0.5 * ((i + k) % 3) as f32,
                -6.0 + 4.0 * k as f32,
            );
            tris.extend(displaced_sphere(
                center,
                1.4,
                n_phi,
                n_theta,
                (4 * i + k) as f32,
            ));
        }
    }
    tris
}

fn shapes(tris: &[[Vec3; 3]]) -> Vec<Shape> {
    tris.iter().map(|&t| Shape::Triangle(t)).collect()
}

/// The `mixed` scene: [`room`] at a quarter of the triangles, 6 000 analytic spheres
/// (on the floor, on the displaced spheres' surfaces, and floating), and 20 000 small
/// alpha-masked triangles (a barycentric checker, half of each cut away) drifting like
/// leaves through the room. Spheres and masked triangles sit next to the room's own
/// triangles, so the leaf blocks mix every kind.
fn mixed() -> Vec<Shape> {
    let mut shapes = shapes(&room(96, 48));
    let mut rng = Pcg32::new(3, 1);
    let mut u = || rng.uniform_f32();
    for k in 0..6000 {
        let (center, radius) = match k % 3 {
            0 => (Vec3::new(20.0 * u() - 10.0, 0.1, 20.0 * u() - 10.0), 0.1),
            1 => {
                // On one of the 16 displaced spheres, near its surface.
                let (i, j) = (k / 3 % 4, k / 12 % 4);
                let c = Vec3::new(
                    -6.0 + 4.0 * i as f32,
                    1.6 + 0.5 * ((i + j) % 3) as f32,
                    -6.0 + 4.0 * j as f32,
                );
                let d = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5).normalize_or(Vec3::Y);
                (c + d * 1.45, 0.04 + 0.08 * u())
            }
            _ => (
                Vec3::new(18.0 * u() - 9.0, 7.0 * u() + 0.5, 18.0 * u() - 9.0),
                0.05,
            ),
        };
        shapes.push(Shape::Sphere { center, radius });
    }
    for _ in 0..20000 {
        let c = Vec3::new(18.0 * u() - 9.0, 7.0 * u() + 0.5, 18.0 * u() - 9.0);
        let e = |u: &mut dyn FnMut() -> f32| Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5) * 0.4;
        shapes.push(Shape::Triangle([c, c + e(&mut u), c + e(&mut u)]));
    }
    shapes
}

/// Primitives of the `mixed` scene whose hits go through [`leaf_mask`]: its loose
/// triangles, the last 20 000.
fn masked(shapes: &[Shape]) -> impl Fn(u32) -> bool + '_ {
    move |i| i as usize >= shapes.len() - 20000
}

/// The alpha mask of the `mixed` scene's loose triangles: a 4 × 4 checker in
/// barycentrics, half of each triangle cut away.
fn leaf_mask(_: u32, h: &TriangleHit) -> bool {
    ((h.b1 * 4.0) as u32 + (h.b2 * 4.0) as u32).is_multiple_of(2)
}

/// The geometric normal of shape `s` at `p`.
fn normal(s: &Shape, p: Vec3) -> Vec3 {
    match *s {
        Shape::Triangle(t) => (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero(),
        Shape::Sphere { center, .. } => (p - center).normalize_or_zero(),
    }
}

/// Film position in [0, 1)² to primary ray.
type CameraFn = Box<dyn Fn(Vec2) -> Ray>;

/// A pinhole in a corner of the room looking at its middle, 60° field of view.
fn room_camera() -> CameraFn {
    let (eye, target) = (Vec3::new(-9.0, 6.0, 9.0), Vec3::new(0.0, 1.5, 0.0));
    let frame = Frame::from_z((eye - target).normalize());
    let tan = (30f32).to_radians().tan();
    Box::new(move |f: Vec2| {
        let d = Vec3::new((2.0 * f.x - 1.0) * tan, (1.0 - 2.0 * f.y) * tan, -1.0);
        Ray::new(eye, frame.to_world(d).normalize())
    })
}

fn rays_bench(scene: &str, out: &Path, n_rays: usize) {
    let (shapes, camera): (Vec<Shape>, CameraFn) = match scene {
        "cornell" => {
            let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
            let mut desc = candela_scene::load_scene(Path::new(path)).expect("cornell.toml");
            desc.render.width = 512;
            desc.render.height = 512;
            let scene = candela_core::build::build(&desc).expect("cornell builds");
            assert!(
                scene.spheres.is_empty(),
                "the benchmark traces triangles only"
            );
            let tris: Vec<[Vec3; 3]> = scene
                .meshes
                .iter()
                .flat_map(|m| (0..m.indices.len() as u32).map(move |t| m.vertices(t)))
                .collect();
            let cam = scene.camera.clone();
            (
                shapes(&tris),
                Box::new(move |f: Vec2| cam.generate_ray(f * 512.0)),
            )
        }
        "room" => (shapes(&room(192, 96)), room_camera()),
        "mixed" => (mixed(), room_camera()),
        other => panic!("unknown scene {other:?}: cornell, room or mixed"),
    };
    // Only the mixed scene has alpha masks; the filter is the same function for all.
    let is_masked = masked(&shapes);
    let filtered = |i: u32| scene == "mixed" && is_masked(i);
    let t0 = Instant::now();
    let accel = Accel::build_layout(&shapes, filtered, simd_from_env(), layout_from_env());
    let build_s = t0.elapsed().as_secs_f64();

    // Diffuse-bounce rays from primary hits.
    let mut rng = Pcg32::new(7, 0);
    let mut rays = Vec::with_capacity(n_rays);
    while rays.len() < n_rays {
        let film = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let primary = camera(film);
        let Some(hit) = accel.intersect(&primary, f32::INFINITY, leaf_mask) else {
            continue;
        };
        let shape = &shapes[hit.prim as usize];
        let p = match *shape {
            Shape::Triangle(t) => t[0] * (1.0 - hit.b1 - hit.b2) + t[1] * hit.b1 + t[2] * hit.b2,
            Shape::Sphere { .. } => primary.o + primary.d * hit.t,
        };
        let mut n = normal(shape, p);
        if n.dot(primary.d) > 0.0 {
            n = -n;
        }
        let d = Frame::from_z(n).to_world(sample_cosine_hemisphere(Vec2::new(
            rng.uniform_f32(),
            rng.uniform_f32(),
        )));
        rays.push(Ray::new(offset_ray_origin(p, n), d.normalize()));
    }

    let mut hits = vec![(u32::MAX, f32::INFINITY); rays.len()];
    let closest = best_of(3, || trace_closest(&accel, &rays, &mut hits));
    let mut blocked = 0;
    let any = best_of(3, || blocked = trace_any(&accel, &rays));
    let found = hits.iter().filter(|h| h.0 != u32::MAX).count();
    assert_eq!(
        found, blocked,
        "closest-hit and any-hit agree on which rays hit"
    );

    std::fs::create_dir_all(out).expect("OUT_DIR");
    let floats =
        |v: &mut dyn Iterator<Item = f32>| -> Vec<u8> { v.flat_map(f32::to_le_bytes).collect() };
    let tris: Vec<[Vec3; 3]> = shapes
        .iter()
        .filter_map(|s| match *s {
            Shape::Triangle(t) => Some(t),
            Shape::Sphere { .. } => None,
        })
        .collect();
    let spheres = shapes.len() - tris.len();
    if spheres == 0 {
        // Embree's input: only for scenes of plain triangles.
        std::fs::write(
            out.join("tris.f32"),
            floats(&mut tris.iter().flatten().flat_map(|v| v.to_array())),
        )
        .unwrap();
    }
    std::fs::write(
        out.join("rays.f32"),
        floats(
            &mut rays
                .iter()
                .flat_map(|r| [r.o.to_array(), r.d.to_array()].concat()),
        ),
    )
    .unwrap();
    let mut f = std::fs::File::create(out.join("candela_hits.bin")).unwrap();
    for (prim, t) in &hits {
        f.write_all(&prim.to_le_bytes()).unwrap();
        f.write_all(&t.to_le_bytes()).unwrap();
    }
    let packets = packet_mode()
        .map(|mode| packet_bench(&accel, &rays, &hits, &camera, mode))
        .unwrap_or_default();
    let n = rays.len() as f64;
    let (node_bytes, block_bytes) = accel.memory();
    let masked_count = (0..shapes.len() as u32).filter(|&i| filtered(i)).count();
    println!(
        "{{\"scene\": \"{scene}\", \"simd\": \"{:?}\", \"layout\": \"{:?}\", \"triangles\": {}, \
         \"spheres\": {spheres}, \"masked\": {masked_count}, \"rays\": {}, \"hit\": {found}, \
         \"build_s\": {build_s:.4}, \"closest_mrays_s\": {:.3}, \"any_mrays_s\": {:.3}, \
         \"node_bytes\": {node_bytes}, \"block_bytes\": {block_bytes}{packets}}}",
        accel.simd(),
        accel.layout(),
        tris.len(),
        rays.len(),
        n / closest / 1e6,
        n / any / 1e6
    );
}

/// The timed closest-hit loop; out of line so that callgrind can count it alone
/// (`--toggle-collect=traversal::trace_closest`).
#[inline(never)]
fn trace_closest(accel: &Accel, rays: &[Ray], hits: &mut [(u32, f32)]) {
    closest_loop(accel, rays, hits)
}

/// The body of [`trace_closest`] and [`trace_primary`] (inlined into each, so that each
/// counts only its own rays).
#[inline(always)]
fn closest_loop(accel: &Accel, rays: &[Ray], hits: &mut [(u32, f32)]) {
    for (r, h) in rays.iter().zip(hits.iter_mut()) {
        if let Some(hit) = accel.intersect(r, f32::INFINITY, leaf_mask) {
            *h = (hit.prim, hit.t);
        }
    }
}

/// The timed any-hit loop: how many rays are blocked (`traversal::trace_any`).
#[inline(never)]
fn trace_any(accel: &Accel, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|r| accel.occluded(r, f32::INFINITY, leaf_mask))
        .count()
}

/// Shadow rays: from each bounce ray's origin to a random point on a quad just under the
/// scene's ceiling (a fifth of its width and depth, centred), `t_max` just short of it.
fn shadow_rays(accel: &Accel, rays: &[Ray]) -> (Vec<Ray>, Vec<f32>) {
    let b = accel.bounds();
    let (c, e) = ((b.min + b.max) * 0.5, b.max - b.min);
    let mut rng = Pcg32::new(11, 5);
    rays.iter()
        .map(|r| {
            let q = Vec3::new(
                c.x + 0.2 * e.x * (rng.uniform_f32() - 0.5),
                b.max.y - 0.01 * e.y,
                c.z + 0.2 * e.z * (rng.uniform_f32() - 0.5),
            );
            let d = q - r.o;
            let dist = d.length();
            (Ray::new(r.o, d / dist), dist * 0.999)
        })
        .unzip()
}

/// `CANDELA_PACKET_K=K` (a subtree reached by K rays or fewer is finished by each alone)
/// and `CANDELA_PACKET_NODES=boxes|rays` (each child box against the rays in lanes, the
/// default, or each ray against the node's boxes): the packet benchmark's mode, if asked.
fn packet_mode() -> Option<PacketMode> {
    let k = std::env::var("CANDELA_PACKET_K").ok()?;
    let box_against_rays = match std::env::var("CANDELA_PACKET_NODES").as_deref() {
        Ok("boxes") | Err(_) => true,
        Ok("rays") => false,
        Ok(other) => panic!("CANDELA_PACKET_NODES={other:?}: boxes or rays"),
    };
    Some(PacketMode {
        box_against_rays,
        single_below: k.parse().expect("CANDELA_PACKET_K"),
    })
}

/// Packets of eight against single rays, in `mode`: closest hit and any hit on the bounce rays,
/// any hit on shadow rays, eight consecutive rays a packet (incoherent: each from a
/// random pixel); and closest hit on coherent primary rays, a packet from a 4 × 2 pixel
/// tile of a 512² image (tiles spread evenly over it). Checks that every any-hit answer and every closest-hit distance is the
/// single rays' (and counts the closest hits on another primitive at the same distance),
/// and returns the JSON fields.
fn packet_bench(
    accel: &Accel,
    rays: &[Ray],
    hits: &[(u32, f32)],
    camera: &CameraFn,
    mode: PacketMode,
) -> String {
    let k = mode.single_below;
    let mut rng = Pcg32::new(5, 3);
    let primary: Vec<Ray> = (0..rays.len())
        .map(|i| {
            // Tiles spread evenly over the 128 × 256 tiles of the image.
            let step = (128 * 256 / (rays.len() / 8).max(1)).max(1);
            let (tile, j) = (i / 8 * step % (128 * 256), i % 8);
            let (x, y) = ((tile % 128) * 4 + j % 4, (tile / 128) % 256 * 2 + j / 4);
            let film = Vec2::new(x as f32 + rng.uniform_f32(), y as f32 + rng.uniform_f32());
            camera(film / 512.0)
        })
        .collect();
    let mut primary_hits = vec![(u32::MAX, f32::INFINITY); rays.len()];
    let mut primary_hit = 0;
    let primary1 = best_of(3, || {
        primary_hit = trace_primary(accel, &primary, &mut primary_hits)
    });
    let mut primary_hits8 = vec![(u32::MAX, f32::INFINITY); rays.len()];
    let mut primary_hit8 = 0;
    let primary8 = best_of(3, || {
        primary_hit8 = trace_primary8(accel, &primary, &mut primary_hits8, mode)
    });
    assert_eq!(primary_hit, primary_hit8, "primary rays that hit");
    for (i, (a, b)) in primary_hits.iter().zip(&primary_hits8).enumerate() {
        assert_eq!(
            a.1.to_bits(),
            b.1.to_bits(),
            "primary ray {i}: packet distance"
        );
    }
    let (shadow, shadow_t) = shadow_rays(accel, rays);
    let mut hits8 = vec![(u32::MAX, f32::INFINITY); rays.len()];
    let closest8 = best_of(3, || trace_closest8(accel, rays, &mut hits8, mode));
    let mut blocked8 = Vec::new();
    let any8 = best_of(3, || {
        blocked8 = trace_any8(accel, rays, &[f32::INFINITY; 8], mode)
    });
    let mut blocked_shadow = Vec::new();
    let shadow1 = best_of(3, || {
        blocked_shadow = trace_shadow(accel, &shadow, &shadow_t)
    });
    let mut blocked_shadow8 = Vec::new();
    let shadow8 = best_of(3, || {
        blocked_shadow8 = trace_shadow8(accel, &shadow, &shadow_t, mode)
    });
    let blocked: Vec<bool> = hits.iter().map(|h| h.0 != u32::MAX).collect();
    assert_eq!(blocked8, blocked, "packet any-hit answers as single rays");
    assert_eq!(
        blocked_shadow8, blocked_shadow,
        "packet shadow rays as single"
    );
    for (i, (a, b)) in hits.iter().zip(&hits8).enumerate() {
        assert_eq!(
            a.1.to_bits(),
            b.1.to_bits(),
            "ray {i}: packet closest distance"
        );
    }
    let other_prim = hits.iter().zip(&hits8).filter(|(a, b)| a.0 != b.0).count();
    let n = rays.len() as f64;
    let shadow_blocked = blocked_shadow.iter().filter(|&&b| b).count();
    format!(
        ", \"packet_k\": {k}, \"packet_box_against_rays\": {}, \"closest8_mrays_s\": {:.3}, \"any8_mrays_s\": {:.3}, \
         \"shadow_mrays_s\": {:.3}, \"shadow8_mrays_s\": {:.3}, \"shadow_blocked\": \
         {shadow_blocked}, \"closest8_other_prim\": {other_prim}, \"primary_mrays_s\": \
         {:.3}, \"primary8_mrays_s\": {:.3}",
        mode.box_against_rays,
        n / closest8 / 1e6,
        n / any8 / 1e6,
        n / shadow1 / 1e6,
        n / shadow8 / 1e6,
        n / primary1 / 1e6,
        n / primary8 / 1e6
    )
}

/// Primary rays one at a time (`traversal::trace_primary`): how many hit. (Not the same
/// code as [`trace_closest`], which the linker would fold into one symbol.)
#[inline(never)]
fn trace_primary(accel: &Accel, rays: &[Ray], hits: &mut [(u32, f32)]) -> usize {
    closest_loop(accel, rays, hits);
    hits.iter().filter(|h| h.0 != u32::MAX).count()
}

/// Primary rays eight a call (`traversal::trace_primary8`): how many hit.
#[inline(never)]
fn trace_primary8(accel: &Accel, rays: &[Ray], hits: &mut [(u32, f32)], mode: PacketMode) -> usize {
    closest8_loop(accel, rays, hits, mode);
    hits.iter().filter(|h| h.0 != u32::MAX).count()
}

/// [`trace_closest`] eight rays a call (`traversal::trace_closest8`).
#[inline(never)]
fn trace_closest8(accel: &Accel, rays: &[Ray], hits: &mut [(u32, f32)], mode: PacketMode) {
    closest8_loop(accel, rays, hits, mode)
}

/// The body of [`trace_closest8`] and [`trace_primary8`].
#[inline(always)]
fn closest8_loop(accel: &Accel, rays: &[Ray], hits: &mut [(u32, f32)], mode: PacketMode) {
    for (r, h) in rays.chunks_exact(8).zip(hits.chunks_exact_mut(8)) {
        let found = accel.intersect8(r.try_into().unwrap(), &[f32::INFINITY; 8], mode, leaf_mask);
        for (f, h) in found.iter().zip(h) {
            if let Some(hit) = f {
                *h = (hit.prim, hit.t);
            }
        }
    }
}

/// [`trace_any`] eight rays a call, each ray's answer (`traversal::trace_any8`).
#[inline(never)]
fn trace_any8(accel: &Accel, rays: &[Ray], t_max: &[f32; 8], mode: PacketMode) -> Vec<bool> {
    let mut out = Vec::with_capacity(rays.len());
    for r in rays.chunks_exact(8) {
        let m = accel.occluded8(r.try_into().unwrap(), t_max, mode, leaf_mask);
        out.extend((0..8).map(|i| m & (1 << i) != 0));
    }
    out
}

/// Shadow rays one at a time (`traversal::trace_shadow`).
#[inline(never)]
fn trace_shadow(accel: &Accel, rays: &[Ray], t_max: &[f32]) -> Vec<bool> {
    rays.iter()
        .zip(t_max)
        .map(|(r, &t)| accel.occluded(r, t, leaf_mask))
        .collect()
}

/// Shadow rays eight a call (`traversal::trace_shadow8`).
#[inline(never)]
fn trace_shadow8(accel: &Accel, rays: &[Ray], t_max: &[f32], mode: PacketMode) -> Vec<bool> {
    let mut out = Vec::with_capacity(rays.len());
    for (r, t) in rays.chunks_exact(8).zip(t_max.chunks_exact(8)) {
        let m = accel.occluded8(
            r.try_into().unwrap(),
            t.try_into().unwrap(),
            mode,
            leaf_mask,
        );
        out.extend((0..8).map(|i| m & (1 << i) != 0));
    }
    out
}

/// The kernels to trace with: `CANDELA_SIMD=scalar|sse|avx2` to measure a fallback, else
/// the best this CPU has.
fn simd_from_env() -> Simd {
    match std::env::var("CANDELA_SIMD").as_deref() {
        Ok("scalar") => Simd::Scalar,
        Ok("sse") => Simd::Sse,
        Ok("avx2") => Simd::Avx2,
        Ok(other) => panic!("CANDELA_SIMD={other:?}: scalar, sse or avx2"),
        Err(_) => Simd::best(),
    }
}

/// The layout: `CANDELA_NODES=full|quantized` and `CANDELA_LEAVES=inline|indexed`,
/// else the library's defaults.
fn layout_from_env() -> AccelLayout {
    let nodes = match std::env::var("CANDELA_NODES").as_deref() {
        Ok("full") => NodeLayout::Full,
        Ok("quantized") => NodeLayout::Quantized,
        Ok(other) => panic!("CANDELA_NODES={other:?}: full or quantized"),
        Err(_) => NodeLayout::default(),
    };
    let leaves = match std::env::var("CANDELA_LEAVES").as_deref() {
        Ok("inline") => LeafLayout::Inline,
        Ok("indexed") => LeafLayout::Indexed,
        Ok(other) => panic!("CANDELA_LEAVES={other:?}: inline or indexed"),
        Err(_) => LeafLayout::default(),
    };
    AccelLayout { nodes, leaves }
}

/// The fastest of `runs` timings of `f`, in seconds: the least disturbed by other load.
fn best_of(runs: usize, mut f: impl FnMut()) -> f64 {
    (0..runs)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn build_bench(n: usize) {
    // 25 displaced spheres sized to give at least n triangles.
    let per = n.div_ceil(25);
    let n_theta = ((per as f64 / 4.0).sqrt().ceil() as usize).max(2);
    let n_phi = per.div_ceil(2 * n_theta);
    let mut tris = Vec::new();
    for i in 0..5 {
        for k in 0..5 {
            let c = Vec3::new(3.0 * i as f32, 0.0, 3.0 * k as f32);
            tris.extend(displaced_sphere(c, 1.4, n_phi, n_theta, (5 * i + k) as f32));
        }
    }
    let shapes = shapes(&tris);
    let threads = rayon::current_num_threads();
    let mut times: Vec<(f64, f64)> = (0..5)
        .map(|_| {
            let (t, cpu) = (Instant::now(), cpu_seconds());
            let accel = Accel::build_layout(&shapes, |_| false, Simd::best(), layout_from_env());
            let s = (t.elapsed().as_secs_f64(), cpu_seconds() - cpu);
            assert!(!accel.bounds().is_empty());
            s
        })
        .collect();
    times.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!(
        "{{\"triangles\": {}, \"threads\": {threads}, \"build_best_s\": {:.3}, \"build_median_s\": {:.3}, \
         \"cpu_s_of_best\": {:.2}}}",
        tris.len(),
        times[0].0,
        times[2].0,
        times[0].1
    );
}
