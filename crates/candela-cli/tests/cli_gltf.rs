//! `candela render` on glTF files: the README's example renders deterministically, a
//! model without lights gets the default sky with a warning, `--env`/`--env-strength`
//! relight it, `--scene` picks a scene, and broken files exit 2 with a located message.

use std::path::{Path, PathBuf};

mod common;
use common::candela;

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/gltf/spheres.gltf")
}

/// The mean of a PFM's floats (the header is three text lines).
fn pfm_mean(path: &Path) -> f64 {
    let bytes = std::fs::read(path).unwrap();
    let mut lines = 0;
    let start = bytes.iter().position(|&b| {
        lines += (b == b'\n') as u32;
        lines == 3
    });
    let data = &bytes[start.unwrap() + 1..];
    let v: Vec<f32> = data
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

/// A glTF with one triangle and no light, its buffer embedded as base64.
const NO_LIGHTS: &str = r#"{
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}, {"nodes": []}],
  "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]
}"#;

#[test]
fn the_example_renders_the_same_for_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let ex = example();
    let render = |name: &str, threads: &str| {
        let out = dir.path().join(name);
        let o = candela(&[
            "render",
            ex.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--res",
            "32x20",
            "--spp",
            "2",
            "--threads",
            threads,
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(out).unwrap()
    };
    let a = render("a.pfm", "1");
    assert_eq!(a, render("b.pfm", "2"));
    assert!(pfm_mean(&dir.path().join("a.pfm")) > 0.0);
}

#[test]
fn no_lights_means_a_default_sky_and_env_flags_relight() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("tri.gltf");
    std::fs::write(&model, NO_LIGHTS).unwrap();
    let m = model.to_str().unwrap();
    let out = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let o = candela(&[
        "render",
        m,
        "-o",
        &out("a.pfm"),
        "--res",
        "16x16",
        "--spp",
        "2",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("no lights: lit by a uniform white environment"),
        "{err}"
    );
    let o = candela(&[
        "render",
        m,
        "-o",
        &out("b.pfm"),
        "--res",
        "16x16",
        "--spp",
        "2",
        "--env-strength",
        "3",
    ]);
    assert!(o.status.success());
    // Everything scales with the only light: 3 times the image.
    let (a, b) = (
        pfm_mean(&dir.path().join("a.pfm")),
        pfm_mean(&dir.path().join("b.pfm")),
    );
    assert!((b / a - 3.0).abs() < 1e-4, "{a} {b}");
    let sky = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/hdri/venice_sunset_1k.hdr");
    if sky.exists() {
        let o = candela(&[
            "render",
            m,
            "-o",
            &out("c.pfm"),
            "--res",
            "16x16",
            "--spp",
            "2",
            "--env",
            sky.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_ne!(pfm_mean(&dir.path().join("c.pfm")), a);
    } else {
        eprintln!(
            "skipped: ../shared/data not found (--env with {} is absent)",
            sky.display()
        );
    }
    // Scene 1 is empty: it renders (the sky alone); scene 2 does not exist.
    let o = candela(&[
        "render",
        m,
        "-o",
        &out("d.pfm"),
        "--res",
        "8x8",
        "--spp",
        "1",
        "--scene",
        "1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = candela(&["render", m, "-o", &out("e.pfm"), "--scene", "2"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("scene 2 does not exist"));
}

#[test]
fn broken_gltf_exits_2_with_a_located_message() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("bad.gltf");
    std::fs::write(&model, NO_LIGHTS.replace("\"count\": 3", "\"count\": 30")).unwrap();
    let o = candela(&["render", model.to_str().unwrap(), "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("bad.gltf: meshes[0].primitives[0]: POSITION: accessor 0 reads past the end"),
        "{err}"
    );
    let o = candela(&["info", model.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
}
