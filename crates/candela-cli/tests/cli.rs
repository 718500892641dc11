//! End-to-end tests of the `candela` binary: files written, exit codes, located errors,
//! determinism (interruption: robustness.rs).

use std::path::PathBuf;

mod common;
use common::{candela, s, SCENE};

fn scene_dir(text: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    (dir, scene)
}

#[test]
fn renders_every_output_format() {
    let (dir, scene) = scene_dir(SCENE);
    for ext in ["png", "exr", "pfm"] {
        let out = dir.path().join(format!("out.{ext}"));
        let o = candela(&["render", s(&scene), "-o", s(&out)]);
        assert!(
            o.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(
            stdout.contains("24x16, 4 spp") && stdout.contains("rays/s"),
            "summary line: {stdout}"
        );
        let bytes = std::fs::read(&out).unwrap();
        let magic: &[u8] = match ext {
            "png" => b"\x89PNG",
            "exr" => &[0x76, 0x2f, 0x31, 0x01],
            _ => b"PF\n24 16\n",
        };
        assert!(bytes.starts_with(magic), "{ext} header");
    }
    let png = image::open(dir.path().join("out.png")).unwrap();
    assert_eq!((png.width(), png.height()), (24, 16));
    // No temporary files are left behind.
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".candela-"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn same_seed_gives_the_same_image_whatever_the_thread_count() {
    let (dir, scene) = scene_dir(SCENE);
    let render = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec!["render", s(&scene), "-o", s(&out)];
        args.extend_from_slice(extra);
        assert!(candela(&args).status.success());
        std::fs::read(out).unwrap()
    };
    let a = render("a.pfm", &["--threads", "1", "--seed", "3"]);
    let b = render("b.pfm", &["--threads", "2", "--seed", "3"]);
    let c = render("c.pfm", &["--threads", "2", "--seed", "4"]);
    assert_eq!(a, b, "thread count changed the image");
    assert_ne!(a, c, "the seed did not change the image");
    // The default sampler is sobol-cmj; the independent and zsobol ones are as
    // deterministic.
    let independent = ["--sampler", "independent", "--seed", "3"];
    let d = render("d.pfm", &[&["--threads", "1"][..], &independent].concat());
    let e = render("e.pfm", &[&["--threads", "2"][..], &independent].concat());
    assert_eq!(d, e, "thread count changed the independent sampler's image");
    assert_ne!(a, d, "--sampler independent did not change the image");
    let zsobol = ["--sampler", "zsobol", "--seed", "3"];
    let g = render("g.pfm", &[&["--threads", "1"][..], &zsobol].concat());
    let h = render("h.pfm", &[&["--threads", "2"][..], &zsobol].concat());
    assert_eq!(g, h, "thread count changed the zsobol sampler's image");
    assert_ne!(a, g, "--sampler zsobol did not change the image");
    assert_eq!(
        a,
        render("f.pfm", &["--sampler", "sobol-cmj", "--seed", "3"])
    );
}

#[test]
fn overrides_change_resolution() {
    let (dir, scene) = scene_dir(SCENE);
    let out = dir.path().join("o.png");
    let o = candela(&[
        "render",
        s(&scene),
        "-o",
        s(&out),
        "--res",
        "10x7",
        "--spp",
        "2",
        "--max-depth",
        "1",
    ]);
    assert!(o.status.success());
    let png = image::open(&out).unwrap();
    assert_eq!((png.width(), png.height()), (10, 7));
}

#[test]
fn malformed_scene_gives_exit_2_and_a_located_message_and_keeps_old_output() {
    let bad = SCENE.replace("fov = 45", "fvo = 45");
    let (dir, scene) = scene_dir(&bad);
    let out = dir.path().join("keep.png");
    std::fs::write(&out, b"previous image").unwrap();
    let o = candela(&["render", s(&scene), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    let line = SCENE.lines().position(|l| l.starts_with("fov")).unwrap() + 1;
    assert!(
        err.contains(&format!("scene.toml:{line}:")),
        "location missing: {err}"
    );
    assert!(err.contains("fvo"), "message should name the key: {err}");
    assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
    assert_eq!(std::fs::read(&out).unwrap(), b"previous image");
}

#[test]
fn unknown_material_and_missing_scene_are_user_errors() {
    let (dir, scene) = scene_dir(&SCENE.replace(
        "material = \"white\"\nemission",
        "material = \"gold\"\nemission",
    ));
    let o = candela(&["render", s(&scene), "-o", s(&dir.path().join("x.png"))]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown material \"gold\""));
    let o = candela(&["render", "does/not/exist.toml", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2));
    let o = candela(&["render", s(&scene), "-o", "x.jpg"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unsupported output format"));
}

#[test]
fn unwritable_output_is_a_clear_error() {
    let (dir, scene) = scene_dir(SCENE);
    let out = dir.path().join("no/such/folder/x.png");
    let o = candela(&["render", s(&scene), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot write"));
}

#[test]
fn info_describes_the_scene() {
    let (_dir, scene) = scene_dir(SCENE);
    let o = candela(&["info", s(&scene)]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("triangles  2"), "{text}");
    assert!(text.contains("lights     2"), "{text}");
    assert!(text.contains("materials  1 (white)"), "{text}");
}

#[test]
fn info_and_render_report_instanced_triangles() {
    let (dir, scene) = scene_dir(&format!(
        "{SCENE}
[[shape]]
type = \"mesh\"
positions = [[0, 0, -2], [1, 0, -2], [0, 1, -2]]
indices = [[0, 1, 2]]
material = \"white\"
instances = [[], [{{ translate = [-1, 0, 0] }}], [{{ translate = [0, -1, 0] }}]]
"
    ));
    let o = candela(&["info", s(&scene)]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    // The base scene's 2 triangles, and 3 instances of 1.
    assert!(
        text.contains("triangles  5 rendered, 3 stored (3 instances of 1 shared mesh)"),
        "{text}"
    );
    let out = dir.path().join("x.png");
    let o = candela(&["render", s(&scene), "-o", s(&out), "--spp", "1"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("3 instances of 1 shared mesh: 3 triangles stored, 5 rendered"),
        "{text}"
    );
}

#[test]
fn info_reports_the_environment() {
    // A 100×50 panorama, black but for one texel: all power in the brightest 1%.
    let (dir, scene) = scene_dir(&format!(
        "{SCENE}\n[environment]\nequirect = \"sky.png\"\nstrength = 2\n"
    ));
    let mut img = image::RgbImage::new(100, 50);
    img.put_pixel(10, 20, image::Rgb([255, 255, 255]));
    img.save(dir.path().join("sky.png")).unwrap();
    let o = candela(&["info", s(&scene)]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(text.contains("1 environments"), "{text}");
    assert!(
        text.contains("environment equirect 100x50, strength 2, visible"),
        "{text}"
    );
    assert!(text.contains("hold 100.0% of it"), "{text}");
}

#[cfg(unix)]
#[test]
fn lens_flags_blur_the_render_and_bad_values_are_located_errors() {
    let (dir, scene) = scene_dir(SCENE);
    let render = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let args = [&["render", s(&scene), "-o", s(&out), "--spp", "4"], extra].concat();
        let o = candela(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(&out).unwrap()
    };
    let pinhole = render("a.pfm", &[]);
    // A very wide aperture focused far behind the sphere changes the image...
    let blurred = render("b.pfm", &["--f-number", "0.05", "--focus-distance", "20"]);
    assert_ne!(pinhole, blurred);
    // ...a focus distance alone keeps the pinhole (no aperture), bit for bit.
    assert_eq!(pinhole, render("c.pfm", &["--focus-distance", "20"]));

    let o = candela(&[
        "render",
        s(&scene),
        "-o",
        s(&dir.path().join("d.png")),
        "--f-number",
        "-1",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    let line = SCENE.lines().position(|l| l == "[camera]").unwrap() + 1;
    assert!(err.contains(&format!("scene.toml:{line}:")), "{err}");
    assert!(err.contains("f-number -1 must be positive"), "{err}");
}

#[test]
fn a_bare_obj_or_ply_renders_under_the_default_camera_and_sky() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("quad.obj");
    std::fs::write(&obj, "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n").unwrap();
    let ply = dir.path().join("quad.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
         end_header\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n",
    )
    .unwrap();
    for model in [obj, ply] {
        let out = dir.path().join("out.png");
        let o = candela(&[
            "render",
            s(&model),
            "-o",
            s(&out),
            "--res",
            "16x16",
            "--spp",
            "2",
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(err.contains("white environment"), "{err}");
        let img = image::open(&out).unwrap().to_rgb8();
        // The grey model in the middle is darker than the white sky around it.
        let (centre, corner) = (img.get_pixel(8, 8)[0], img.get_pixel(0, 0)[0]);
        assert!(
            centre < corner,
            "{model:?}: centre {centre}, corner {corner}"
        );
    }
}

/// `--lamp-sampling` reaches the lamps: a panel close over the floor renders differently
/// (other points drawn on it) under `solid-angle` than by area, the scene's key says the
/// same as the flag, and a misspelt value is refused before anything renders.
#[test]
fn lamp_sampling_flag_and_key_reach_the_lamps() {
    let panel = "\n[[shape]]\ntype = \"rectangle\"\nmaterial = \"white\"\nemission = 3\n\
                 transform = [{ rotate = { axis = [1, 0, 0], angle = 90 } }, \
                 { translate = [0, 0.4, 0] }]\n";
    let (dir, scene) = scene_dir(&format!("{SCENE}{panel}"));
    let render = |scene: &PathBuf, name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let args = [
            &["render", s(scene), "-o", s(&out), "--threads", "1"],
            extra,
        ]
        .concat();
        let o = candela(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(&out).unwrap()
    };
    let area = render(&scene, "a.pfm", &[]);
    assert_eq!(area, render(&scene, "b.pfm", &["--lamp-sampling", "area"]));
    let solid_angle = render(&scene, "c.pfm", &["--lamp-sampling", "solid-angle"]);
    assert_ne!(
        area, solid_angle,
        "--lamp-sampling solid-angle changed nothing"
    );
    let keyed = dir.path().join("keyed.toml");
    let text = format!("{SCENE}{panel}")
        .replace("[render]\n", "[render]\nlamp_sampling = \"solid-angle\"\n");
    std::fs::write(&keyed, text).unwrap();
    assert_eq!(solid_angle, render(&keyed, "d.pfm", &[]));

    let out = dir.path().join("e.pfm");
    let o = candela(&[
        "render",
        s(&scene),
        "-o",
        s(&out),
        "--lamp-sampling",
        "sphere",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("solid-angle"), "{err}");
    assert!(!out.exists());
}

/// `--integrator lanes` renders the path integrator's image (bit for bit: see
/// candela-scene's lanes_consistency) and says once why a scene with media falls back.
#[test]
fn the_lanes_integrator_renders_the_same_file_and_names_its_fallback() {
    let (dir, scene) = scene_dir(SCENE);
    let render = |integrator: &str, scene: &str, out: &str| {
        let out = dir.path().join(out);
        let o = candela(&["render", scene, "-o", s(&out), "--integrator", integrator]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        (
            std::fs::read(&out).unwrap(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (path, _) = render("path", s(&scene), "path.pfm");
    let (lanes, quiet) = render("lanes", s(&scene), "lanes.pfm");
    assert!(path == lanes, "the lanes integrator wrote another image");
    assert!(!quiet.contains("--integrator lanes"), "{quiet}");
    let media = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/media.toml");
    let o = candela(&[
        "render",
        s(&media),
        "-o",
        s(&dir.path().join("media.pfm")),
        "--integrator",
        "lanes",
        "--res",
        "16x12",
        "--spp",
        "1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        stderr.matches("participating media").count(),
        1,
        "one fallback line: {stderr}"
    );
}
