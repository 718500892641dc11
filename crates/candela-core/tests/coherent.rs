//! The coherent packet query (`Accel::intersect_coherent8`) against eight single queries
//! (`Accel::intersect`) on the same rays: every ray's hit must be the same bit for bit
//! (primitive, distance, barycentrics), ties included: the scenes hold duplicated
//! triangles (two primitives at the very same distance) and triangles sharing edges and
//! vertices that rays aim at (exactly zero edge functions, which count as inside).
//! Trees of one leaf, of one node over several leaves (the packet paths) and of several
//! nodes (single queries), with spheres and alpha-masked triangles whose filter depends
//! on the ray (so each ray must be asked about with its own), in coherent packets (one
//! origin, nearby directions: camera rays) and incoherent ones, with finite and
//! infinite `t_max`, partial packets and non-finite rays. Every kernel set the CPU has
//! (only AVX2 packs; the others fall back and must agree all the same) and the layouts.
//! No statistics: every ray must agree.

use candela_core::accel::{Accel, AccelLayout, Hit, LeafLayout, NodeLayout, Shape, Simd};
use candela_core::geometry::{Ray, TriangleHit};
use candela_core::sampler::Pcg32;
use glam::Vec3;

fn v3(rng: &mut Pcg32) -> Vec3 {
    Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32())
}

/// `n` primitives in the unit cube on a coarse grid (shared vertices and edges): a
/// floor quad, triangles, every seventh a sphere, every fifth triangle duplicated (the
/// copy a primitive of its own, hit at the same distance).
fn scene(rng: &mut Pcg32, n: usize) -> Vec<Shape> {
    let grid = |v: Vec3| (v * 4.0).round() / 4.0;
    let mut shapes = vec![
        Shape::Triangle([
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(2.0, 0.0, -1.0),
            Vec3::new(2.0, 0.0, 2.0),
        ]),
        Shape::Triangle([
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(2.0, 0.0, 2.0),
            Vec3::new(-1.0, 0.0, 2.0),
        ]),
    ];
    while shapes.len() < n {
        let k = shapes.len();
        if k % 7 == 3 {
            shapes.push(Shape::Sphere {
                center: v3(rng),
                radius: 0.05 + 0.15 * rng.uniform_f32(),
            });
        } else {
            let c = grid(v3(rng));
            let mut e = || grid((v3(rng) - 0.5) * 0.8);
            let t = Shape::Triangle([c, c + e(), c + e()]);
            shapes.push(t);
            if k % 5 == 2 && shapes.len() < n {
                shapes.push(t);
            }
        }
    }
    shapes
}

/// Every fourth primitive goes through the filter.
fn masked(i: u32) -> bool {
    i % 4 == 2
}

/// A barycentric checker, flipped for odd rays: the answer depends on the ray asking.
fn mask(ray: usize, _: u32, h: &TriangleHit) -> bool {
    ((h.b1 * 4.0) as u32 + (h.b2 * 4.0) as u32).is_multiple_of(2) != (ray % 2 == 1)
}

/// Coherent packets (one origin, directions within a pixel-sized cone around an aim at
/// a vertex of the scene, or anywhere) and incoherent ones; every ninth packet has a
/// non-finite ray.
fn packets(rng: &mut Pcg32, shapes: &[Shape], n: usize) -> Vec<[Ray; 8]> {
    (0..n)
        .map(|p| {
            let origin = v3(rng) * 3.0 - 1.0;
            let aim = match shapes[rng.next_u32() as usize % shapes.len()] {
                Shape::Triangle(v) if p % 3 == 0 => v[p / 3 % 3],
                Shape::Triangle(v) => (v[0] + v[1] + v[2]) / 3.0,
                Shape::Sphere { center, .. } => center,
            };
            let axis = (aim - origin).normalize_or(Vec3::Y);
            let spread = [0.0, 1e-3, 3e-2][p % 3];
            let mut rays: [Ray; 8] = std::array::from_fn(|k| {
                if p % 4 == 3 {
                    let d = (v3(rng) * 2.0 - 1.0).normalize_or(Vec3::Y);
                    Ray::new(v3(rng) * 1.6 - 0.3, d)
                } else if k == 0 {
                    Ray::new(origin, axis)
                } else {
                    let d = (axis + (v3(rng) - 0.5) * spread).normalize_or(Vec3::Y);
                    Ray::new(origin, d)
                }
            });
            if p % 9 == 8 {
                rays[p % 8].d = Vec3::new(f32::NAN, 0.0, 1.0);
            }
            rays
        })
        .collect()
}

