//! glTF import on files the tests make (candela_test_support::gltf writes GLB bytes): every
//! feature round-trips into the expected description, photometric units come out at
//! 683 lm/W in a render, and broken files give located errors, not panics.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use candela_core::alpha::AlphaMode;
use candela_core::desc::{
    BsdfDesc, GeometryDesc, LightAmountDesc, LightColorDesc, LightKindDesc, MaterialDesc,
    SceneDesc, SpotFalloff, TextureDesc, WrapMode,
};
use candela_scene::gltf::parse_gltf;
use candela_scene::{LoadOptions, LoadedScene};
use candela_test_support::gltf::{png, Glb};
use glam::{Mat4, Quat, Vec2, Vec3};
use serde_json::json;

/// cos 45°, for quaternions of quarter turns.
const H: f32 = std::f32::consts::FRAC_1_SQRT_2;

fn parse(glb: &Glb) -> Result<LoadedScene, String> {
    parse_gltf(
        &glb.bytes(),
        Path::new("t.glb"),
        None,
        &LoadOptions::default(),
    )
    .map_err(|e| e.to_string())
}

/// A scene with every feature the importer reads.
fn feature_file() -> Glb {
    let mut g = Glb::new();
    let t0 = g.texture(
        &png(2, 2, |x, y| {
            [200, 100, 50, if x == 0 && y == 0 { 0 } else { 255 }]
        }),
        Some(json!({"wrapS": 33071, "wrapT": 33071})),
    );
    let t1 = g.texture(
        &png(1, 1, |_, _| [0, 128, 255, 255]),
        Some(json!({"wrapS": 33648, "wrapT": 33648})),
    );
    let t2 = g.texture(&png(1, 1, |_, _| [255, 128, 255, 255]), None);
    let m0 = g.material(json!({
        "name": "painted",
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.6, 0.4, 0.5],
            "baseColorTexture": {"index": t0, "texCoord": 1, "extensions": {
                "KHR_texture_transform": {"offset": [0.5, 0.0], "rotation": 0.0, "scale": [2.0, 2.0]}}},
            "metallicFactor": 0.7, "roughnessFactor": 0.3,
            "metallicRoughnessTexture": {"index": t1, "texCoord": 1}
        },
        "normalTexture": {"index": t2, "scale": 0.5, "texCoord": 0, "extensions": {
            "KHR_texture_transform": {"offset": [0.0, 0.5], "texCoord": 1}}},
        "occlusionTexture": {"index": t1},
        "emissiveFactor": [1.0, 0.5, 0.25],
        "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": true,
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}
    }));
    let m1 = g.material(json!({
        "name": "glass",
        "pbrMetallicRoughness": {"roughnessFactor": 0.2, "baseColorFactor": [0.9, 0.8, 0.7, 0.5]},
        "alphaMode": "BLEND",
        "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                       "KHR_materials_ior": {"ior": 1.33}}
    }));
    // Mesh 0: an indexed quad with normals and two uv sets.
    let mut quad = g.quad(m0);
    let uv1 = g.floats(&[0., 0., 0.5, 0., 0.5, 0.5, 0., 0.5], 2, "VEC2");
    quad["attributes"]["TEXCOORD_1"] = json!(uv1);
    let mesh0 = g.mesh(vec![quad]);
    // Mesh 1: a strip without indices or normals and an indexed fan.
    let strip_pos = g.floats(
        &[0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0., 0., 2., 0.],
        3,
        "VEC3",
    );
    let fan_pos = g.floats(
        &[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0., -1., 1., 0.],
        3,
        "VEC3",
    );
    let fan_idx = g.indices(&[0, 1, 2, 3, 4]);
    let mesh1 = g.mesh(vec![
        json!({"attributes": {"POSITION": strip_pos}, "mode": 5, "material": m1}),
        json!({"attributes": {"POSITION": fan_pos}, "indices": fan_idx, "mode": 6}),
    ]);
    // Nodes: a TRS parent with a matrix child holding mesh 0; mesh 0 again at the root;
    // mesh 1; three lights; a camera.
    let child = g.node(
        json!({"mesh": mesh0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}),
        false,
    );
    g.node(
        json!({"children": [child], "translation": [1.0, 2.0, 3.0],
               "rotation": [0.0, H, 0.0, H], "scale": [2.0, 2.0, 2.0]}),
        true,
    );
    g.node(json!({"mesh": mesh0}), true);
    g.node(json!({"mesh": mesh1}), true);
    g.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"type": "point", "intensity": 20.0, "color": [1.0, 0.5, 0.25], "range": 10.0},
        {"type": "spot", "intensity": 5.0, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}},
        {"type": "directional", "intensity": 3.0}
    ]}});
    g.node(json!({"translation": [0.0, 4.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}), true);
    // Rotated −90° about x: −z turns to −y (pointing down).
    let down = [-H, 0.0, 0.0, H];
    g.node(json!({"translation": [0.0, 3.0, 0.0], "rotation": down, "extensions": {"KHR_lights_punctual": {"light": 1}}}), true);
    g.node(
        json!({"rotation": down, "extensions": {"KHR_lights_punctual": {"light": 2}}}),
        true,
    );
    g.json["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 2.0, "znear": 0.1}}]);
    g.node(json!({"camera": 0, "translation": [0.0, 1.0, 10.0]}), true);
    g.json["extensionsUsed"] = json!([
        "KHR_lights_punctual",
        "KHR_materials_emissive_strength",
        "KHR_materials_ior",
        "KHR_materials_transmission",
        "KHR_texture_transform",
        "EXT_fancy"
    ]);
    g
}

fn material<'a>(desc: &'a SceneDesc, name: &str) -> &'a MaterialDesc {
    desc.materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("{name}"))
}

