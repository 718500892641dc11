//! The wide BVH against the references it replaces: on random rays through random and
//! degenerate scenes, `Accel` must find the same nearest primitive at the same distance,
//! bit for bit, as a brute-force loop and as the binary BVH's own traversal (the one the
//! scene used before), with the same triangle and sphere tests; any-hit queries must give
//! the same answers. Ties (two primitives at the same distance, e.g. a ray through a
//! shared edge) may resolve to either, so there the found primitive is checked to give
//! the same distance. No statistics: every ray must agree.
//!
//! The alpha-mask path: flagging every other triangle and rejecting it in the filter must
//! give the same hits as building without those triangles.
//!
//! Leaves are blocks of up to eight lanes, so these scenes hold blocks of every fill, and
//! the soup mixes spheres among its triangles (`accel::block`'s own test checks each
//! fill and mix lane by lane). Scenes of one leaf (one triangle; a block of triangles and
//! spheres) take the queries' path without box tests, and a scene of one node over four
//! leaves the path without the traversal's stack; both must also return the traversal's
//! own hits bit for bit (`small_trees_find_the_traversals_hits`).
//!
//! Every SIMD kernel set the CPU has (`Simd::available`, always including the scalar
//! fallback) is checked the same way, with both node layouts (full planes and quantized
//! boxes) and both leaf layouts (inline blocks and indexed records), and each must return
//! exactly what the scalar kernels with inline leaves and the same node layout return
//! (same primitive even in ties, same t and barycentric bits): their box tests give the
//! same bits, so they walk the tree in the same order, and an indexed leaf is tested as
//! the block it gathers. Across node layouts the order differs (quantized boxes are
//! entered a little earlier), so there only ties may differ.

use candela_core::accel::{
    accept_all, Accel, AccelLayout, Geometry, Hit, LeafLayout, NodeLayout, Shape, Simd,
    TriangleMesh,
};
use candela_core::bvh::{Bvh, SahCost, WideBvh};
use candela_core::geometry::{intersect_sphere, Aabb, Ray, WatertightRay};
use candela_core::sampler::Pcg32;
use glam::Vec3;

fn v3(rng: &mut Pcg32) -> Vec3 {
    Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32())
}

/// Distance at which `shape` is hit before `t_max`, with the renderer's tests.
fn test_shape(shape: &Shape, ray: &Ray, t_max: f32) -> Option<f32> {
    match *shape {
        Shape::Triangle([a, b, c]) => WatertightRay::new(ray)
            .intersect(a, b, c, t_max)
            .map(|h| h.t),
        Shape::Sphere { center, radius } => intersect_sphere(ray, center, radius, t_max),
    }
}

fn brute_force(shapes: &[Shape], ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
    let mut best = None;
    let mut t_max = t_max;
    for (i, s) in shapes.iter().enumerate() {
        if let Some(t) = test_shape(s, ray, t_max) {
            t_max = t;
            best = Some((i as u32, t));
        }
    }
    best
}

fn boxes(shapes: &[Shape]) -> Vec<Aabb> {
    shapes
        .iter()
        .map(|s| match *s {
            Shape::Triangle(v) => Aabb::from_points(&v),
            Shape::Sphere { center, radius } => Aabb {
                min: center - Vec3::splat(radius),
                max: center + Vec3::splat(radius),
            },
        })
        .collect()
}

