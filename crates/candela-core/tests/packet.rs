//! The packet queries (`Accel::occluded8`, `Accel::intersect8`) against eight single-ray
//! queries on the same rays: every any-hit answer must be the same, and every nearest
//! hit the same distance, bit for bit (the same primitive and barycentric bits too, except
//! where two primitives are hit at that very distance, which the packet may visit in
//! another order). Checked with both node tests of the packet (each box against the rays,
//! each ray against the boxes) and with single rays finishing subtrees reached by few
//! lanes (K = 0, 2, 8), on a soup of triangles and spheres with alpha-masked triangles
//! (so blocks of every mix), in incoherent packets (rays from anywhere) and coherent ones
//! (eight rays from one point in nearby directions), with finite and infinite `t_max`
//! and a non-finite ray in some packets. Every kernel set and layout the CPU has: the
//! packet path runs for AVX2 with full nodes and inline leaves, the others fall back to
//! single queries and must agree all the same. No statistics: every ray must agree.

use candela_core::accel::{Accel, Hit};
use candela_core::accel::{AccelLayout, LeafLayout, NodeLayout, PacketMode, Shape, Simd};
use candela_core::geometry::{Ray, TriangleHit};
use candela_core::sampler::Pcg32;
use glam::Vec3;

fn v3(rng: &mut Pcg32) -> Vec3 {
    Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32())
}

/// Small triangles and spheres in the unit cube, and a floor of two big triangles.
fn soup(rng: &mut Pcg32) -> Vec<Shape> {
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
    for k in 0..1500 {
        let c = v3(rng);
        if k % 12 == 0 {
            shapes.push(Shape::Sphere {
                center: c,
                radius: 0.01 + 0.03 * rng.uniform_f32(),
            });
        } else {
            let mut e = || (v3(rng) - 0.5) * 0.12;
            shapes.push(Shape::Triangle([c, c + e(), c + e()]));
        }
    }
    shapes
}

/// Every third triangle from the fourth on goes through the filter, which rejects hits
/// on half of each (a barycentric checker), as an alpha mask does.
fn masked(i: u32) -> bool {
    i > 2 && i.is_multiple_of(3)
}

fn mask(_: u32, h: &TriangleHit) -> bool {
    ((h.b1 * 4.0) as u32 + (h.b2 * 4.0) as u32).is_multiple_of(2)
}

/// Packets of eight rays: incoherent ones (origins anywhere in and around the cube,
/// uniform directions) and coherent ones (one origin, directions within a narrow cone);
/// every fifth packet has a non-finite ray.
fn packets(rng: &mut Pcg32, n: usize) -> Vec<[Ray; 8]> {
    (0..n)
        .map(|p| {
            let origin = v3(rng) * 1.6 - 0.3;
            let axis = (v3(rng) * 2.0 - 1.0).normalize_or(Vec3::Y);
            let mut rays: [Ray; 8] = std::array::from_fn(|_| {
                if p % 2 == 0 {
                    let d = (v3(rng) * 2.0 - 1.0).normalize_or(Vec3::Y);
                    Ray::new(v3(rng) * 1.6 - 0.3, d)
                } else {
                    let d = (axis + (v3(rng) - 0.5) * 0.1).normalize_or(Vec3::Y);
                    Ray::new(origin, d)
                }
            });
            if p % 5 == 4 {
                rays[p % 8].d = Vec3::new(f32::NAN, 0.0, 1.0);
            }
            rays
        })
        .collect()
}

fn bits(h: &Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.prim, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()))
}

#[test]
fn packets_find_what_single_rays_find() {
    let mut rng = Pcg32::new(35, 8);
    let shapes = soup(&mut rng);
    let packets = packets(&mut rng, 1200);
    let layouts = [
        (NodeLayout::Full, LeafLayout::Inline),
        (NodeLayout::Quantized, LeafLayout::Inline),
        (NodeLayout::Full, LeafLayout::Indexed),
    ];
    let modes: Vec<PacketMode> = [true, false]
        .into_iter()
        .flat_map(|box_against_rays| {
            [0, 2, 8].map(|single_below| PacketMode {
                box_against_rays,
                single_below,
            })
        })
        .collect();
    let (mut hits, mut blocked, mut ties) = (0, 0, 0);
    for simd in Simd::available() {
        for (nodes, leaves) in layouts {
            let layout = AccelLayout { nodes, leaves };
            let accel = Accel::build_layout(&shapes, masked, simd, layout);
            for (p, rays) in packets.iter().enumerate() {
                let t_max: [f32; 8] = std::array::from_fn(|i| {
                    if (p + i) % 3 == 0 {
                        0.2 + rng.uniform_f32()
                    } else {
                        f32::INFINITY
                    }
                });
                let single: [Option<Hit>; 8] =
                    std::array::from_fn(|i| accel.intersect(&rays[i], t_max[i], mask));
                let single_blocked = (0..8).fold(0, |m, i| {
                    m | (accel.occluded(&rays[i], t_max[i], mask) as u32) << i
                });
                for &mode in &modes {
                    let what = format!("{simd:?} {layout:?} {mode:?} packet {p}");
                    assert_eq!(
                        accel.occluded8(rays, &t_max, mode, mask),
                        single_blocked,
                        "{what}: any hit"
                    );
                    let found = accel.intersect8(rays, &t_max, mode, mask);
                    for i in 0..8 {
                        let (a, b) = (bits(&found[i]), bits(&single[i]));
                        if a != b {
                            // Only a tie: the same distance on another primitive.
                            let (a, b) = (a.unwrap(), b.unwrap());
                            assert!(a.0 != b.0 && a.1 == b.1, "{what}, ray {i}: {a:?} vs {b:?}");
                            ties += 1;
                        }
                    }
                }
                hits += single.iter().flatten().count();
                blocked += single_blocked.count_ones();
            }
        }
    }
    let queries = Simd::available().len() * layouts.len() * packets.len() * 8;
    eprintln!("{queries} rays: {hits} hit, {blocked} blocked, {ties} ties");
    // A third to two thirds of the rays hit something (the floor catches many); ties are rare.
    assert!(
        hits * 3 > queries && hits * 3 < 2 * queries,
        "{hits} of {queries} hit"
    );
    assert_eq!(
        hits as u32, blocked,
        "closest and any hit agree on which rays hit"
    );
    assert!(ties * 1000 < queries * modes.len(), "{ties} ties");
}
