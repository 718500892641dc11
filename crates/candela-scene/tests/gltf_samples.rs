//! glTF import on the Khronos sample models in shared/data/gltf: what the loader builds
//! must equal what the files say, read independently here from their JSON (triangle
//! counts per placed primitive, POSITION bounds, material factors, lights), and each
//! model must render without a non-finite sample.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use candela_core::desc::{
    BsdfDesc, GeometryDesc, LightAmountDesc, LightColorDesc, LightKindDesc, SceneDesc, TextureDesc,
};
use candela_scene::{load_scene_with, LoadOptions};
use glam::{Mat4, Quat, Vec3};
use serde_json::Value;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/gltf");

const MODELS: &[&str] = &[
    "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf",
    "MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf",
    "EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf",
    "NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb",
];

fn model(rel: &str) -> Option<PathBuf> {
    let p = Path::new(DATA).join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!(
            "skipped: ../shared/data not found ({} is absent)",
            p.display()
        );
        None
    }
}

fn f32s(v: &Value) -> Vec<f32> {
    v.as_array()
        .map(|a| a.iter().map(|x| x.as_f64().unwrap() as f32).collect())
        .unwrap_or_default()
}

/// A node's local matrix from the JSON (matrix, or T·R·S).
fn local(node: &Value) -> Mat4 {
    if let Some(m) = node.get("matrix") {
        return Mat4::from_cols_slice(&f32s(m));
    }
    let t = node
        .get("translation")
        .map_or(Vec3::ZERO, |v| Vec3::from_slice(&f32s(v)));
    let r = node
        .get("rotation")
        .map_or(Quat::IDENTITY, |v| Quat::from_slice(&f32s(v)));
    let s = node
        .get("scale")
        .map_or(Vec3::ONE, |v| Vec3::from_slice(&f32s(v)));
    Mat4::from_scale_rotation_translation(s, r, t)
}

/// What the file places, in the loader's order (depth first, children in order):
/// (mesh, primitive, world) for each primitive and (light, world) for each light.
#[derive(Default)]
struct Placed {
    prims: Vec<(usize, usize, Mat4)>,
    lights: Vec<(usize, Mat4)>,
}

fn walk(json: &Value, node: usize, parent: Mat4, out: &mut Placed) {
    let n = &json["nodes"][node];
    let world = parent * local(n);
    if let Some(m) = n.get("mesh").and_then(Value::as_u64) {
        let count = json["meshes"][m as usize]["primitives"]
            .as_array()
            .unwrap()
            .len();
        for p in 0..count {
            out.prims.push((m as usize, p, world));
        }
    }
    if let Some(l) = n.pointer("/extensions/KHR_lights_punctual/light") {
        out.lights.push((l.as_u64().unwrap() as usize, world));
    }
    for c in n
        .get("children")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        walk(json, c.as_u64().unwrap() as usize, world, out);
    }
}

fn placed(json: &Value) -> Placed {
    let scene = json.get("scene").and_then(Value::as_u64).unwrap_or(0) as usize;
    let mut out = Placed::default();
    for n in json["scenes"][scene]["nodes"].as_array().unwrap() {
        walk(json, n.as_u64().unwrap() as usize, Mat4::IDENTITY, &mut out);
    }
    out
}

/// Triangles of a primitive from its accessor counts and mode.
fn triangles(json: &Value, prim: &Value) -> usize {
    let acc = prim
        .get("indices")
        .unwrap_or(&prim["attributes"]["POSITION"])
        .as_u64()
        .unwrap() as usize;
    let count = json["accessors"][acc]["count"].as_u64().unwrap() as usize;
    match prim.get("mode").and_then(Value::as_u64).unwrap_or(4) {
        4 => count / 3,
        5 | 6 => count.saturating_sub(2),
        _ => 0,
    }
}