#[test]
fn every_feature_round_trips_into_the_expected_description() {
    let loaded = parse(&feature_file()).unwrap();
    let d = &loaded.desc;
    // Shapes: quad under the parent, quad at the root, strip, fan.
    assert_eq!(d.shapes.len(), 4);
    let parent = Mat4::from_scale_rotation_translation(
        Vec3::splat(2.0),
        Quat::from_xyzw(0.0, H, 0.0, H),
        Vec3::new(1.0, 2.0, 3.0),
    );
    let child = Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0));
    assert!(d.shapes[0].transform.abs_diff_eq(parent * child, 1e-5));
    assert_eq!(d.shapes[1].transform, Mat4::IDENTITY);
    let mesh = |i: usize| match &d.shapes[i].geometry {
        GeometryDesc::Mesh(m) => m.clone(),
        g => panic!("{g:?}"),
    };
    // One Arc per primitive, shared by the nodes that place it.
    assert!(Arc::ptr_eq(&mesh(0), &mesh(1)));
    let q = mesh(0);
    assert_eq!(q.indices, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(q.normals, vec![Vec3::Z; 4]);
    // TEXCOORD_1 (the set the material names), v flipped.
    assert_eq!(
        q.uvs,
        vec![
            Vec2::new(0., 1.),
            Vec2::new(0.5, 1.),
            Vec2::new(0.5, 0.5),
            Vec2::new(0., 0.5)
        ]
    );
    let strip = mesh(2);
    assert_eq!(strip.indices, vec![[0, 1, 2], [2, 1, 3], [2, 3, 4]]);
    assert!(strip.normals.is_empty(), "missing normals stay flat");
    assert_eq!(mesh(3).indices, vec![[1, 2, 0], [2, 3, 0], [3, 4, 0]]);

    // Material 0: MASK, double-sided, normal map over metal-rough.
    let m0 = material(d, &d.shapes[0].material);
    assert_eq!(m0.name, "gltf0:painted");
    let BsdfDesc::TwoSided(inner) = &m0.bsdf else {
        panic!("{:?}", m0.bsdf)
    };
    let BsdfDesc::Alpha { alpha, inner } = &**inner else {
        panic!()
    };
    assert_eq!(alpha.mode, AlphaMode::Mask { cutoff: 0.3 });
    assert_eq!(alpha.factor, 0.5);
    let Some(TextureDesc::Image(at)) = &alpha.texture else {
        panic!()
    };
    assert_eq!(at.image.pixels[0], Vec3::ZERO, "alpha of texel (0, 0)");
    assert_eq!(at.image.pixels[1], Vec3::ONE);
    let BsdfDesc::NormalMap { map, inner } = &**inner else {
        panic!()
    };
    let TextureDesc::Image(nm) = map else {
        panic!()
    };
    // Scale ½ halves x and y about the flat value: 255 → 0.75, 128/255 → ≈0.5.
    let n = nm.image.pixels[0];
    assert!(
        (n.x - 0.75).abs() < 1e-6
            && (n.y - (0.25 + 0.5 * 128.0 / 255.0)).abs() < 1e-6
            && n.z == 1.0,
        "{n}"
    );
    let BsdfDesc::MetalRough {
        base_color,
        metallic,
        roughness,
    } = &**inner
    else {
        panic!()
    };
    let TextureDesc::Image(bc) = base_color else {
        panic!()
    };
    assert_eq!(bc.scale, Vec3::new(0.8, 0.6, 0.4));
    assert_eq!(bc.wrap, WrapMode::Clamp);
    // sRGB-decoded: 200/255 → 0.578.
    assert!(
        (bc.image.pixels[0].x - 0.5776).abs() < 1e-3,
        "{}",
        bc.image.pixels[0]
    );
    // KHR_texture_transform in Candela's uvs: glTF (u, v) → (2u + 0.5, 2v).
    let p = bc
        .uv_transform
        .transform_point2(Vec2::new(0.25, 1.0 - 0.125));
    assert!((p - Vec2::new(1.0, 1.0 - 0.25)).length() < 1e-6, "{p}");
    let (TextureDesc::Image(mt), TextureDesc::Image(rt)) = (metallic, roughness) else {
        panic!()
    };
    assert_eq!(
        (mt.channel, mt.scale, mt.wrap),
        (Some(2), Vec3::splat(0.7), WrapMode::Mirror)
    );
    assert_eq!((rt.channel, rt.scale), (Some(1), Vec3::splat(0.3)));
    assert!(
        (mt.image.pixels[0].z - 1.0).abs() < 1e-6,
        "metallic-roughness is linear"
    );
    assert!(
        (rt.image.pixels[0].y - 128.0 / 255.0).abs() < 1e-6,
        "metallic-roughness is linear"
    );
    assert_eq!(d.shapes[0].emission, Some(Vec3::new(4.0, 2.0, 1.0)));

    // Material 1: BLEND over a rough dielectric of index 1.33, α = 0.2².
    let m1 = material(d, &d.shapes[2].material);
    let BsdfDesc::Alpha { alpha, inner } = &m1.bsdf else {
        panic!("{:?}", m1.bsdf)
    };
    assert_eq!(alpha.mode, AlphaMode::Blend);
    assert!(alpha.texture.is_none());
    let BsdfDesc::Dielectric {
        eta,
        alpha_u,
        alpha_v,
        thin,
        tint: TextureDesc::Constant(tint),
        ..
    } = **inner
    else {
        panic!()
    };
    assert_eq!((eta, thin), (1.33, false));
    // Transmission is tinted by the base colour.
    assert_eq!(tint, Vec3::new(0.9, 0.8, 0.7));
    assert!((alpha_u - 0.04).abs() < 1e-6 && alpha_u == alpha_v);
    // The fan has no material: glTF's default (white, metallic 1, roughness 1).
    let m2 = material(d, &d.shapes[3].material);
    let BsdfDesc::MetalRough {
        base_color: TextureDesc::Constant(c),
        metallic: TextureDesc::Constant(m),
        ..
    } = &m2.bsdf
    else {
        panic!()
    };
    assert_eq!((*c, *m), (Vec3::ONE, Vec3::ONE));

    // Lights: candela for point and spot, lux for directional, at the nodes.
    assert_eq!(d.lights.len(), 3);
    let LightKindDesc::ShapedPoint(p) = &d.lights[0].kind else {
        panic!()
    };
    assert_eq!(p.position, Vec3::new(0.0, 4.0, 0.0));
    assert_eq!(p.amount, LightAmountDesc::Candela(20.0));
    assert_eq!(p.color, LightColorDesc::Rgb(Vec3::new(1.0, 0.5, 0.25)));
    let LightKindDesc::Spot(s) = &d.lights[1].kind else {
        panic!()
    };
    assert!(
        (s.direction - Vec3::NEG_Y).length() < 1e-5,
        "{}",
        s.direction
    );
    assert!((s.inner_angle_deg - 0.2f32.to_degrees()).abs() < 1e-4);
    assert!((s.outer_angle_deg - 0.4f32.to_degrees()).abs() < 1e-4);
    assert_eq!(
        (s.falloff, s.amount),
        (SpotFalloff::Gltf, LightAmountDesc::Candela(5.0))
    );
    let LightKindDesc::Directional(dl) = &d.lights[2].kind else {
        panic!()
    };
    assert!((dl.direction - Vec3::NEG_Y).length() < 1e-5);
    assert_eq!(dl.amount, LightAmountDesc::Candela(3.0));

    // Camera: node origin, −z, yfov; the aspect ratio sets the height.
    let c = &d.camera;
    assert_eq!(c.position, Vec3::new(0.0, 1.0, 10.0));
    assert!((c.look_at - Vec3::new(0.0, 1.0, 9.0)).length() < 1e-6);
    assert!((c.fov_y_deg - 0.8f32.to_degrees()).abs() < 1e-4);
    assert_eq!(d.render.width, 2 * d.render.height);
    assert!(d.environment.is_none(), "lit by its own lights");

    // One warning per unsupported optional extension and per ignored feature.
    let w = &loaded.warnings;
    assert_eq!(
        w.iter().filter(|w| w.contains("EXT_fancy")).count(),
        1,
        "{w:#?}"
    );
    for what in ["range is ignored", "occlusion"] {
        assert!(
            w.iter().any(|x| x.contains(what)),
            "no warning on {what}: {w:#?}"
        );
    }
    assert!(w.iter().all(|x| x.starts_with("t.glb: ")), "{w:#?}");
    candela_core::build::build(d).unwrap();
}

