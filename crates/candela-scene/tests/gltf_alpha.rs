//! glTF alpha modes in the ray queries: a MASK'd quad is cut out exactly where its
//! texture's α falls below the cutoff, for camera (intersect) and shadow (occluded) rays
//! alike; a BLEND quad of α = a stops a fraction a of rays (binomial z test), so a
//! render through it sees the background with transmittance 1 − a.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use candela_core::desc::{BsdfDesc, TextureDesc};
use candela_core::geometry::Ray;
use candela_core::sampler::Pcg32;
use candela_core::Scene;
use candela_scene::gltf::parse_gltf;
use candela_scene::LoadOptions;
use candela_test_support::gltf::{png, Glb};
use glam::Vec3;
use serde_json::json;

/// A quad [-1, 1]² at z = 0 with the given material JSON (texture 0, if the material
/// uses one, is `texture`).
fn quad_scene(material: serde_json::Value, texture: Option<Vec<u8>>) -> Scene {
    let mut g = Glb::new();
    if let Some(t) = texture {
        g.texture(&t, Some(json!({"wrapS": 33071, "wrapT": 33071})));
    }
    let m = g.material(material);
    let q = g.quad(m);
    let mesh = g.mesh(vec![q]);
    g.node(json!({"mesh": mesh}), true);
    let desc = parse_gltf(
        &g.bytes(),
        Path::new("a.glb"),
        None,
        &LoadOptions::default(),
    )
    .unwrap()
    .desc;
    candela_core::build::build(&desc).unwrap()
}

/// |z| below 4: a correct implementation fails with probability 6·10⁻⁵ per check, while
/// the wrong fractions the checks guard against (a, 1 − a, 0, 1) sit dozens of σ away.
const Z_BOUND: f64 = 4.0;

fn z(hits: u32, n: u32, p: f64) -> f64 {
    (hits as f64 / n as f64 - p) / (p * (1.0 - p) / n as f64).sqrt()
}

#[test]
fn mask_cuts_out_where_alpha_is_below_the_cutoff_for_camera_and_shadow_rays() {
    // Two texels across: α = 0 on the left, 1 on the right; bilinear with clamp makes
    // α(u) = clamp(2u − 0.5, 0, 1), which crosses the cutoff ½ at u = ½, i.e. x = 0.
    let tex = png(2, 1, |x, _| [255, 255, 255, if x == 0 { 0 } else { 255 }]);
    let scene = quad_scene(
        json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
               "alphaMode": "MASK", "alphaCutoff": 0.5}),
        Some(tex),
    );
    let mut rng = Pcg32::new(7, 0);
    let n = 20_000;
    let (mut hits, mut blocked) = (0, 0);
    for _ in 0..n {
        let x = rng.uniform_f32() * 2.0 - 1.0;
        let y = rng.uniform_f32() * 2.0 - 1.0;
        let down = Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z);
        let hit = scene.intersect(&down, f32::INFINITY).is_some();
        let shadow = scene.occluded(&down, 2.0);
        if x.abs() > 1e-4 {
            assert_eq!(hit, x > 0.0, "camera ray at x = {x}");
            assert_eq!(shadow, x > 0.0, "shadow ray at x = {x}");
        }
        hits += hit as u32;
        blocked += shadow as u32;
    }
    // The kept half of uniform points: z against ½.
    let (zh, zs) = (z(hits, n, 0.5), z(blocked, n, 0.5));
    eprintln!("MASK: {hits}/{n} camera hits (z {zh:.2}), {blocked}/{n} shadow hits (z {zs:.2})");
    assert!(zh.abs() < Z_BOUND && zs.abs() < Z_BOUND);
}

#[test]
fn blend_stops_a_fraction_alpha_of_rays() {
    for a in [0.3f64, 0.8] {
        let scene = quad_scene(
            json!({"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, a]},
                   "alphaMode": "BLEND"}),
            None,
        );
        let mut rng = Pcg32::new(11, 0);
        let n = 40_000;
        let (mut hits, mut blocked) = (0, 0);
        for _ in 0..n {
            let o = Vec3::new(rng.uniform_f32() - 0.5, rng.uniform_f32() - 0.5, 1.0);
            let d = Vec3::new(
                rng.uniform_f32() * 0.2 - 0.1,
                rng.uniform_f32() * 0.2 - 0.1,
                -1.0,
            )
            .normalize();
            let ray = Ray::new(o, d);
            let hit = scene.intersect(&ray, f32::INFINITY).is_some();
            // The same ray decides the same way in both queries.
            assert_eq!(hit, scene.occluded(&ray, 10.0));
            hits += hit as u32;
            // A different shadow ray towards the same point decides independently.
            blocked += scene.occluded(&Ray::new(o + Vec3::new(0.0, 0.0, 0.5), d), 10.0) as u32;
        }
        let (zh, zs) = (z(hits, n, a), z(blocked, n, a));
        eprintln!(
            "BLEND a = {a}: {hits}/{n} hits (z {zh:.2}), {blocked}/{n} shadow hits (z {zs:.2})"
        );
        assert!(
            zh.abs() < Z_BOUND && zs.abs() < Z_BOUND,
            "a = {a}: z {zh}, {zs}"
        );
    }
}

#[test]
fn a_render_through_a_blend_quad_sees_transmittance_one_minus_alpha() {
    // A black quad of α = 0.3 in front of the camera, a white sky behind it: each camera
    // sample sees 1 (passes) or 0 (stops at the black surface), so the image mean is
    // 1 − α with binomial variance over width·height·spp samples.
    let a = 0.3;
    let mut g = Glb::new();
    let m = g.material(
        json!({"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, a]},
                              "alphaMode": "BLEND"}),
    );
    let q = g.quad(m);
    let mesh = g.mesh(vec![q]);
    g.node(json!({"mesh": mesh, "scale": [10.0, 10.0, 1.0]}), true);
    g.json["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 1.0, "znear": 0.1}}]);
    g.node(json!({"camera": 0, "translation": [0.0, 0.0, 2.0]}), true);
    let mut desc = parse_gltf(
        &g.bytes(),
        Path::new("b.glb"),
        None,
        &LoadOptions::default(),
    )
    .unwrap()
    .desc;
    assert!(desc.environment.is_some(), "the default white sky");
    for mat in &mut desc.materials {
        if let BsdfDesc::Alpha { inner, .. } = &mut mat.bsdf {
            **inner = BsdfDesc::Diffuse {
                albedo: TextureDesc::Constant(Vec3::ZERO),
            };
        }
    }
    (desc.render.width, desc.render.height, desc.render.spp) = (32, 32, 16);
    desc.render.max_depth = 1;
    let scene = candela_core::build::build(&desc).unwrap();
    let r = candela_core::integrator::render(&scene, 0..16, &AtomicBool::new(false), &|_| {});
    let px = r.film.resolve();
    let mean = px.iter().map(|p| p.x as f64).sum::<f64>() / px.len() as f64;
    let n = 32 * 32 * 16;
    let z = (mean - (1.0 - a)) / (a * (1.0 - a) / n as f64).sqrt();
    eprintln!(
        "BLEND render: mean {mean:.4}, expected {}, z {z:.2}",
        1.0 - a
    );
    assert!(z.abs() < Z_BOUND, "mean {mean}, z {z}");
}