/// Strips the wrappers that do not change the parameters.
fn core_bsdf(b: &BsdfDesc) -> &BsdfDesc {
    match b {
        BsdfDesc::TwoSided(i) | BsdfDesc::OneSided(i) => core_bsdf(i),
        BsdfDesc::NormalMap { inner, .. } | BsdfDesc::Alpha { inner, .. } => core_bsdf(inner),
        b => b,
    }
}

/// The factor a texture slot carries: its constant, or the scale of its image.
fn factor(t: &TextureDesc) -> Vec3 {
    match t {
        TextureDesc::Constant(c) => *c,
        TextureDesc::Image(i) => i.scale,
        TextureDesc::Checker { .. } => panic!("glTF makes no checkers"),
    }
}

fn close(a: Vec3, b: Vec3, what: &str) {
    assert!(
        (a - b).abs().max_element() <= 1e-6 * (1.0 + b.abs().max_element()),
        "{what}: {a} vs {b}"
    );
}

fn check_model(path: &Path) -> SceneDesc {
    let json = candela_test_support::gltf::read_json(&std::fs::read(path).unwrap());
    let loaded = load_scene_with(path, &LoadOptions::default()).unwrap();
    let desc = loaded.desc;
    let placed = placed(&json);
    let name = path.file_name().unwrap().to_string_lossy().to_string();

    // Shapes: one per placed primitive, with the file's triangle count, bounds and
    // placement.
    assert_eq!(desc.shapes.len(), placed.prims.len(), "{name}: shapes");
    let mut total = 0;
    for (shape, &(m, p, world)) in desc.shapes.iter().zip(&placed.prims) {
        let prim = &json["meshes"][m]["primitives"][p];
        let GeometryDesc::Mesh(mesh) = &shape.geometry else {
            panic!("{name}: glTF shapes are meshes")
        };
        assert_eq!(
            mesh.indices.len(),
            triangles(&json, prim),
            "{name}: mesh {m}/{p}"
        );
        total += mesh.indices.len();
        let acc = &json["accessors"][prim["attributes"]["POSITION"].as_u64().unwrap() as usize];
        let (lo, hi) = mesh
            .positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &q| {
                (lo.min(q), hi.max(q))
            });
        close(
            lo,
            Vec3::from_slice(&f32s(&acc["min"])),
            &format!("{name}: {m}/{p} min"),
        );
        close(
            hi,
            Vec3::from_slice(&f32s(&acc["max"])),
            &format!("{name}: {m}/{p} max"),
        );
        assert!(
            shape.transform.abs_diff_eq(world, 1e-5),
            "{name}: {m}/{p} transform"
        );

        // The material's factors.
        let mi = prim
            .get("material")
            .and_then(Value::as_u64)
            .map(|i| i as usize);
        let mat = desc
            .materials
            .iter()
            .find(|d| d.name == shape.material)
            .unwrap();
        let Some(mi) = mi else { continue };
        let jm = &json["materials"][mi];
        let pbr = &jm["pbrMetallicRoughness"];
        let bc = pbr.get("baseColorFactor").map_or(vec![1.0; 4], f32s);
        let metallic = pbr
            .get("metallicFactor")
            .map_or(1.0, |v| v.as_f64().unwrap() as f32);
        let rough = pbr
            .get("roughnessFactor")
            .map_or(1.0, |v| v.as_f64().unwrap() as f32);
        let transmission = jm
            .pointer("/extensions/KHR_materials_transmission/transmissionFactor")
            .map_or(0.0, |v| v.as_f64().unwrap() as f32);
        match core_bsdf(&mat.bsdf) {
            BsdfDesc::MetalRough {
                base_color,
                metallic: m_t,
                roughness,
            } => {
                assert!(transmission <= 0.0, "{name}: material {mi}");
                close(
                    factor(base_color),
                    Vec3::new(bc[0], bc[1], bc[2]),
                    &format!("{name}: material {mi} base"),
                );
                close(
                    factor(m_t),
                    Vec3::splat(metallic),
                    &format!("{name}: material {mi} metallic"),
                );
                close(
                    factor(roughness),
                    Vec3::splat(rough),
                    &format!("{name}: material {mi} roughness"),
                );
            }
            BsdfDesc::Dielectric { eta, alpha_u, .. } => {
                assert!(transmission >= 1.0, "{name}: material {mi}");
                let ior = jm
                    .pointer("/extensions/KHR_materials_ior/ior")
                    .map_or(1.5, |v| v.as_f64().unwrap() as f32);
                assert_eq!(*eta, ior);
                assert!((alpha_u - rough * rough).abs() < 1e-6);
            }
            BsdfDesc::Mix { a, b, .. } => {
                assert!(transmission > 0.0, "{name}: material {mi}");
                assert!(matches!(**a, BsdfDesc::MetalRough { .. }), "{name}: {mi}");
                assert!(matches!(**b, BsdfDesc::Dielectric { .. }), "{name}: {mi}");
            }
            _ => panic!("{name}: material {mi} became an unexpected BSDF"),
        }
        assert_eq!(
            matches!(mat.bsdf, BsdfDesc::TwoSided(_)),
            jm.get("doubleSided")
                .and_then(Value::as_bool)
                .unwrap_or(false),
            "{name}: material {mi} doubleSided"
        );
        assert_eq!(
            core_bsdf_alpha(&mat.bsdf).is_some(),
            jm.get("alphaMode")
                .and_then(Value::as_str)
                .unwrap_or("OPAQUE")
                != "OPAQUE",
            "{name}: material {mi} alphaMode"
        );
        let strength = jm
            .pointer("/extensions/KHR_materials_emissive_strength/emissiveStrength")
            .map_or(1.0, |v| v.as_f64().unwrap() as f32);
        let emissive =
            Vec3::from_slice(&jm.get("emissiveFactor").map_or(vec![0.0; 3], f32s)) * strength;
        let got = shape.emission.unwrap_or(Vec3::ZERO);
        close(got, emissive, &format!("{name}: material {mi} emission"));
        assert_eq!(
            shape.emission_texture.is_some(),
            jm.get("emissiveTexture").is_some() && emissive != Vec3::ZERO,
            "{name}: material {mi} emissive texture"
        );
    }
    eprintln!("{name}: {} shapes, {total} triangles", desc.shapes.len());

    // Lights: kind, intensity (candela) and colour as in the file, at the node's origin.
    let jl = json.pointer("/extensions/KHR_lights_punctual/lights");
    assert_eq!(desc.lights.len(), placed.lights.len(), "{name}: lights");
    for (l, &(li, world)) in desc.lights.iter().zip(&placed.lights) {
        let j = &jl.unwrap()[li];
        let intensity = j
            .get("intensity")
            .map_or(1.0, |v| v.as_f64().unwrap() as f32);
        let color = Vec3::from_slice(&j.get("color").map_or(vec![1.0; 3], f32s));
        let pos = world.transform_point3(Vec3::ZERO);
        match (&l.kind, j["type"].as_str().unwrap()) {
            (LightKindDesc::ShapedPoint(p), "point") => {
                assert_eq!(p.amount, LightAmountDesc::Candela(intensity));
                assert_eq!(p.color, LightColorDesc::Rgb(color));
                close(p.position, pos, &format!("{name}: light {li} position"));
            }
            (LightKindDesc::Spot(s), "spot") => {
                assert_eq!(s.amount, LightAmountDesc::Candela(intensity));
            }
            (LightKindDesc::Directional(d), "directional") => {
                assert_eq!(d.amount, LightAmountDesc::Candela(intensity));
            }
            (k, t) => panic!("{name}: light {li} of type {t} became {k:?}"),
        }
    }
    desc
}