fn bits(h: &Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.prim, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()))
}

/// Checks every ray of every packet on `accel`; returns (hits, ties seen by the single
/// query: another primitive hit at the same distance as the reported one).
fn check(
    accel: &Accel,
    shapes: &[Shape],
    packets: &[[Ray; 8]],
    rng: &mut Pcg32,
    what: &str,
) -> (u32, u32) {
    let (mut hits, mut ties) = (0, 0);
    for (p, rays) in packets.iter().enumerate() {
        let t_max: [f32; 8] = std::array::from_fn(|i| {
            if (p + i) % 4 == 0 {
                0.3 + 2.0 * rng.uniform_f32()
            } else {
                f32::INFINITY
            }
        });
        let active = if p % 5 == 1 { 0xff >> (p % 8) } else { 0xff };
        let found = accel.intersect_coherent8(rays, active, &t_max, mask);
        for i in 0..8 {
            let single = if active & (1 << i) != 0 {
                accel.intersect(&rays[i], t_max[i], |prim, h| mask(i, prim, h))
            } else {
                None
            };
            assert_eq!(
                bits(&found[i]),
                bits(&single),
                "{what}, packet {p}, ray {i}"
            );
            if let Some(h) = single {
                hits += 1;
                // A duplicate of the reported triangle lies at the same distance.
                let twin = |s: &Shape| {
                    matches!((s, &shapes[h.prim as usize]),
                    (Shape::Triangle(a), Shape::Triangle(b)) if a == b)
                };
                ties += (shapes.iter().filter(|s| twin(s)).count() > 1) as u32;
            }
        }
    }
    (hits, ties)
}

#[test]
fn coherent_packets_find_what_single_rays_find_bit_for_bit() {
    let mut rng = Pcg32::new(35, 88);
    let layouts = [
        (NodeLayout::Full, LeafLayout::Inline),
        (NodeLayout::Quantized, LeafLayout::Inline),
        (NodeLayout::Full, LeafLayout::Indexed),
    ];
    // One leaf, one node over leaves, several nodes.
    for n in [6, 8, 12, 16, 20, 40, 64, 400] {
        let shapes = scene(&mut rng, n);
        let packets = packets(&mut rng, &shapes, 1500);
        let (mut hits, mut ties, mut rays, mut packed) = (0, 0, 0, false);
        for simd in Simd::available() {
            for (nodes, leaves) in layouts {
                let layout = AccelLayout { nodes, leaves };
                let accel = Accel::build_layout(&shapes, masked, simd, layout);
                packed |= accel.packs_rays();
                let what = format!("{n} prims, {simd:?} {layout:?}");
                let (h, t) = check(&accel, &shapes, &packets, &mut rng, &what);
                hits += h;
                ties += t;
                rays += packets.len() as u32 * 8;
            }
        }
        eprintln!(
            "{n} prims: {rays} rays, {hits} hits, {ties} on duplicated triangles, packed {packed}"
        );
        // Thresholds: most rays aim at a primitive (and the floor catches many others);
        // every fifth triangle is duplicated, so some hits are ties.
        assert!(hits * 2 > rays, "{n} prims: {hits} hits of {rays}");
        assert!(ties > 100, "{n} prims: only {ties} ties");
        // Trees of one node pack where the CPU has AVX2.
        if n <= 16 && Simd::available().contains(&Simd::Avx2) {
            assert!(packed, "{n} prims: no packet query");
        }
    }
}

