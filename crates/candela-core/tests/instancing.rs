//! Instanced meshes against the same meshes flattened into world space: the same hits on
//! random rays, the triangles stored once, and renders that agree.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use candela_core::desc::*;
use candela_core::geometry::Ray;
use candela_core::sampler::mix64;
use candela_core::scene::Prim;
use candela_core::Scene;
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};

/// A deterministic uniform number in [0, 1) from a counter.
fn uniform(state: &mut u64) -> f32 {
    *state += 1;
    (mix64(*state) >> 40) as f32 / (1u64 << 24) as f32
}

/// A uniform point of the cube [−h, h]³.
fn uniform_in_cube(state: &mut u64, h: f32) -> Vec3 {
    let x = uniform(state);
    let y = uniform(state);
    let z = uniform(state);
    Vec3::new(x, y, z) * (2.0 * h) - h
}

/// A bumpy sphere of `2·rings·segments` triangles with normals, uvs and tangents, so that
/// every attribute the hit record carries goes through the instance transform.
fn bumpy_sphere(rings: u32, segments: u32) -> MeshDesc {
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
            let r = 1.0 + 0.15 * (3.0 * phi).sin() * (4.0 * theta).sin();
            m.positions.push(dir * r);
            // Deliberately not unit length: the build normalises after transforming.
            m.normals.push(dir * 2.0);
            m.uvs.push(Vec2::new(
                j as f32 / segments as f32,
                i as f32 / rings as f32,
            ));
            m.tangents.push(Vec4::new(
                -phi.sin(),
                0.0,
                phi.cos(),
                if j % 2 == 0 { 1.0 } else { -1.0 },
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

/// Random placements: rotation, non-uniform scale (condition number up to 3), every
/// third one mirrored, translation within a 20-unit box.
fn placements(n: usize, state: &mut u64) -> Vec<Mat4> {
    (0..n)
        .map(|k| {
            let axis = Vec3::new(
                uniform(state) - 0.5,
                uniform(state) - 0.5,
                uniform(state) - 0.5,
            )
            .normalize();
            let rot = Quat::from_axis_angle(axis, uniform(state) * std::f32::consts::TAU);
            let mut scale = Vec3::new(
                0.5 + uniform(state),
                0.5 + uniform(state),
                0.5 + uniform(state),
            );
            if k % 3 == 0 {
                scale.x = -scale.x;
            }
            let t = Vec3::new(uniform(state), uniform(state), uniform(state)) * 20.0 - 10.0;
            Mat4::from_scale_rotation_translation(scale, rot, t)
        })
        .collect()
}

fn base_desc() -> SceneDesc {
    let mut desc = SceneDesc {
        render: RenderSettings {
            width: 24,
            height: 24,
            spp: 16,
            ..Default::default()
        },
        ..Default::default()
    };
    desc.materials
        .push(MaterialDesc::diffuse("white", Vec3::splat(0.7)));
    desc
}

/// The same placements of `mesh`: one shared `Arc` (instanced) or a copy per shape
/// (flattened).
fn scene_pair(mesh: &MeshDesc, transforms: &[Mat4], base: &SceneDesc) -> (Scene, Scene) {
    let shared = Arc::new(mesh.clone());
    let mut scenes = [true, false].map(|instanced| {
        let mut desc = base.clone();
        for (k, &transform) in transforms.iter().enumerate() {
            let geometry = if instanced {
                shared.clone()
            } else {
                Arc::new(mesh.clone())
            };
            desc.shapes.push(
                ShapeDesc::mesh(geometry, "white")
                    .transformed(transform)
                    .with_flipped_normals(k % 4 == 1),
            );
        }
        Some(candela_core::build::build(&desc).unwrap())
    });
    (scenes[0].take().unwrap(), scenes[1].take().unwrap())
}

/// (shape index, triangle, t, barycentrics) of the nearest hit, read from the structure
/// that found it.
fn raw_hit(scene: &Scene, ray: &Ray) -> Option<(u32, u32, f32, Vec2)> {
    let flat = scene.accel.intersect(ray, f32::INFINITY, |_, _| true);
    let inst = scene
        .instances
        .intersect(ray, flat.map_or(f32::INFINITY, |h| h.t), |_, _, _| true);
    if let Some(h) = inst {
        return Some((h.instance, h.tri, h.t, Vec2::new(h.b1, h.b2)));
    }
    flat.map(|h| match scene.prims[h.prim as usize] {
        Prim::Triangle { mesh, tri } => (mesh, tri, h.t, Vec2::new(h.b1, h.b2)),
        Prim::Sphere(_) => unreachable!("no spheres here"),
    })
}

fn near_edge(b: Vec2) -> bool {
    b.x.min(b.y).min(1.0 - b.x - b.y) < 1e-4
}

/// Random rays through the 20-unit box: the instanced scene hits the same triangle of the
/// same shape as the flattened one, at the same t and point within 2·10⁻⁵ of the ray's
/// scale (|o| + t·|d|), with the same frame.
///
/// Why that bound: the instanced ray is W·o and W·d, W the inverse placement, each a
/// 3-term dot product (rounding ≤ γ₃ ≈ 1.8·10⁻⁷ relative to |o| and |d|), then amplified by
/// the condition number of the placement (≤ 3 here) and by the triangle test's own
/// rounding of the translated vertices (another few γ); ~10⁻⁶ relative is the expected
/// size, so 2·10⁻⁵ leaves an order of magnitude. A wrong transform (transposed, inverse
/// not taken, t rescaled by a renormalised direction) is off by O(1).
///
/// Which triangle is hit may differ only where the hit lies within 10⁻⁴ (barycentric) of
/// an edge, where the two arithmetics may legitimately disagree; at most 0.2 % of hits.
#[test]
fn instanced_hits_equal_flattened_hits() {
    let mut state = 7;
    let mesh = bumpy_sphere(16, 24);
    let transforms = placements(24, &mut state);
    let (inst, flat) = scene_pair(&mesh, &transforms, &base_desc());
    assert_eq!(inst.instances.instances.len(), 24);
    assert!(inst.meshes.is_empty());
    assert!(flat.instances.is_empty());
    assert_eq!(flat.meshes.len(), 24);
    // The instances' boxes are their object boxes' corners carried over: they contain
    // the flattened triangles' box.
    let bi = inst.bounds();
    let bf = flat.bounds();
    assert!(bi.min.cmple(bf.min).all() && bi.max.cmpge(bf.max).all());

    let (n, mut hits, mut edge_mismatch) = (40_000, 0, 0);
    let mut worst = 0.0f32;
    for _ in 0..n {
        let o = uniform_in_cube(&mut state, 15.0);
        let target = uniform_in_cube(&mut state, 10.0);
        // Not unit length, so a renormalised object-space direction would show in t.
        let ray = Ray::new(o, (target - o) * (0.3 + uniform(&mut state)));
        let (a, b) = (raw_hit(&inst, &ray), raw_hit(&flat, &ray));
        match (a, b) {
            (None, None) => {}
            (Some((sa, ta, t_a, ba)), Some((sb, tb, t_b, bb))) => {
                hits += 1;
                let scale = ray.o.length() + t_b * ray.d.length();
                if (sa, ta) != (sb, tb) {
                    assert!(
                        near_edge(ba) && near_edge(bb),
                        "different triangles away from an edge: {a:?} vs {b:?}"
                    );
                    edge_mismatch += 1;
                    continue;
                }
                let dt = (t_a - t_b).abs() * ray.d.length() / scale;
                worst = worst.max(dt);
                assert!(dt < 2e-5, "t {t_a} vs {t_b} (relative {dt})");
                let (ia, ib) = (
                    inst.intersect(&ray, f32::INFINITY).unwrap(),
                    flat.intersect(&ray, f32::INFINITY).unwrap(),
                );
                let dp = (ia.p - ib.p).length() / scale;
                worst = worst.max(dp);
                assert!(dp < 2e-5, "p {} vs {} (relative {dp})", ia.p, ib.p);
                assert_eq!(ia.ng, ib.ng, "the geometric normal is made the same way");
                // The shading attributes interpolate bit-identical world-space vertex
                // values, so they differ only by the barycentrics' difference db (L1):
                // unit tangents move by at most db, unit normals by db over the
                // interpolated normal's length (≥ 1/2 on this mesh), uvs in [0,1]² by
                // √2·db. A wrongly carried normal or tangent is off by O(1).
                let db = (ba.x - bb.x).abs()
                    + (ba.y - bb.y).abs()
                    + ((1.0 - ba.x - ba.y) - (1.0 - bb.x - bb.y)).abs();
                assert!(
                    (ia.ns - ib.ns).length() <= 4.0 * db + 1e-5,
                    "ns {} vs {} (db {db})",
                    ia.ns,
                    ib.ns
                );
                assert!(
                    (ia.dpdu - ib.dpdu).length() <= db + 1e-5,
                    "dpdu {} vs {} (db {db})",
                    ia.dpdu,
                    ib.dpdu
                );
                assert!((ia.uv - ib.uv).length() <= 1.5 * db + 1e-6);
                assert_eq!(ia.bitangent_sign, ib.bitangent_sign);
                assert_eq!(ia.material, ib.material);
            }
            _ => {
                let (_, _, _, bary) = a.or(b).unwrap();
                assert!(
                    near_edge(bary),
                    "hit in one, miss in the other, away from an edge: {a:?} vs {b:?}"
                );
                edge_mismatch += 1;
            }
        }
        // The shadow query agrees with the closest-hit query (both structures).
        for s in [&inst, &flat] {
            let t = raw_hit(s, &ray).map_or(f32::INFINITY, |h| h.2);
            if t.is_finite() {
                assert!(s.occluded(&ray, t * 1.001));
                assert!(!s.occluded(&ray, t * 0.999));
            } else {
                assert!(!s.occluded(&ray, f32::INFINITY));
            }
        }
    }
    eprintln!(
        "{hits} hits of {n} rays, {edge_mismatch} differ at an edge, worst relative error {worst:.2e}"
    );
    assert!(hits > n / 10, "the rays must hit something: {hits}");
    assert!(
        edge_mismatch * 500 <= hits,
        "{edge_mismatch} edge mismatches"
    );
}

/// N instances of an M-triangle mesh store M triangles (and render N·M); flattened, they
/// store N·M.
#[test]
fn instances_store_their_mesh_once() {
    let mesh = bumpy_sphere(10, 20);
    let m = mesh.indices.len();
    let mut state = 3;
    let transforms = placements(50, &mut state);
    let (inst, flat) = scene_pair(&mesh, &transforms, &base_desc());
    assert_eq!(inst.stored_triangle_count(), m);
    assert_eq!(inst.triangle_count(), 50 * m);
    assert_eq!(flat.stored_triangle_count(), 50 * m);
    assert_eq!(flat.triangle_count(), 50 * m);
}

/// A mesh placed once, or by emitting shapes, stays flattened: area lights are per
/// triangle in world space, and a single placement gains nothing from a BLAS.
#[test]
fn single_and_emitting_meshes_stay_flattened() {
    let mesh = Arc::new(bumpy_sphere(4, 6));
    let mut desc = base_desc();
    for (k, emission) in [None, Some(Vec3::ONE), Some(Vec3::ONE)]
        .into_iter()
        .enumerate()
    {
        desc.shapes.push(
            ShapeDesc::mesh(mesh.clone(), "white")
                .transformed(Mat4::from_translation(Vec3::X * 3.0 * k as f32))
                .with_emission(emission),
        );
    }
    let scene = candela_core::build::build(&desc).unwrap();
    assert!(scene.instances.is_empty());
    assert_eq!(scene.meshes.len(), 3);
    assert_eq!(scene.stored_triangle_count(), 3 * mesh.indices.len());
}

/// Renders of a lit scene of instances and of the same scene flattened, with the same
/// seed, agree pixel for pixel. The instanced hit record equals the flattened one bit for
/// bit at equal barycentrics, the barycentrics differ by ~10⁻⁶ (the test above), and every
/// sampling decision comes from the sampler, not from the hit point: so the same sample
/// stream follows the same path and each pixel agrees to float rounding, except where a
/// path meets an edge within that 10⁻⁶ and goes elsewhere. Bounds: every pixel within
/// 10⁻³ relative (+10⁻⁵) but at most 1 % of pixels, and the image mean within 10⁻³
/// relative. (Measured: all 576 pixels within 4·10⁻⁷, image mean 0.044.) A misplaced or mis-shaded
/// instance changes whole regions of the image.
///
/// Why not a test across independent seeds: this scene's noise is heavy-tailed (a small
/// light seen through bounces), and Welch's t over a dozen seeds rejected at |t| = 4.35
/// between two correct renders; the paired comparison is both stricter and reliable.
#[test]
fn instanced_render_matches_flattened_render() {
    let mesh = bumpy_sphere(8, 12);
    let transforms: Vec<Mat4> = (0..9)
        .map(|k| {
            let (x, y) = ((k % 3) as f32 - 1.0, (k / 3) as f32 - 1.0);
            Mat4::from_translation(Vec3::new(x * 2.5, y * 2.5, 0.0))
                * Mat4::from_rotation_y(k as f32)
                * Mat4::from_scale(Vec3::new(if k % 2 == 0 { 1.0 } else { -0.8 }, 1.0, 0.7))
        })
        .collect();
    let mut base = base_desc();
    base.camera.position = Vec3::new(0.0, 0.0, 12.0);
    base.camera.look_at = Vec3::ZERO;
    base.camera.fov_y_deg = 50.0;
    base.render.max_depth = 4;
    base.render.spp = 32;
    // A backdrop, and a large emitting rectangle (both flattened) on the camera's side.
    for (emission, transform) in [
        (
            Some(Vec3::splat(3.0)),
            Mat4::from_translation(Vec3::new(2.0, 4.0, 9.0))
                * Mat4::from_rotation_x(0.6)
                * Mat4::from_scale(Vec3::splat(5.0)),
        ),
        (
            None,
            Mat4::from_translation(Vec3::new(0.0, 0.0, -3.0)) * Mat4::from_scale(Vec3::splat(20.0)),
        ),
    ] {
        base.shapes.push(
            ShapeDesc::new(GeometryDesc::Rectangle, "white")
                .transformed(transform)
                .with_emission(emission)
                .with_flipped_normals(emission.is_some()),
        );
    }
    let (inst, flat) = scene_pair(&mesh, &transforms, &base);
    assert_eq!(inst.instances.instances.len(), 9);
    let render = |scene: &Scene| {
        candela_core::integrator::render(
            scene,
            0..scene.settings.spp,
            &AtomicBool::new(false),
            &|_| {},
        )
        .film
        .resolve()
    };
    let (a, b) = (render(&inst), render(&flat));
    let lum = |p: Vec3| (p.x + p.y + p.z) as f64 / 3.0;
    let (mut differ, mut worst) = (0, 0.0f32);
    for (x, y) in a.iter().zip(&b) {
        let d = (*x - *y).abs().max_element();
        worst = worst.max(d);
        if d > 1e-3 * y.max_element() + 1e-5 {
            differ += 1;
        }
    }
    let (ma, mb) = (
        a.iter().map(|&p| lum(p)).sum::<f64>() / a.len() as f64,
        b.iter().map(|&p| lum(p)).sum::<f64>() / b.len() as f64,
    );
    eprintln!(
        "image means: instanced {ma:.6}, flattened {mb:.6}; {differ} of {} pixels differ, \
         worst {worst:.2e}",
        a.len()
    );
    assert!(mb > 0.02, "the scene must be lit: {mb}");
    assert!(differ * 100 <= a.len(), "{differ} pixels differ");
    assert!((ma - mb).abs() <= 1e-3 * mb, "means {ma} vs {mb}");
}

/// Alpha-masked instances cut out the same holes as the flattened mesh: a checker mask
/// (α = 1 or 0 in squares of 1/8 of the uv range, cutoff 0.5) on every placement. Both the
/// closest hit and the shadow query agree on at least 99.8 % of the rays; the rest may
/// differ only where a hit's uv lies within 10⁻³ of a checker edge (the barycentrics, so
/// the uvs, differ by ~10⁻⁶).
#[test]
fn alpha_masked_instances_cut_the_same_holes() {
    let mut base = base_desc();
    base.materials[0].bsdf = BsdfDesc::Alpha {
        alpha: AlphaDesc {
            mode: candela_core::alpha::AlphaMode::Mask { cutoff: 0.5 },
            factor: 1.0,
            texture: Some(TextureDesc::Checker {
                a: Vec3::ONE,
                b: Vec3::ZERO,
                uv_transform: glam::Affine2::from_scale(Vec2::splat(8.0)),
            }),
        },
        inner: Box::new(base.materials[0].bsdf.clone()),
    };
    let mut state = 11;
    let mesh = bumpy_sphere(12, 16);
    let (inst, flat) = scene_pair(&mesh, &placements(12, &mut state), &base);
    assert_eq!(inst.instances.instances.len(), 12);
    let near_checker_edge = |uv: Vec2| {
        let f = (uv * 8.0).fract();
        f.min(1.0 - f).min_element() < 1e-3
    };
    let (n, mut hits, mut holes, mut differ) = (20_000, 0, 0, 0);
    for _ in 0..n {
        let o = uniform_in_cube(&mut state, 15.0);
        let target = uniform_in_cube(&mut state, 10.0);
        let ray = Ray::new(o, target - o);
        let (a, b) = (
            inst.intersect(&ray, f32::INFINITY),
            flat.intersect(&ray, f32::INFINITY),
        );
        // Rays that meet a mesh where the unmasked scene has them but pass a hole.
        let raw = raw_hit(&flat, &ray);
        match (a, b) {
            (Some(x), Some(y)) if (x.p - y.p).length() <= 1e-4 * (1.0 + y.t) => hits += 1,
            (None, None) => {}
            _ => {
                let uvs = [a, b].into_iter().flatten().map(|h| h.uv);
                assert!(
                    uvs.clone().any(near_checker_edge),
                    "away from a checker edge: {a:?} vs {b:?}"
                );
                differ += 1;
            }
        }
        if raw.is_some_and(|r| b.is_none_or(|h| h.t > r.2 * 1.0001)) {
            holes += 1;
        }
        if inst.occluded(&ray, f32::INFINITY) != flat.occluded(&ray, f32::INFINITY) {
            differ += 1;
        }
    }
    eprintln!("{hits} equal hits, {holes} rays through holes, {differ} differ of {n}");
    assert!(holes > n / 50, "the mask must cut holes: {holes}");
    assert!(hits > n / 20, "{hits}");
    assert!(differ * 500 <= n, "{differ} differ");
}