/// Renders the centre of a white Lambertian plane z = 0 lit by the file's one light at
/// (0, 0, 1) (or from above), seen from (0, 0, 3) through a 0.3° field of view. Radiance
/// is ρ/π·E, so π·L is the irradiance E. Returns E.
fn irradiance_under(light: serde_json::Value, rotation: [f32; 4]) -> f32 {
    let mut g = Glb::new();
    let m = g.material(json!({}));
    let q = g.quad(m);
    let mesh = g.mesh(vec![q]);
    g.node(json!({"mesh": mesh, "scale": [10.0, 10.0, 1.0]}), true);
    g.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [light]}});
    g.node(
        json!({"translation": [0.0, 0.0, 1.0], "rotation": rotation,
                  "extensions": {"KHR_lights_punctual": {"light": 0}}}),
        true,
    );
    g.json["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.005, "aspectRatio": 1.0, "znear": 0.1}}]);
    g.node(json!({"camera": 0, "translation": [0.0, 0.0, 3.0]}), true);
    let mut desc = parse(&g).unwrap().desc;
    for mat in &mut desc.materials {
        mat.bsdf = BsdfDesc::Diffuse {
            albedo: TextureDesc::Constant(Vec3::ONE),
        };
    }
    desc.render.width = 8;
    desc.render.height = 8;
    desc.render.spp = 4;
    desc.render.max_depth = 1;
    let scene = candela_core::build::build(&desc).unwrap();
    let r = candela_core::integrator::render(&scene, 0..4, &AtomicBool::new(false), &|_| {});
    let px = r.film.resolve();
    let mean = px.iter().copied().sum::<Vec3>() / px.len() as f32;
    // White light stays white.
    assert!(
        (mean.x - mean.z).abs() < 1e-6 * mean.x.abs().max(1e-12),
        "{mean}"
    );
    std::f32::consts::PI * mean.x
}

#[test]
fn one_candela_at_one_metre_gives_an_irradiance_of_one_683th_watt_per_square_metre() {
    // The view spans ±0.0075 units of the plane, where cos³θ departs from 1 by < 10⁻⁴:
    // the tolerance 10⁻³ is rounding plus that, and a 683 missing, squared or doubled
    // fails it by orders of magnitude. (Point and spot lights are delta lights and the
    // plane is Lambertian, so the estimate has no noise.)
    let expected = 1.0 / 683.0;
    let identity = [0.0, 0.0, 0.0, 1.0];
    let point = irradiance_under(json!({"type": "point", "intensity": 1.0}), identity);
    let spot = irradiance_under(
        json!({"type": "spot", "intensity": 1.0, "spot": {"outerConeAngle": 0.5}}),
        identity,
    );
    let sun = irradiance_under(json!({"type": "directional", "intensity": 1.0}), identity);
    let twice = irradiance_under(json!({"type": "point", "intensity": 2.0}), identity);
    eprintln!("E: point {point:e}, spot {spot:e}, directional {sun:e}, 1/683 = {expected:e}");
    for (what, e, want) in [
        ("point 1 cd", point, expected),
        ("spot 1 cd on its axis", spot, expected),
        ("directional 1 lux", sun, expected),
        ("point 2 cd", twice, 2.0 * expected),
    ] {
        assert!(
            (e / want - 1.0).abs() < 1e-3,
            "{what}: E = {e}, expected {want}"
        );
    }
}