/// Random rays: origins in and around `bounds` (a fifth inside a primitive's box),
/// directions uniform, a quarter of them with one or two components exactly ±0
/// (axis-parallel), some aimed at a vertex.
fn random_rays(rng: &mut Pcg32, shapes: &[Shape], bounds: Aabb, n: usize) -> Vec<Ray> {
    let (lo, ext) = if bounds.is_empty() {
        (Vec3::splat(-1.0), Vec3::splat(2.0))
    } else {
        let e = bounds.extent();
        (bounds.min - 0.25 * e, 1.5 * e)
    };
    (0..n)
        .map(|i| {
            let mut o = lo + v3(rng) * ext;
            if i % 5 == 4 && !shapes.is_empty() {
                // From inside a primitive's box (and so inside every box above it).
                let b = shapes[rng.next_u32() as usize % shapes.len()].bounds();
                if b.min.is_finite() && b.max.is_finite() {
                    o = b.min + v3(rng) * (b.max - b.min);
                }
            }
            let mut d = v3(rng) * 2.0 - 1.0;
            match i % 8 {
                0 => d.x = 0.0,
                1 => {
                    d.y = -0.0;
                    d.z = 0.0
                }
                2 if !shapes.is_empty() => {
                    // Straight at a vertex or sphere centre: edges and corners.
                    let k = rng.next_u32() as usize % shapes.len();
                    let target = match shapes[k] {
                        Shape::Triangle(v) => v[rng.next_u32() as usize % 3],
                        Shape::Sphere { center, .. } => center,
                    };
                    d = target - o;
                }
                _ => {}
            }
            if d == Vec3::ZERO {
                d = Vec3::Y;
            }
            Ray::new(o, d.normalize_or(Vec3::Y))
        })
        .collect()
}

/// Checks every ray against brute force and the binary BVH, with every kernel set;
/// returns how many hit.
fn check_scene(name: &str, shapes: &[Shape], rays: &[Ray], rng: &mut Pcg32) -> usize {
    let layouts = all_layouts();
    let accels: Vec<Vec<Accel>> = layouts
        .iter()
        .map(|&layout| {
            Simd::available()
                .into_iter()
                .map(|simd| Accel::build_layout(shapes, |_| false, simd, layout))
                .collect()
        })
        .collect();
    assert_eq!(accels[0][0].simd(), Simd::Scalar);
    let binary = Bvh::build(&boxes(shapes));
    let mut hits = 0;
    for (k, ray) in rays.iter().enumerate() {
        let t_max = if k % 3 == 0 {
            rng.uniform_f32() * 4.0
        } else {
            f32::INFINITY
        };
        let brute = brute_force(shapes, ray, t_max);
        let old = binary.intersect(ray, t_max, |i, t| test_shape(&shapes[i as usize], ray, t));
        for accel in accels.iter().flatten() {
            // Within a node layout every kernel and leaf layout walks the same order: the
            // same hit, bit for bit.
            let nodes = accel.layout().nodes;
            let scalar = accels[layouts.iter().position(|l| *l == nodes.into()).unwrap()][0]
                .intersect(ray, t_max, accept_all);
            let simd = (accel.layout(), accel.simd());
            let new = accel.intersect(ray, t_max, accept_all);
            assert_eq!(
                new.map(|h| (h.prim, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits())),
                scalar.map(|h| (h.prim, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits())),
                "{name}: ray {k} ({ray:?}): {simd:?} vs scalar kernels"
            );
            let new_pt = new.map(|h: Hit| (h.prim, h.t));
            for (what, reference) in [("brute force", brute), ("binary BVH", old)] {
                match (new_pt, reference) {
                    (None, None) => {}
                    (Some((p, t)), Some((q, s))) => {
                        assert_eq!(
                            t.to_bits(),
                            s.to_bits(),
                            "{name} {simd:?}: ray {k} ({ray:?}): t {t} vs {what} {s}"
                        );
                        if p != q {
                            let tie = test_shape(&shapes[p as usize], ray, f32::INFINITY);
                            assert_eq!(
                                tie.map(f32::to_bits),
                                Some(s.to_bits()),
                                "{name} {simd:?}: ray {k}: prim {p} vs {what} {q}, and not a tie"
                            );
                        }
                    }
                    _ => panic!(
                        "{name} {simd:?}: ray {k} ({ray:?}): {new_pt:?} vs {what} {reference:?}"
                    ),
                }
            }
            assert_eq!(
                accel.occluded(ray, t_max, accept_all),
                brute.is_some(),
                "{name} {simd:?}: ray {k}: any-hit disagrees"
            );
        }
        hits += brute.is_some() as usize;
    }
    hits
}