/// Checks every ray of every packet's any-hit answer on `accel` against the single
/// any-hit query; returns (rays asked, rays blocked).
fn check_any(accel: &Accel, packets: &[[Ray; 8]], rng: &mut Pcg32, what: &str) -> (u32, u32) {
    let (mut asked, mut blocked) = (0, 0);
    for (p, rays) in packets.iter().enumerate() {
        // Segments short and long (shadow rays towards a point) and unbounded ones
        // (towards an infinite light).
        let t_max: [f32; 8] = std::array::from_fn(|i| match (p + i) % 3 {
            0 => 0.05 + 2.0 * rng.uniform_f32(),
            1 => 0.5 * rng.uniform_f32(),
            _ => f32::INFINITY,
        });
        let active = if p % 5 == 1 { 0xff >> (p % 8) } else { 0xff };
        let found = accel.occluded_coherent8(rays, active, &t_max, mask);
        for i in 0..8 {
            let single = active & (1 << i) != 0
                && accel.occluded(&rays[i], t_max[i], |prim, h| mask(i, prim, h));
            assert_eq!(found & (1 << i) != 0, single, "{what}, packet {p}, ray {i}");
            asked += (active >> i) & 1;
            blocked += single as u32;
        }
        assert_eq!(
            found & !active,
            0,
            "{what}, packet {p}: an inactive ray blocked"
        );
    }
    (asked, blocked)
}

/// The any-hit packet query (`Accel::occluded_coherent8`) against eight single any-hit
/// queries (`Accel::occluded`): every ray blocked or not as the single query says, on the
/// scenes and packets of the closest-hit test (coherent and incoherent rays, spheres,
/// ray-dependent alpha masks, edges aimed at, non-finite rays, partial packets), with
/// bounded and unbounded rays, every kernel set and layout.
#[test]
fn any_hit_packets_answer_as_single_rays() {
    let mut rng = Pcg32::new(35, 89);
    let layouts = [
        (NodeLayout::Full, LeafLayout::Inline),
        (NodeLayout::Quantized, LeafLayout::Inline),
        (NodeLayout::Full, LeafLayout::Indexed),
    ];
    // Scenes of more than a block's eight primitives that pack are one node over leaves.
    let mut packed_roots = 0;
    for n in [6, 8, 12, 16, 20, 40, 64, 400] {
        let shapes = scene(&mut rng, n);
        let packets = packets(&mut rng, &shapes, 1500);
        let (mut asked, mut blocked, mut packed) = (0, 0, false);
        for simd in Simd::available() {
            for (nodes, leaves) in layouts {
                let layout = AccelLayout { nodes, leaves };
                let accel = Accel::build_layout(&shapes, masked, simd, layout);
                packed |= accel.packs_rays();
                let what = format!("{n} prims, {simd:?} {layout:?}");
                let (a, b) = check_any(&accel, &packets, &mut rng, &what);
                asked += a;
                blocked += b;
            }
        }
        eprintln!("{n} prims: {asked} rays, {blocked} blocked, packed {packed}");
        // Both answers are common: short segments mostly pass, rays aimed at a
        // primitive and unbounded ones are mostly blocked.
        assert!(
            blocked * 5 > asked,
            "{n} prims: {blocked} blocked of {asked}"
        );
        assert!(
            blocked * 5 < asked * 4,
            "{n} prims: {blocked} blocked of {asked}"
        );
        // Trees of one leaf pack where the CPU has AVX2; so do some of one node.
        if Simd::available().contains(&Simd::Avx2) {
            assert!(packed || n > 8, "{n} prims: no packet query");
            packed_roots += (packed && n > 8) as u32;
        }
    }
    if Simd::available().contains(&Simd::Avx2) {
        assert!(packed_roots > 0, "no tree of one node over leaves packs");
    }
}