#[test]
fn unsupported_required_extensions_are_errors_naming_them() {
    let mut g = feature_file();
    g.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let e = parse(&g).unwrap_err();
    assert!(
        e.starts_with("t.glb: requires extension KHR_draco_mesh_compression"),
        "{e}"
    );
    // A supported one may be required.
    g.json["extensionsRequired"] = json!(["KHR_materials_transmission"]);
    parse(&g).unwrap();
}

/// A change that breaks a file.
type Edit = Box<dyn Fn(&mut Glb)>;

#[test]
fn broken_files_are_located_errors_not_panics() {
    let base = feature_file();
    let cases: Vec<(&str, Edit)> = vec![
        (
            "reads past the end",
            Box::new(|g| g.json["accessors"][0]["count"] = json!(1000)),
        ),
        (
            "index 9 is out of range",
            Box::new(|g| {
                let i = g.indices(&[0, 1, 9]);
                let p = g.quad(0);
                let mut p = p;
                p["indices"] = json!(i);
                g.mesh(vec![p]);
                let n = g.json["meshes"].as_array().unwrap().len() - 1;
                g.node(json!({"mesh": n}), true);
            }),
        ),
        (
            "accessors",
            Box::new(|g| {
                g.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(999)
            }),
        ),
        (
            "external file",
            Box::new(|g| {
                g.json["buffers"] = json!([]);
                g.bin.clear();
            }),
        ),
        (
            "no scene",
            Box::new(|g| {
                g.json["scenes"] = json!([]);
                g.json.as_object_mut().unwrap().remove("scene");
            }),
        ),
        (
            "cycle",
            Box::new(|g| g.json["nodes"][0]["children"] = json!([1])),
        ),
    ];
    for (want, edit) in cases {
        let mut g = Glb {
            json: base.json.clone(),
            bin: base.bin.clone(),
        };
        edit(&mut g);
        let bytes = if want == "external file" {
            // A buffer given by a URI that bytes in memory cannot resolve.
            let mut j = g.json.clone();
            j["buffers"] = json!([{"byteLength": 4, "uri": "missing.bin"}]);
            serde_json::to_vec(&j).unwrap()
        } else {
            g.bytes()
        };
        let e = parse_gltf(&bytes, Path::new("t.glb"), None, &LoadOptions::default())
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.glb"), "{want}: {e}");
        assert!(e.contains(want), "expected \"{want}\" in: {e}");
    }
    // A missing external buffer beside a real file names it.
    let dir = tempfile::tempdir().unwrap();
    let mut j = base.json.clone();
    j["buffers"] = json!([{"byteLength": 4, "uri": "missing.bin"}]);
    let path = dir.path().join("m.gltf");
    std::fs::write(&path, serde_json::to_vec(&j).unwrap()).unwrap();
    let e = candela_scene::load_scene(&path).unwrap_err().to_string();
    assert!(
        e.contains("m.gltf") && e.contains("cannot read glTF"),
        "{e}"
    );
    // JSON syntax errors keep line and column.
    let e = parse_gltf(
        b"{\n  \"asset\": {\"version\": \"2.0\"},\n  oops\n}",
        Path::new("s.gltf"),
        None,
        &LoadOptions::default(),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("s.gltf:3:3: invalid glTF JSON"), "{e}");
    // Truncated GLBs and garbage do not panic.
    let bytes = base.bytes();
    for n in [0, 4, 12, 20, 100, bytes.len() / 2, bytes.len() - 1] {
        assert!(
            parse_gltf(
                &bytes[..n],
                Path::new("t.glb"),
                None,
                &LoadOptions::default()
            )
            .is_err(),
            "{n}"
        );
    }
}

#[test]
fn scene_option_picks_a_scene_and_a_missing_one_is_an_error() {
    let mut g = feature_file();
    g.json["scenes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"nodes": [3]}));
    let opts = LoadOptions {
        scene: Some(1),
        ..LoadOptions::default()
    };
    let d = parse_gltf(&g.bytes(), Path::new("t.glb"), None, &opts)
        .unwrap()
        .desc;
    assert_eq!(
        d.shapes.len(),
        2,
        "scene 1 holds only the strip and the fan"
    );
    // Nothing emits there: a white environment, and an automatic camera framing the
    // bounds ([-1, 1] × [0, 2] × 0) from the front right, above.
    let env = d.environment.expect("default light");
    assert_eq!(env.strength, 1.0);
    let to_center = (Vec3::Y - d.camera.position).normalize();
    assert!(to_center.dot((d.camera.look_at - d.camera.position).normalize()) > 0.9999);
    assert!(d.camera.position.y > 0.0 && d.camera.position.z > 0.0 && d.camera.position.x > 0.0);
    let opts = LoadOptions {
        scene: Some(5),
        ..LoadOptions::default()
    };
    let e = parse_gltf(&g.bytes(), Path::new("t.glb"), None, &opts)
        .map(|_| ())
        .unwrap_err();
    assert!(
        e.to_string().contains("scene 5 does not exist (2 scenes)"),
        "{e}"
    );
}

/// A unit quad whose vertices carry COLOR_0 `colors` (accessor index), material 0 default.
fn colored_quad(g: &mut Glb, colors: usize) {
    let m = g.material(json!({}));
    let mut q = g.quad(m);
    q["attributes"]["COLOR_0"] = json!(colors);
    let mesh = g.mesh(vec![q]);
    g.node(json!({"mesh": mesh}), true);
}

#[test]
fn vertex_colors_round_trip_from_normalized_bytes_and_floats() {
    // Normalized u8 RGBA (alpha 255): c/255, linear, no sRGB decoding.
    let mut g = Glb::new();
    let bytes = [
        255u8, 0, 0, 255, 0, 255, 0, 255, 0, 0, 51, 255, 255, 255, 255, 255,
    ];
    let view = g.view(&bytes);
    g.json["accessors"].as_array_mut().unwrap().push(json!({
        "bufferView": view, "componentType": 5121, "normalized": true, "count": 4,
        "type": "VEC4"}));
    let acc = g.json["accessors"].as_array().unwrap().len() - 1;
    colored_quad(&mut g, acc);
    let loaded = parse(&g).unwrap();
    assert!(
        loaded.warnings.iter().all(|w| !w.contains("COLOR")),
        "{:?}",
        loaded.warnings
    );
    let GeometryDesc::Mesh(m) = &loaded.desc.shapes[0].geometry else {
        panic!("not a mesh")
    };
    let want = [Vec3::X, Vec3::Y, Vec3::new(0.0, 0.0, 0.2), Vec3::ONE];
    for (c, w) in m.colors.iter().zip(want) {
        assert!((*c - w).abs().max_element() < 1e-6, "{c} vs {w}");
    }
    assert_eq!(m.colors.len(), 4);

    // Float RGBA with a translucent alpha: RGB read, the ignored alpha warned.
    let mut g = Glb::new();
    let acc = g.floats(&[0.5, 0.25, 1.0, 0.5].repeat(4), 4, "VEC4");
    colored_quad(&mut g, acc);
    let loaded = parse(&g).unwrap();
    let GeometryDesc::Mesh(m) = &loaded.desc.shapes[0].geometry else {
        panic!("not a mesh")
    };
    assert_eq!(m.colors, vec![Vec3::new(0.5, 0.25, 1.0); 4]);
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("alpha of COLOR_0")),
        "{:?}",
        loaded.warnings
    );

    // A colour count that does not match the positions is a located error.
    let mut g = Glb::new();
    let acc = g.floats(&[1.0; 9], 3, "VEC3");
    colored_quad(&mut g, acc);
    let e = parse(&g).unwrap_err();
    assert!(e.contains("COLOR_0 has 3 elements for 4 positions"), "{e}");
}