/// Each node layout with each leaf layout.
fn all_layouts() -> Vec<AccelLayout> {
    [NodeLayout::Full, NodeLayout::Quantized]
        .into_iter()
        .flat_map(|nodes| {
            [LeafLayout::Inline, LeafLayout::Indexed].map(|leaves| AccelLayout { nodes, leaves })
        })
        .collect()
}

/// Every kernel set the CPU has, with each layout.
fn kernels_and_layouts() -> Vec<(Simd, AccelLayout)> {
    Simd::available()
        .into_iter()
        .flat_map(|s| all_layouts().into_iter().map(move |l| (s, l)))
        .collect()
}

fn random_soup(rng: &mut Pcg32, n: usize, spheres: usize) -> Vec<Shape> {
    let mut s: Vec<Shape> = (0..n)
        .map(|_| {
            let c = v3(rng) * 10.0;
            let size = 0.1 + 3.0 * rng.uniform_f32().powi(2);
            Shape::Triangle([c, c + (v3(rng) - 0.5) * size, c + (v3(rng) - 0.5) * size])
        })
        .collect();
    s.extend((0..spheres).map(|_| Shape::Sphere {
        center: v3(rng) * 10.0,
        radius: 0.05 + 0.5 * rng.uniform_f32(),
    }));
    s
}

/// A bumpy height field of `n`×`n` quads: triangles sharing edges and vertices.
fn height_field(n: usize, scale: f32) -> Vec<Shape> {
    let p = |i: usize, j: usize| {
        let (x, z) = (i as f32 / n as f32, j as f32 / n as f32);
        Vec3::new(x, 0.1 * (9.0 * x).sin() * (7.0 * z).cos(), z) * scale
    };
    let mut s = Vec::new();
    for i in 0..n {
        for j in 0..n {
            s.push(Shape::Triangle([p(i, j), p(i + 1, j), p(i + 1, j + 1)]));
            s.push(Shape::Triangle([p(i, j), p(i + 1, j + 1), p(i, j + 1)]));
        }
    }
    s
}

fn bounds_of(shapes: &[Shape]) -> Aabb {
    boxes(shapes)
        .into_iter()
        .filter(|b| b.min.is_finite() && b.max.is_finite())
        .fold(Aabb::EMPTY, Aabb::union)
}

#[test]
fn same_hits_as_brute_force_and_the_binary_bvh() {
    let mut rng = Pcg32::new(2024, 1);
    let mut scenes: Vec<(&str, Vec<Shape>)> = vec![
        ("soup", random_soup(&mut rng, 3000, 60)),
        ("height field", height_field(40, 5.0)),
        ("huge scale", height_field(12, 1e12)),
        ("tiny scale", height_field(12, 1e-12)),
    ];
    // Many copies of one triangle: coincident centroids, median splits.
    let one = Shape::Triangle([Vec3::ZERO, Vec3::X, Vec3::Y]);
    scenes.push(("coincident", vec![one; 300]));
    // Positions at 2^-i: a maximally unbalanced SAH tree, deeper than the depth cap.
    scenes.push((
        "geometric",
        (0..400)
            .map(|i| {
                let x = 0.97f32.powi(i);
                Shape::Triangle([
                    Vec3::new(x, 0.0, 0.0),
                    Vec3::new(x, 1.0, 0.0),
                    Vec3::new(x, 0.0, 1.0),
                ])
            })
            .collect(),
    ));
    // Zero-area and non-finite triangles mixed with ordinary ones.
    let mut degenerate = random_soup(&mut rng, 200, 5);
    degenerate.push(Shape::Triangle([Vec3::ONE; 3]));
    degenerate.push(Shape::Triangle([Vec3::ZERO, Vec3::ONE, Vec3::splat(2.0)]));
    degenerate.push(Shape::Triangle([
        Vec3::ZERO,
        Vec3::X,
        Vec3::splat(f32::NAN),
    ]));
    degenerate.push(Shape::Triangle([
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(0.0, f32::INFINITY, 0.0),
    ]));
    degenerate.push(Shape::Sphere {
        center: Vec3::splat(3.0),
        radius: 0.0,
    });
    scenes.push(("degenerate", degenerate));
    scenes.push(("one triangle", vec![one]));
    scenes.push(("one block", one_block(&mut rng)));
    scenes.push(("one node", one_node(&mut rng)));
    scenes.push(("empty", vec![]));

    for (name, shapes) in &scenes {
        let rays = random_rays(&mut rng, shapes, bounds_of(shapes), 6000);
        let hits = check_scene(name, shapes, &rays, &mut rng);
        eprintln!(
            "{name}: {} shapes, {} rays, {hits} hit",
            shapes.len(),
            rays.len()
        );
        if !matches!(*name, "empty") {
            assert!(hits > 100, "{name}: too few hits ({hits}) to test anything");
        }
    }
    // An instance's BLAS is traced with object-space rays, whose directions are scaled by
    // the instance's inverse transform: the same checks on rays that are not unit.
    let soup = &scenes[0].1;
    let rays: Vec<Ray> = random_rays(&mut rng, soup, bounds_of(soup), 6000)
        .into_iter()
        .enumerate()
        .map(|(i, r)| Ray::new(r.o, r.d * [0.1, 3.0, 17.0][i % 3]))
        .collect();
    let hits = check_scene("soup, rays not unit", soup, &rays, &mut rng);
    assert!(hits > 1000, "rays not unit: only {hits} hits");
}