fn core_bsdf_alpha(b: &BsdfDesc) -> Option<&candela_core::desc::AlphaDesc> {
    match b {
        BsdfDesc::Alpha { alpha, .. } => Some(alpha),
        BsdfDesc::TwoSided(i) | BsdfDesc::OneSided(i) => core_bsdf_alpha(i),
        BsdfDesc::NormalMap { inner, .. } => core_bsdf_alpha(inner),
        _ => None,
    }
}

/// Renders at 24×24, 2 spp and checks that no sample was non-finite.
fn renders_finite(mut desc: SceneDesc, name: &str) {
    desc.render.width = 24;
    desc.render.height = 24;
    desc.render.spp = 2;
    let scene = candela_core::build::build(&desc).unwrap();
    let r = candela_core::integrator::render(&scene, 0..2, &AtomicBool::new(false), &|_| {});
    assert_eq!(r.film.rejected_samples(), 0, "{name}: non-finite samples");
    let pixels = r.film.resolve();
    assert!(pixels.iter().all(|p| p.is_finite()), "{name}");
    let mean = pixels.iter().map(|p| p.element_sum()).sum::<f32>() / pixels.len() as f32;
    assert!(mean > 0.0, "{name}: black image");
}

#[test]
fn khronos_samples_import_as_their_files_say_and_render_finite() {
    for rel in MODELS {
        let Some(path) = model(rel) else { continue };
        let desc = check_model(&path);
        renders_finite(desc, rel);
    }
}