#[test]
fn vertex_colors_multiply_the_albedo_of_a_lit_diffuse_quad() {
    // Red at x = −1, green at x = +1: the colour (1 − x, 1 + x, 0)/2 is linear in x, so
    // barycentric interpolation gives it exactly on both triangles. A 683 lux sun from
    // straight above gives E = 1 W/m²; a white Lambertian albedo then gives radiance
    // colour·1/π. Every sample sees R + G = 1/π and B = 0 (tolerance: f32 rounding), and
    // the column means of (G − R)/(G + R) follow the x of the column centre: the samples
    // spread over the filter's footprint, symmetric about the centre, so the mean of a
    // linear colour is its centre value up to sampling imbalance (measured 6·10⁻⁴; the
    // bound 0.02 is a tenth of a pixel on the plane). Without colours R = G everywhere;
    // swapped colours flip the sign: both fail by ~0.7 at the edge columns.
    let mut g = Glb::new();
    let acc = g.floats(&[1., 0., 0., 0., 1., 0., 0., 1., 0., 1., 0., 0.], 3, "VEC3");
    colored_quad(&mut g, acc);
    g.json["extensions"] =
        json!({"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 683.0}]}});
    g.node(
        json!({"extensions": {"KHR_lights_punctual": {"light": 0}}}),
        true,
    );
    // Half-height tan(0.25)·3 = 0.77 on the plane: the view stays inside the quad.
    g.json["cameras"] = json!([{"type": "perspective",
        "perspective": {"yfov": 0.5, "aspectRatio": 1.0, "znear": 0.1}}]);
    g.node(json!({"camera": 0, "translation": [0.0, 0.0, 3.0]}), true);
    let mut desc = parse(&g).unwrap().desc;
    for mat in &mut desc.materials {
        mat.bsdf = BsdfDesc::Diffuse {
            albedo: TextureDesc::Constant(Vec3::ONE),
        };
    }
    let (w, h) = (8usize, 8usize);
    desc.render.width = w as u32;
    desc.render.height = h as u32;
    desc.render.spp = 16;
    desc.render.max_depth = 1;
    let scene = candela_core::build::build(&desc).unwrap();
    let r = candela_core::integrator::render(&scene, 0..16, &AtomicBool::new(false), &|_| {});
    let px = r.film.resolve();
    let inv_pi = std::f32::consts::FRAC_1_PI;
    for p in &px {
        assert!(
            ((p.x + p.y) / inv_pi - 1.0).abs() < 1e-3 && p.z.abs() < 1e-6,
            "pixel {p}, expected R + G = 1/π, B = 0"
        );
    }
    let half = 0.25f32.tan() * 3.0; // tan(yfov/2)·distance
    let mut worst = 0.0f32;
    for col in 0..w {
        let x = (2.0 * (col as f32 + 0.5) / w as f32 - 1.0) * half;
        let (mut r_, mut g_) = (0.0, 0.0);
        for row in 0..h {
            r_ += px[row * w + col].x;
            g_ += px[row * w + col].y;
        }
        let measured = (g_ - r_) / (g_ + r_);
        worst = worst.max((measured - x).abs());
        assert!(
            (measured - x).abs() < 0.02,
            "column {col}: (G − R)/(G + R) = {measured}, expected x = {x}"
        );
    }
    eprintln!("vertex colours: worst column deviation {worst} (plane units)");
}

/// The normal-mapped shading normals at world (−0.5, 0.2) and (0.5, 0.2) of a quad in z = 0
/// made of two halves: x ∈ [0, 1] with u = x, and x ∈ [−1, 0] with u = −x (mirrored uvs),
/// v up along +y on both, under a normal map of one texel `c`. `tangents` adds TANGENT
/// ((1,0,0,1) on the right, (−1,0,0,−1) on the mirrored left); `mirror` places the mesh
/// with scale (−1, 1, 1).
fn mapped_normals(c: u8, tangents: bool, mirror: bool) -> [Vec3; 2] {
    let mut g = Glb::new();
    let tex = g.texture(&png(1, 1, |_, _| [c, c, c, 255]), None);
    let m = g.material(json!({"normalTexture": {"index": tex}}));
    #[rustfmt::skip]
    let pos = g.floats(&[
        0., -1., 0., 1., -1., 0., 1., 1., 0., 0., 1., 0.,
        0., -1., 0., -1., -1., 0., -1., 1., 0., 0., 1., 0.,
    ], 3, "VEC3");
    let nrm = g.floats(&[0., 0., 1.].repeat(8), 3, "VEC3");
    // glTF v runs down: v = 0 at y = +1.
    #[rustfmt::skip]
    let uv = g.floats(&[0., 1., 1., 1., 1., 0., 0., 0., 0., 1., 1., 1., 1., 0., 0., 0.], 2, "VEC2");
    let idx = g.indices(&[0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6]);
    let mut attributes = json!({"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv});
    if tangents {
        let mut t = [1., 0., 0., 1.].repeat(4);
        t.extend([-1., 0., 0., -1.].repeat(4));
        attributes["TANGENT"] = json!(g.floats(&t, 4, "VEC4"));
    }
    let mesh = g.mesh(vec![
        json!({"attributes": attributes, "indices": idx, "material": m}),
    ]);
    let scale = if mirror { -1.0 } else { 1.0 };
    g.node(json!({"mesh": mesh, "scale": [scale, 1.0, 1.0]}), true);
    let loaded = parse(&g).unwrap();
    assert!(
        loaded.warnings.iter().all(|w| !w.contains("TANGENT")),
        "{:?}",
        loaded.warnings
    );
    let scene = candela_core::build::build(&loaded.desc).unwrap();
    [-0.5f32, 0.5].map(|x| {
        let ray = candela_core::geometry::Ray::new(Vec3::new(x, 0.2, 3.0), -Vec3::Z);
        let si = scene.intersect(&ray, f32::INFINITY).expect("hits the quad");
        scene.materials[si.material.0 as usize].bsdf_at(&si).frame.n
    })
}

#[test]
fn normal_maps_shade_mirrored_uv_halves_with_the_right_bitangent() {
    // The texel c = 217 decodes to m = 2c/255 − 1 = 0.702 on all three axes: tilted
    // towards +u and +v. +v is +y on both halves; +u is +x on the right and −x on the
    // mirrored left. So the right half must shade with normalize(m, m, m) and the left
    // with normalize(−m, m, m) — whether the frame comes from TANGENT or from the uvs,
    // and under a mirroring node transform (which maps each half onto the other's place).
    // A bitangent n × t without the sign gives (−m, −m, m) on the mirrored half. The
    // tolerance 10⁻⁴ is f32 rounding of the frame and the 8-bit texel is exact.
    let m = 2.0 * 217.0 / 255.0 - 1.0;
    let want = [
        Vec3::new(-m, m, m).normalize(),
        Vec3::new(m, m, m).normalize(),
    ];
    for tangents in [false, true] {
        for mirror in [false, true] {
            let got = mapped_normals(217, tangents, mirror);
            eprintln!(
                "tangents {tangents}, mirror {mirror}: left {}, right {}",
                got[0], got[1]
            );
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (*g - w).length() < 1e-4,
                    "tangents {tangents}, mirror {mirror}: normal {g}, expected {w}"
                );
            }
        }
    }
}

/// The mean radiance seen from (0, 0, 3) looking down −z at an emissive quad in z = 0
/// wound clockwise as seen from there (its front faces −z in object space), with
/// `normals` −z or none, placed by `node` (a node's JSON without its mesh).
fn seen_emission(node: serde_json::Value, normals: bool) -> f32 {
    let mut g = Glb::new();
    let m = g.material(json!({"emissiveFactor": [1.0, 1.0, 1.0],
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0]}}));
    let mut q = g.quad(m);
    let pos = g.floats(
        &[-1., -1., 0., -1., 1., 0., 1., 1., 0., 1., -1., 0.],
        3,
        "VEC3",
    );
    q["attributes"]["POSITION"] = json!(pos);
    let attributes = q["attributes"].as_object_mut().unwrap();
    attributes.remove("TEXCOORD_0");
    if normals {
        let n = g.floats(
            &[0., 0., -1., 0., 0., -1., 0., 0., -1., 0., 0., -1.],
            3,
            "VEC3",
        );
        q["attributes"]["NORMAL"] = json!(n);
    } else {
        attributes.remove("NORMAL");
    }
    let mesh = g.mesh(vec![q]);
    let mut node = node;
    node["mesh"] = json!(mesh);
    g.node(node, true);
    g.json["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.1, "aspectRatio": 1.0, "znear": 0.1}}]);
    g.node(json!({"camera": 0, "translation": [0.0, 0.0, 3.0]}), true);
    let mut desc = parse(&g).unwrap().desc;
    desc.render.width = 4;
    desc.render.height = 4;
    desc.render.spp = 1;
    desc.render.max_depth = 0;
    let scene = candela_core::build::build(&desc).unwrap();
    let r = candela_core::integrator::render(&scene, 0..1, &AtomicBool::new(false), &|_| {});
    let px = r.film.resolve();
    px.iter().map(|p| p.x).sum::<f32>() / px.len() as f32
}

#[test]
fn mirroring_transforms_reverse_the_winding_of_the_front_face() {
    // glTF 2.0 §3.7.2.1: under a transform of negative determinant the front faces are
    // the clockwise ones. The quad's object-space front is −z (away from the camera):
    // mirrored in z it faces the camera, mirrored in x it still faces away. Shading
    // normals must agree with the winding rule. The emitter shows radiance 1 or 0, so
    // any threshold between separates them; ½ is the middle.
    let flip_z = [
        1., 0., 0., 0., 0., 1., 0., 0., 0., 0., -1., 0., 0., 0., 0., 1.,
    ];
    let flip_x = [
        -1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.,
    ];
    for normals in [false, true] {
        for (what, node, faces_camera) in [
            ("unmirrored", json!({}), false),
            ("scale z −1", json!({"scale": [1.0, 1.0, -1.0]}), true),
            ("matrix z −1", json!({ "matrix": flip_z }), true),
            ("matrix x −1", json!({ "matrix": flip_x }), false),
            (
                "scale x −1, y −1",
                json!({"scale": [-1.0, -1.0, 1.0]}),
                false,
            ),
        ] {
            let l = seen_emission(node, normals);
            assert_eq!(
                l > 0.5,
                faces_camera,
                "{what}, normals {normals}: radiance {l}"
            );
        }
    }
}

#[test]
fn orthographic_cameras_view_twice_ymag_at_the_aspect_of_xmag_over_ymag() {
    let mut g = Glb::one_quad();
    g.json["cameras"] = json!([{"type": "orthographic",
        "orthographic": {"xmag": 3.0, "ymag": 1.5, "znear": 0.1, "zfar": 100.0}}]);
    g.node(json!({"camera": 0, "translation": [0.0, 0.0, 4.0]}), true);
    let loaded = parse(&g).unwrap();
    let w = &loaded.warnings;
    assert!(!w.iter().any(|w| w.contains("camera")), "{w:?}");
    let (c, r) = (&loaded.desc.camera, &loaded.desc.render);
    assert_eq!(c.ortho_height, Some(3.0));
    assert_eq!(c.position, Vec3::new(0.0, 0.0, 4.0));
    assert!((c.look_at - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-6);
    assert_eq!(r.width, 2 * r.height);
    // The quad (2 × 2 at the origin) fills the middle 2/3 of the height and 1/3 of the
    // width: its corner ray starts at the quad's corner.
    let cam = candela_core::camera::Camera::new(c, r.width, r.height);
    let (w, h) = (r.width as f32, r.height as f32);
    let ray = cam.generate_ray(glam::Vec2::new(w / 3.0, h / 6.0));
    assert!(
        (ray.o - Vec3::new(-1.0, 1.0, 4.0)).length() < 1e-4,
        "{}",
        ray.o
    );
    assert!((ray.d - Vec3::NEG_Z).length() < 1e-6);
}

#[test]
fn accessors_of_a_wrong_format_count_or_stride_are_errors_not_panics() {
    // Each edit makes an accessor that the `gltf` crate's readers would panic on
    // (unreachable!, an assertion, an underflow) or silently misread.
    let base = Glb::one_quad();
    let cases: Vec<(&str, Edit)> = vec![
        (
            "indices: accessors[3] holds Scalar of F32",
            Box::new(|g| g.json["accessors"][3]["componentType"] = json!(5126)),
        ),
        (
            "indices: accessors[3] holds Vec2 of U32",
            Box::new(|g| {
                g.json["accessors"][3]["type"] = json!("VEC2");
                g.json["accessors"][3]["count"] = json!(3);
            }),
        ),
        (
            "POSITION: accessors[0] holds Vec3 of U16",
            Box::new(|g| g.json["accessors"][0]["componentType"] = json!(5123)),
        ),
        (
            "NORMAL: accessors[1] holds Vec2 of F32",
            Box::new(|g| g.json["accessors"][1]["type"] = json!("VEC2")),
        ),
        (
            "TEXCOORD_0: accessors[2] holds Vec2 of I8",
            Box::new(|g| g.json["accessors"][2]["componentType"] = json!(5120)),
        ),
        (
            "POSITION: accessors[0]: buffer view 0 has byteStride 4 < the element's 12 bytes",
            Box::new(|g| g.json["bufferViews"][0]["byteStride"] = json!(4)),
        ),
        (
            "POSITION: accessors[0] has count 0",
            Box::new(|g| g.json["accessors"][0]["count"] = json!(0)),
        ),
        (
            "indices: accessors[3] has count 0",
            Box::new(|g| g.json["accessors"][3]["count"] = json!(0)),
        ),
        (
            "POSITION: accessors[0]: sparse count is 0",
            Box::new(|g| {
                g.json["accessors"][0]["sparse"] = json!({"count": 0,
                    "indices": {"bufferView": 3, "componentType": 5125},
                    "values": {"bufferView": 0}})
            }),
        ),
    ];
    for (want, edit) in cases {
        let mut g = Glb {
            json: base.json.clone(),
            bin: base.bin.clone(),
        };
        edit(&mut g);
        let e = parse(&g).map(|_| ()).unwrap_err();
        assert!(
            e.starts_with("t.glb: meshes[0].primitives[0]: ") && e.contains(want),
            "expected \"{want}\" in: {e}"
        );
    }
}

#[test]
fn sparse_accessors_override_a_base_view_or_zeros() {
    // Sparse POSITION data: over the quad's own view, and without a view (zeros, glTF
    // 2.0 §3.6.2.3), replacing vertices 1 and 2 with (5, 0, 0) and (5, 5, 0).
    for base_view in [true, false] {
        let mut g = Glb::new();
        let q = g.quad(0);
        g.material(json!({}));
        let idx = g.view(
            &[1u16, 2]
                .iter()
                .flat_map(|i| i.to_le_bytes())
                .collect::<Vec<_>>(),
        );
        let values: Vec<u8> = [5f32, 0., 0., 5., 5., 0.]
            .iter()
            .flat_map(|f| f.to_le_bytes())
            .collect();
        let vals = g.view(&values);
        let a = &mut g.json["accessors"][0];
        a["sparse"] = json!({"count": 2,
            "indices": {"bufferView": idx, "componentType": 5123},
            "values": {"bufferView": vals}});
        if !base_view {
            a.as_object_mut().unwrap().remove("bufferView");
        }
        let mesh = g.mesh(vec![q]);
        g.node(json!({ "mesh": mesh }), true);
        let desc = parse(&g).unwrap().desc;
        let GeometryDesc::Mesh(m) = &desc.shapes[0].geometry else {
            panic!("not a mesh")
        };
        let corner = if base_view {
            [Vec3::new(-1., -1., 0.), Vec3::new(-1., 1., 0.)]
        } else {
            [Vec3::ZERO; 2]
        };
        assert_eq!(
            m.positions,
            vec![
                corner[0],
                Vec3::new(5., 0., 0.),
                Vec3::new(5., 5., 0.),
                corner[1]
            ],
            "base view {base_view}"
        );
    }
}

#[test]
fn scenes_without_nodes_load() {
    // glTF 2.0 §5.17 leaves a scene's `nodes` optional; `gltf-json` 1.4 requires it.
    let mut g = Glb::one_quad();
    g.json["scenes"] = json!([{"name": "empty"}, {"nodes": [0]}]);
    g.json["scene"] = json!(1);
    let desc = parse(&g).unwrap().desc;
    assert_eq!(desc.shapes.len(), 1);
    g.json["scene"] = json!(0);
    assert!(parse(&g).unwrap().desc.shapes.is_empty());
    // Other missing data is still an error (here a scene's node list of the wrong type).
    g.json["scenes"] = json!([{"nodes": 0}]);
    let e = parse(&g).unwrap_err();
    assert!(e.contains("invalid glTF JSON"), "{e}");
}

#[test]
fn an_emissive_texture_makes_a_textured_area_light() {
    // A quad filling the view, emissive factor 2 × a 2 × 1 texture (white | black, clamped):
    // bilinear between the texel centres at u = ¼ and ¾, so the radiance is 2 left of
    // u = ¼, 0 right of ¾ and linear between. The camera sees u ∈ [0, 1] across 8 columns;
    // a column's mean is the texture's mean over it (up to where its 64 samples fall in
    // the pixel: 0.02 covers that). Before, the texture became its mean, 1, everywhere.
    let mut g = Glb::new();
    let tex = g.texture(
        &png(2, 1, |x, _| if x == 0 { [255; 4] } else { [0, 0, 0, 255] }),
        Some(json!({"wrapS": 33071, "wrapT": 33071})),
    );
    let m = g.material(json!({"emissiveFactor": [2.0, 2.0, 2.0],
        "emissiveTexture": {"index": tex},
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0]}}));
    let q = g.quad(m);
    let mesh = g.mesh(vec![q]);
    g.node(json!({ "mesh": mesh }), true);
    let yfov = 2.0 * (1.0f32 / 3.0).atan();
    g.json["cameras"] = json!([{"type": "perspective",
        "perspective": {"yfov": yfov, "aspectRatio": 1.0, "znear": 0.1}}]);
    g.node(json!({"camera": 0, "translation": [0.0, 0.0, 3.0]}), true);
    let loaded = parse(&g).unwrap();
    assert!(
        loaded.warnings.iter().all(|w| !w.contains("emissive")),
        "{:?}",
        loaded.warnings
    );
    let mut desc = loaded.desc;
    assert!(desc.shapes[0].emission_texture.is_some());
    desc.render.width = 8;
    desc.render.height = 8;
    desc.render.spp = 64;
    desc.render.max_depth = 0;
    let scene = candela_core::build::build(&desc).unwrap();
    let r = candela_core::integrator::render(&scene, 0..64, &AtomicBool::new(false), &|_| {});
    let px = r.film.resolve();
    let column = |i: usize| (0..8).map(|j| px[j * 8 + i].x).sum::<f32>() / 8.0;
    let want = |i: usize| {
        // The texture's mean over u ∈ [i/8, (i + 1)/8], by a fine midpoint sum.
        (0..1000)
            .map(|k| {
                let u = (i as f32 + (k as f32 + 0.5) / 1000.0) / 8.0;
                2.0 * ((0.75 - u) / 0.5).clamp(0.0, 1.0)
            })
            .sum::<f32>()
            / 1000.0
    };
    for i in 0..8 {
        assert!(
            (column(i) - want(i)).abs() < 0.02,
            "column {i}: {} vs {}",
            column(i),
            want(i)
        );
    }
}