/// Five triangles and three spheres whose boxes all nearly fill the unit cube: no split
/// pays, so the tree is one leaf.
fn one_block(rng: &mut Pcg32) -> Vec<Shape> {
    let mut near = |c: Vec3| c + (v3(rng) - 0.5) * 0.2;
    let mut shapes = Vec::new();
    for _ in 0..5 {
        let v = [
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 1.0),
        ]
        .map(&mut near);
        shapes.push(Shape::Triangle(v));
    }
    for _ in 0..3 {
        shapes.push(Shape::Sphere {
            center: near(Vec3::splat(0.5)),
            radius: 0.5,
        });
    }
    shapes
}

/// Three clusters of five triangles and a sphere, far apart, and ten copies of one
/// triangle: a tree of one node over four or more leaves, whose boxes a ray may enter in
/// any order.
fn one_node(rng: &mut Pcg32) -> Vec<Shape> {
    let mut shapes = Vec::new();
    for corner in [
        Vec3::ZERO,
        Vec3::new(4.0, 0.0, 0.0),
        Vec3::new(0.0, 4.0, 4.0),
    ] {
        let mut block = one_block(rng);
        block.truncate(6);
        for s in &mut block {
            match s {
                Shape::Triangle(v) => v.iter_mut().for_each(|p| *p += corner),
                Shape::Sphere { center, .. } => *center += corner,
            }
        }
        shapes.extend(block);
    }
    // Ten copies of one triangle: more than a leaf holds, so two leaves with the same box,
    // entered at the same distance, with hits at the same distance (ties the order of
    // the leaves decides).
    shapes.extend((0..10).map(|_| Shape::Triangle(COPIED.map(|p| p + COPIES_AT))));
    shapes
}

/// The triangle `one_node` copies, and where.
const COPIED: [Vec3; 3] = [
    Vec3::ZERO,
    Vec3::new(1.0, 1.0, 0.0),
    Vec3::new(0.0, 1.0, 1.0),
];
const COPIES_AT: Vec3 = Vec3::new(4.0, 4.0, 0.0);