#[test]
fn lamp_has_five_point_lights_and_a_blended_shade() {
    let Some(path) = model(MODELS[0]) else { return };
    let loaded = load_scene_with(&path, &LoadOptions::default()).unwrap();
    let points = loaded
        .desc
        .lights
        .iter()
        .filter(|l| matches!(l.kind, LightKindDesc::ShapedPoint(_)))
        .count();
    assert_eq!(points, 5);
    // Textured transmission becomes a mix with a dielectric; the BLEND material an alpha
    // wrapper.
    let bsdfs: Vec<&BsdfDesc> = loaded.desc.materials.iter().map(|m| &m.bsdf).collect();
    assert!(bsdfs.iter().any(|b| matches!(core_bsdf(b),
        BsdfDesc::Mix { b, .. } if matches!(**b, BsdfDesc::Dielectric { .. }))));
    assert!(bsdfs.iter().any(|b| core_bsdf_alpha(b).is_some()));
    // Its TANGENTs and transmission tint are read now: neither is warned about.
    eprintln!("warnings: {:?}", loaded.warnings);
    assert!(loaded
        .warnings
        .iter()
        .all(|w| !w.contains("TANGENT") && !w.contains("tint")));
}

#[test]
fn mirror_test_keeps_its_tangents_with_both_handednesses() {
    // NormalTangentMirrorTest mirrors uvs on part of its surface, so its TANGENT carries
    // w = +1 and w = −1; the loader keeps every tangent (unit xyz, w = ±1) for the normal map.
    let Some(path) = model(MODELS[3]) else { return };
    let loaded = load_scene_with(&path, &LoadOptions::default()).unwrap();
    assert!(loaded.warnings.iter().all(|w| !w.contains("TANGENT")));
    let (mut plus, mut minus) = (0, 0);
    for shape in &loaded.desc.shapes {
        let GeometryDesc::Mesh(m) = &shape.geometry else {
            continue;
        };
        assert_eq!(m.tangents.len(), m.positions.len());
        for t in &m.tangents {
            assert!((t.truncate().length() - 1.0).abs() < 1e-3, "{t}");
            assert!(t.w == 1.0 || t.w == -1.0, "{t}");
            if t.w > 0.0 {
                plus += 1;
            } else {
                minus += 1;
            }
        }
    }
    eprintln!("tangents: {plus} with w = +1, {minus} with w = −1");
    assert!(plus > 0 && minus > 0, "{plus} / {minus}");
}
