//! `[[include]]` of a glTF file in a TOML scene: the documented example parses, shapes
//! and lights land where the include's transform puts them, materials do not clash.

use std::fs;

use candela_core::desc::{GeometryDesc, LightKindDesc};
use candela_scene::{load_scene_with, LoadOptions};
use candela_test_support::gltf::Glb;
use glam::{Mat4, Vec3};
use serde_json::json;

/// A GLB with one quad and a point light 2 units above it.
fn lamp() -> Vec<u8> {
    let mut g = Glb::new();
    let m = g.material(json!({"name": "shade"}));
    let q = g.quad(m);
    let mesh = g.mesh(vec![q]);
    g.node(json!({"mesh": mesh, "translation": [0.0, 0.0, 1.0]}), true);
    g.json["extensions"] =
        json!({"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 3.0}]}});
    g.node(json!({"translation": [0.0, 2.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}), true);
    g.bytes()
}

fn doc_example() -> String {
    let doc = fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/scene-format.md"
    ))
    .unwrap();
    let at = doc
        .find("### `[[include]]`")
        .expect("the doc documents [[include]]");
    let start = at + doc[at..].find("```toml\n").unwrap() + 8;
    doc[start..start + doc[start..].find("```").unwrap()].to_string()
}

#[test]
fn documented_include_places_the_file_by_its_transform() {
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("lamp.glb"), lamp()).unwrap();
    let scene = format!(
        "[materials.floor]\ntype = \"diffuse\"\n\n[[shape]]\ntype = \"rectangle\"\nmaterial = \"floor\"\n\n{}\n{}",
        doc_example(),
        // The same file again, untransformed and without its lights.
        "[[include]]\ngltf = \"lamp.glb\"\nlights = false\n"
    );
    let path = dir.path().join("room.toml");
    fs::write(&path, scene).unwrap();
    let loaded = load_scene_with(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let d = &loaded.desc;
    assert_eq!(d.shapes.len(), 3);
    assert_eq!(d.lights.len(), 1, "the second include brings no lights");
    let t = Mat4::from_translation(Vec3::Y) * Mat4::from_scale(Vec3::splat(0.5));
    let node = Mat4::from_translation(Vec3::Z);
    // Entries of one array keep their order; the include numbered 0 is the first.
    let by = |name: &str| d.shapes.iter().find(|s| s.material == name).unwrap();
    let (first, second) = (by("include 0:gltf0:shade"), by("include 1:gltf0:shade"));
    assert!(
        first.transform.abs_diff_eq(t * node, 1e-6),
        "{}",
        first.transform
    );
    assert!(second.transform.abs_diff_eq(node, 1e-6));
    assert!(matches!(first.geometry, GeometryDesc::Mesh(_)));
    // The light 2 up in the file: 0.5·2 + 1 = 2 up in the scene.
    let LightKindDesc::ShapedPoint(p) = &d.lights[0].kind else {
        panic!()
    };
    assert!(
        (p.position - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6,
        "{}",
        p.position
    );
    // Three distinct materials: the scene's and one per include.
    let mut names: Vec<&str> = d.materials.iter().map(|m| m.name.as_str()).collect();
    names.sort();
    assert_eq!(
        names,
        ["floor", "include 0:gltf0:shade", "include 1:gltf0:shade"]
    );
    candela_core::build::build(d).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn include_errors_are_located() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    fs::write(&path, "[[include]]\ngltf = \"nope.glb\"\n").unwrap();
    let e = load_scene_with(&path, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("s.toml:2:8: cannot read glTF file"), "{e}");
    fs::write(&path, "[[include]]\ngltf = \"a.glb\"\nscale = 2\n").unwrap();
    let e = load_scene_with(&path, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("s.toml:3:1: unknown field `scale`"), "{e}");
    // Errors inside the glTF file name that file.
    fs::write(dir.path().join("bad.gltf"), "{ \"asset\": 3 }").unwrap();
    fs::write(&path, "[[include]]\ngltf = \"bad.gltf\"\n").unwrap();
    let e = load_scene_with(&path, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.gltf:1:"), "{e}");
}