/// A tree of one leaf is recognised (its queries skip the box test; the scenes "one
/// triangle" and "one block" above check their hits), and one that needs two leaves is not.
#[test]
fn a_tree_of_one_leaf_is_recognised() {
    let mut rng = Pcg32::new(35, 2);
    let sole = |shapes: &[Shape]| {
        let boxes = boxes(shapes);
        let bvh = Bvh::build_from(boxes.len(), |i| boxes[i], SahCost::BLOCKS);
        WideBvh::collapse(&bvh).sole_leaf()
    };
    let one = Shape::Triangle([Vec3::ZERO, Vec3::X, Vec3::Y]);
    assert_eq!(sole(&[one]), Some((0, 1)));
    assert_eq!(sole(&[one; 8]), Some((0, 8)));
    for _ in 0..20 {
        assert_eq!(sole(&one_block(&mut rng)), Some((0, 8)));
    }
    // More than a leaf holds.
    assert_eq!(sole(&[one; 9]), None);
    assert_eq!(sole(&random_soup(&mut rng, 40, 4)), None);
    assert_eq!(sole(&[]), None);
}

/// The queries of trees of one node (one leaf; several leaves) return exactly what the
/// traversal returns on the same structure (the same primitive even in ties, the same
/// bits), with every kernel and layout: the images do not change where they apply.
#[test]
fn small_trees_find_the_traversals_hits() {
    let mut rng = Pcg32::new(35, 4);
    let scenes = [
        ("one block", one_block(&mut rng)),
        ("one node", one_node(&mut rng)),
        ("one node", one_node(&mut rng)),
    ];
    let key = |h: Option<Hit>| h.map(|h| (h.prim, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()));
    for (name, shapes) in &scenes {
        let mut rays = random_rays(&mut rng, shapes, bounds_of(shapes), 6000);
        // At the copied triangle (two leaves with the same box): ties between leaves.
        let centroid = (COPIED[0] + COPIED[1] + COPIED[2]) / 3.0 + COPIES_AT;
        rays.extend((0..2000).map(|_| {
            let aim = centroid + (v3(&mut rng) - 0.5) * 0.3;
            let d = (v3(&mut rng) - 0.5).normalize_or(Vec3::Y);
            Ray::new(aim - d * 8.0, d)
        }));
        let mut hits = 0;
        for (simd, layout) in kernels_and_layouts() {
            let accel = Accel::build_layout(shapes, |_| false, simd, layout);
            let traversal = accel.clone().without_shortcut();
            for (k, ray) in rays.iter().enumerate() {
                let t_max = [f32::INFINITY, 6.0, 0.5][k % 3];
                let (a, b) = (
                    accel.intersect(ray, t_max, accept_all),
                    traversal.intersect(ray, t_max, accept_all),
                );
                assert_eq!(
                    key(a),
                    key(b),
                    "{name} {simd:?} {layout:?}: ray {k} {ray:?}"
                );
                assert_eq!(
                    accel.occluded(ray, t_max, accept_all),
                    b.is_some(),
                    "{name} {simd:?} {layout:?}: any-hit, ray {k}"
                );
                hits += b.is_some() as usize;
            }
        }
        assert!(hits > 10000, "{name}: only {hits} hits");
    }
}

/// A tree of one node over several leaves is recognised (its queries take no stack; the
/// scene "one node" above checks their hits with every kernel and layout), and a bigger
/// one is not.
#[test]
fn a_tree_of_one_node_is_recognised() {
    let mut rng = Pcg32::new(35, 3);
    let tree = |shapes: &[Shape]| {
        let boxes = boxes(shapes);
        let bvh = Bvh::build_from(boxes.len(), |i| boxes[i], SahCost::BLOCKS);
        WideBvh::collapse(&bvh)
    };
    for _ in 0..20 {
        let wide = tree(&one_node(&mut rng));
        let root = wide.sole_node().expect("one node");
        assert!(root.leaves.count_ones() >= 4, "{} leaves", root.leaves);
        assert_eq!(wide.sole_leaf(), None);
    }
    let one = Shape::Triangle([Vec3::ZERO, Vec3::X, Vec3::Y]);
    assert!(tree(&[one]).sole_node().is_some());
    assert!(tree(&random_soup(&mut rng, 400, 4)).sole_node().is_none());
    assert!(tree(&[]).sole_node().is_none());
}