#[test]
fn partial_transmission_mixes_the_glass_in() {
    // KHR_materials_transmission t mixes the dielectric into the metallic-roughness BSDF
    // by t·(1 − metallic); t = 1 without a texture is the dielectric alone.
    for (t, metallic, want) in [
        (0.4f32, 0.5f32, Some(0.2f32)),
        (0.3, 0.0, Some(0.3)),
        (1.0, 0.0, None),
    ] {
        let mut g = Glb::one_quad();
        g.json["materials"][0] = json!({
            "pbrMetallicRoughness": {"metallicFactor": metallic, "roughnessFactor": 0.5},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": t}}});
        g.json["extensionsUsed"] = json!(["KHR_materials_transmission"]);
        let desc = parse(&g).unwrap().desc;
        match (&desc.materials[0].bsdf, want) {
            (BsdfDesc::Mix { weight, a, b }, Some(w)) => {
                let TextureDesc::Constant(c) = weight else {
                    panic!("{weight:?}")
                };
                assert!((c.x - w).abs() < 1e-6, "t {t}: weight {c}");
                assert!(matches!(**a, BsdfDesc::MetalRough { .. }));
                let BsdfDesc::Dielectric { alpha_u, .. } = **b else {
                    panic!("{b:?}")
                };
                assert_eq!(alpha_u, 0.25);
            }
            (BsdfDesc::Dielectric { .. }, None) => {}
            (other, _) => panic!("t {t}: {other:?}"),
        }
    }
}