#[test]
fn rays_inside_box_planes_and_non_finite_rays() {
    // A unit cube of 12 triangles; rays lying exactly in its face planes, along the axes.
    let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let q = |a, b, cc, d| [Shape::Triangle([a, b, cc]), Shape::Triangle([a, cc, d])];
    let mut cube = Vec::new();
    for (a, b, cc, d) in [
        (c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)),
        (c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.)),
        (c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)),
        (c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)),
        (c(0., 0., 0.), c(0., 1., 0.), c(1., 1., 0.), c(1., 0., 0.)),
        (c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)),
    ] {
        cube.extend(q(a, b, cc, d));
    }
    let mut rays = Vec::new();
    for i in 0..=8 {
        for j in 0..=8 {
            let (u, v) = (i as f32 / 8.0, j as f32 / 8.0);
            for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
                rays.push(Ray::new(
                    Vec3::new(u, v, -1.0) * (1.0 - d.z.abs()) + Vec3::new(u, -1.0, v) * d.z.abs(),
                    d,
                ));
                rays.push(Ray::new(Vec3::new(-0.5, u, v) + d * 0.0, d));
            }
        }
    }
    let mut rng = Pcg32::new(5, 5);
    check_scene("cube planes", &cube, &rays, &mut rng);
    for (simd, layout) in kernels_and_layouts() {
        let accel = Accel::build_layout(&cube, |_| false, simd, layout);
        for bad in [
            Ray::new(Vec3::splat(f32::NAN), Vec3::X),
            Ray::new(Vec3::splat(0.5), Vec3::splat(f32::NAN)),
            Ray::new(Vec3::splat(f32::INFINITY), -Vec3::X),
        ] {
            assert!(accel.intersect(&bad, f32::INFINITY, accept_all).is_none());
            assert!(!accel.occluded(&bad, f32::INFINITY, accept_all));
        }
    }
}

#[test]
fn rejected_hits_are_as_if_the_triangles_were_not_there() {
    let mut rng = Pcg32::new(77, 3);
    let shapes = random_soup(&mut rng, 3000, 40);
    let masked = |i: u32| i % 2 == 1 && matches!(shapes[i as usize], Shape::Triangle(_));
    let kept: Vec<u32> = (0..shapes.len() as u32).filter(|&i| !masked(i)).collect();
    let kept_shapes: Vec<Shape> = kept.iter().map(|&i| shapes[i as usize]).collect();
    let rays = random_rays(&mut rng, &shapes, bounds_of(&shapes), 8000);
    for (simd, layout) in kernels_and_layouts() {
        let with_filter = Accel::build_layout(&shapes, masked, simd, layout);
        let without = Accel::build_layout(&kept_shapes, |_| false, simd, layout);
        let calls = std::cell::Cell::new(0usize);
        let reject_odd = |i: u32, _: &_| {
            calls.set(calls.get() + 1);
            assert!(masked(i), "the filter is called only for flagged triangles");
            false
        };
        let mut hits = 0;
        for (k, ray) in rays.iter().enumerate() {
            let t_max = if k % 4 == 0 { 3.0 } else { f32::INFINITY };
            let a = with_filter.intersect(ray, t_max, reject_odd);
            let b = without.intersect(ray, t_max, accept_all);
            assert_eq!(
                a.map(|h| (h.prim, h.t.to_bits())),
                b.map(|h| (kept[h.prim as usize], h.t.to_bits())),
                "{simd:?} {layout:?} ray {k}"
            );
            assert_eq!(
                with_filter.occluded(ray, t_max, reject_odd),
                b.is_some(),
                "{simd:?} {layout:?} ray {k}"
            );
            hits += b.is_some() as usize;
        }
        assert!(hits > 1000, "{simd:?} {layout:?}: only {hits} hits");
        assert!(
            calls.get() > 1000,
            "{simd:?} {layout:?}: filter called only {} times",
            calls.get()
        );
        // Accepting everything is the same as no flags at all.
        let plain = Accel::build_layout(&shapes, |_| false, simd, layout);
        for ray in &rays {
            assert_eq!(
                with_filter.intersect(ray, f32::INFINITY, accept_all),
                plain.intersect(ray, f32::INFINITY, accept_all)
            );
            assert_eq!(
                with_filter.occluded(ray, f32::INFINITY, accept_all),
                plain.occluded(ray, f32::INFINITY, accept_all)
            );
        }
        eprintln!(
            "{simd:?} {layout:?}: {} rays, {hits} hit, filter called {} times",
            rays.len(),
            calls.get()
        );
    }
}

/// A scene given by reference to its meshes' shared vertex arrays (`Geometry`: an
/// indexed height field, an alpha-flagged indexed soup and spheres) builds the same
/// structure as the same primitives given one by one: with either leaf layout and every
/// kernel, each ray's nearest hit is the same primitive with the same bits, its any-hit
/// answer the same, and a flagged triangle reaches the filter with the same id.
#[test]
fn shared_vertices_give_the_hits_of_the_primitives_one_by_one() {
    let n = 40;
    let grid: Vec<Vec3> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .map(|(i, j)| {
            let (x, z) = (i as f32 / n as f32, j as f32 / n as f32);
            Vec3::new(x, 0.1 * (9.0 * x).sin() * (7.0 * z).cos(), z) * 4.0
        })
        .collect();
    let at = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let field: Vec<[u32; 3]> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            [
                [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
            ]
        })
        .collect();
    let mut rng = Pcg32::new(40, 1);
    let soup_points: Vec<Vec3> = (0..600).map(|_| v3(&mut rng) * 4.0).collect();
    let soup: Vec<[u32; 3]> = (0..400)
        .map(|_| [0; 3].map(|_| rng.next_u32() % soup_points.len() as u32))
        .collect();
    let spheres: Vec<(Vec3, f32)> = (0..30)
        .map(|_| (v3(&mut rng) * 4.0, 0.05 + 0.2 * rng.uniform_f32()))
        .collect();
    let geometry = Geometry::new(
        vec![
            TriangleMesh {
                positions: &grid,
                indices: &field,
                filtered: false,
            },
            TriangleMesh {
                positions: &soup_points,
                indices: &soup,
                filtered: true,
            },
        ],
        spheres.clone(),
    );
    let shapes: Vec<Shape> = (0..geometry.len() as u32)
        .map(|i| geometry.shape(i))
        .collect();
    let filtered = |i: u32| geometry.filtered(i);
    // Rejects a flagged triangle when its id is odd.
    let even = |i: u32, _: &_| i.is_multiple_of(2);
    let rays = random_rays(&mut rng, &shapes, bounds_of(&shapes), 6000);
    let (mut hits, mut filtered_hits) = (0, 0);
    for (simd, layout) in kernels_and_layouts() {
        let one_by_one = Accel::build_layout(&shapes, filtered, simd, layout);
        let shared = Accel::build_geometry(&geometry, simd, layout);
        assert_eq!(shared.layout(), layout);
        for (k, ray) in rays.iter().enumerate() {
            let t_max = if k % 4 == 0 { 3.0 } else { f32::INFINITY };
            let bits = |h: Option<Hit>| h.map(|h| (h.prim, [h.t, h.b1, h.b2].map(f32::to_bits)));
            let a = one_by_one.intersect(ray, t_max, even);
            assert_eq!(
                bits(shared.intersect(ray, t_max, even)),
                bits(a),
                "{simd:?} {layout:?} ray {k}"
            );
            assert_eq!(
                shared.occluded(ray, t_max, even),
                one_by_one.occluded(ray, t_max, even),
                "{simd:?} {layout:?} ray {k}"
            );
            hits += a.is_some() as usize;
            filtered_hits += a.is_some_and(|h| filtered(h.prim)) as usize;
        }
    }
    // Thresholds: most rays aim at a primitive; the soup is a fifth of the triangles.
    let runs = kernels_and_layouts().len();
    assert!(hits > runs * 2000, "only {hits} hits in {runs} runs");
    assert!(
        filtered_hits > runs * 100,
        "only {filtered_hits} filtered hits"
    );
}
