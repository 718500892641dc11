//! Every kind of bad scene input gives one `file:line:col: message` error that points at
//! the offending key or value (never a panic).

use std::fs;
use std::path::Path;

use candela_scene::{load_scene, parse_toml_scene};

/// The error of a scene text reported under the name `scene.toml`.
fn error(text: &str) -> String {
    parse_toml_scene(text, Path::new("scene.toml"))
        .expect_err("the scene should not load")
        .to_string()
}

const HEAD: &str = "[materials.white]\ntype = \"diffuse\"\nalbedo = 0.5\n\n";

#[test]
fn unknown_key() {
    let text = "[render]\nspp = 4\n\n[camera]\nposition = [0, 1, 3]\nfvo = 40\n";
    assert_eq!(
        error(text),
        "scene.toml:6:1: unknown field `fvo`, expected one of `type`, `position`, `look_at`, \
         `up`, `fov`, `focal_length`, `sensor`"
    );
}

#[test]
fn unknown_top_level_table() {
    assert_eq!(
        error("[render]\nspp = 4\n[lights]\n"),
        "scene.toml:3:2: unknown key `lights`, expected one of `render`, `camera`, \
         `materials`, `shape`, `light`, `environment`, `include`, `media`"
    );
}

#[test]
fn wrong_type() {
    assert_eq!(
        error("[render]\nspp = \"x\"\n"),
        "scene.toml:2:7: invalid type: string \"x\", expected u32"
    );
}

#[test]
fn bad_enum_value() {
    assert_eq!(
        error("[render]\nmis = \"fast\"\n"),
        "scene.toml:2:7: unknown variant `fast`, expected one of `balance`, `power`, `none`, \
         `bsdf`"
    );
}

#[test]
fn wrong_length_array() {
    assert_eq!(
        error("[camera]\nposition = [1, 2]\n"),
        "scene.toml:2:12: expected an array of 3 numbers, found 2"
    );
    assert_eq!(
        error("[render]\nresolution = [64]\n"),
        "scene.toml:2:14: invalid length 1, expected an array of length 2"
    );
}

#[test]
fn non_finite_number() {
    assert_eq!(
        error("[camera]\nposition = [0, nan, 1]\n"),
        "scene.toml:2:16: expected a finite number, found nan"
    );
    let text = format!("{HEAD}[[shape]]\ntype = \"sphere\"\nmaterial = \"white\"\nradius = -inf\n");
    assert_eq!(
        error(&text),
        "scene.toml:8:10: expected a finite number, found inf"
    );
}

#[test]
fn missing_mesh_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    fs::write(
        &scene,
        format!("{HEAD}[[shape]]\ntype = \"mesh\"\nfile = \"nope.obj\"\nmaterial = \"white\"\n"),
    )
    .unwrap();
    let e = load_scene(&scene).unwrap_err();
    let resolved = dir.path().join("nope.obj");
    assert_eq!(
        e.to_string(),
        format!(
            "{}:7:8: mesh file {} does not exist",
            scene.display(),
            resolved.display()
        )
    );
}

#[test]
fn unknown_material_is_reported_by_the_build_at_the_shape() {
    let text = format!(
        "{HEAD}[[shape]]\ntype = \"sphere\"\nmaterial = \"white\"\n\n  [[shape]]\n\
         type = \"cube\"\nmaterial = \"chrome\"\n"
    );
    let desc = parse_toml_scene(&text, Path::new("scene.toml")).unwrap();
    let e = candela_core::build::build(&desc).unwrap_err();
    assert_eq!(e.to_string(), "scene.toml:9:3: unknown material \"chrome\"");
}

#[test]
fn empty_obj_mesh() {
    let dir = tempfile::tempdir().unwrap();
    fs::write(
        dir.path().join("empty.obj"),
        "# nothing\nv 0 0 0\nv 1 0 0\n",
    )
    .unwrap();
    let scene = dir.path().join("scene.toml");
    fs::write(
        &scene,
        format!("{HEAD}[[shape]]\ntype = \"mesh\"\nmaterial = \"white\"\nfile = \"empty.obj\"\n"),
    )
    .unwrap();
    let e = load_scene(&scene).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}:8:8: {}: OBJ file has no faces",
            scene.display(),
            dir.path().join("empty.obj").display()
        )
    );
}

#[test]
fn obj_and_ply_parse_errors_name_the_mesh_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    fs::write(
        dir.path().join("bad.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n",
    )
    .unwrap();
    fs::write(
        dir.path().join("bad.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
         end_header\n0 0 0\n1 0 0\n0 1\n3 0 1 2\n",
    )
    .unwrap();
    for (file, line) in [("bad.obj", 3), ("bad.ply", 12)] {
        let scene = dir.path().join("scene.toml");
        fs::write(
            &scene,
            format!("{HEAD}[[shape]]\ntype = \"mesh\"\nfile = \"{file}\"\nmaterial = \"white\"\n"),
        )
        .unwrap();
        let e = load_scene(&scene).unwrap_err().to_string();
        let prefix = format!(
            "{}:7:8: {}:{line}: ",
            scene.display(),
            dir.path().join(file).display()
        );
        assert!(e.starts_with(&prefix), "{e}\ndoes not start with\n{prefix}");
    }
}

#[test]
fn truncated_binary_ply() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\n\
        property list uchar uint vertex_indices\nend_header\n"
        .to_vec();
    bytes.extend([0u8; 20]);
    fs::write(dir.path().join("cut.ply"), bytes).unwrap();
    let scene = dir.path().join("scene.toml");
    fs::write(
        &scene,
        format!("{HEAD}[[shape]]\ntype = \"mesh\"\nfile = \"cut.ply\"\nmaterial = \"white\"\n"),
    )
    .unwrap();
    let e = load_scene(&scene).unwrap_err().to_string();
    assert!(e.starts_with(&format!("{}:7:8: ", scene.display())), "{e}");
    assert!(e.contains("cut.ply") && e.contains("truncated"), "{e}");
}

#[test]
fn shape_type_errors() {
    assert_eq!(
        error("[[shape]]\ntype = \"blob\"\n"),
        "scene.toml:2:8: unknown shape type `blob`, expected one of `mesh`, `sphere`, \
         `rectangle`, `disk`, `cube`"
    );
    assert_eq!(
        error("[[shape]]\nmaterial = \"white\"\n"),
        "scene.toml:1:1: shape has no `type`; expected one of `mesh`, `sphere`, `rectangle`, \
         `disk`, `cube`"
    );
    // A key of another shape type is unknown here.
    let e = error("[[shape]]\ntype = \"cube\"\nmaterial = \"w\"\nradius = 2\n");
    assert!(
        e.starts_with("scene.toml:4:1: unknown field `radius`"),
        "{e}"
    );
    assert_eq!(
        error("[[shape]]\ntype = \"cube\"\n"),
        "scene.toml:1:1: missing field `material`"
    );
}

#[test]
fn mesh_source_errors() {
    let both = "[[shape]]\ntype = \"mesh\"\nmaterial = \"w\"\nfile = \"a.obj\"\n\
                positions = [[0, 0, 0]]\nindices = [[0, 0, 0]]\n";
    assert!(error(both).starts_with("scene.toml:4:8: `file` and inline mesh data"));
    assert_eq!(
        error("[[shape]]\ntype = \"mesh\"\nmaterial = \"w\"\npositions = [[0, 0, 0]]\n"),
        "scene.toml:1:1: a mesh needs either `file` or both `positions` and `indices`"
    );
    let out_of_range = "[[shape]]\ntype = \"mesh\"\nmaterial = \"w\"\n\
        positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 3]]\n";
    assert_eq!(
        error(out_of_range),
        "scene.toml:5:11: index 3 is out of range (3 positions)"
    );
    let normals = "[[shape]]\ntype = \"mesh\"\nmaterial = \"w\"\n\
        positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 2]]\n\
        normals = [[0, 0, 1]]\n";
    assert_eq!(error(normals), "scene.toml:6:11: 1 normals for 3 positions");
    let unsupported = "[[shape]]\ntype = \"mesh\"\nmaterial = \"w\"\nfile = \"scene.toml\"\n";
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    fs::write(&scene, unsupported).unwrap();
    let e = load_scene(&scene).unwrap_err().to_string();
    assert!(e.contains("unsupported mesh format \".toml\""), "{e}");
}

#[test]
fn transform_errors() {
    let shape = "[[shape]]\ntype = \"cube\"\nmaterial = \"w\"\ntransform = [";
    assert_eq!(
        error(&format!("{shape}{{ shear = 2 }}]\n")),
        "scene.toml:4:16: unknown variant `shear`, expected one of `translate`, `rotate`, \
         `scale`, `matrix`, `look_at`"
    );
    assert_eq!(
        error(&format!(
            "{shape}{{ rotate = {{ axis = [0, 0, 0], angle = 3 }} }}]\n"
        )),
        "scene.toml:4:14: rotation axis must not be zero"
    );
    assert_eq!(
        error(&format!("{shape}{{ matrix = [1, 0, 0, 1] }}]\n")),
        "scene.toml:4:25: expected an array of 16 numbers, found 4"
    );
    assert_eq!(
        error(&format!("{shape}{{ translate = [1, 0, 0], scale = 2 }}]\n")),
        "scene.toml:4:14: a transform step must have exactly one key (`translate`, `rotate`, \
         `scale`, `matrix` or `look_at`), found 2"
    );
    assert_eq!(
        error(&format!(
            "{shape}{{ rotate = {{ axis = [0, 1, 0], angle = 3, by = 1 }} }}]\n"
        )),
        "scene.toml:4:56: unexpected keys in table: by, available keys: axis, angle"
    );
    let e = error(&format!(
        "{shape}{{ translate = [0, 0, 0] }}, {{ look_at = {{ origin = [0, 0, 0], \
         target = [0, 5, 0] }} }}]\n"
    ));
    assert!(e.starts_with("scene.toml:4:41: look_at needs"), "{e}");
}

#[test]
fn light_errors() {
    assert_eq!(
        error("[[light]]\ntype = \"area\"\n"),
        "scene.toml:2:8: unknown light type `area`, expected one of `point`, `spot`, \
         `directional`, `projector`"
    );
    assert_eq!(
        error("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\n"),
        "scene.toml:1:1: the light needs an intensity or a `power`"
    );
}

#[test]
fn toml_syntax_error() {
    assert_eq!(
        error("[render]\nspp = 4\n[camera\n"),
        "scene.toml:3:8: unclosed table, expected `]`"
    );
}

#[test]
fn unknown_camera_type() {
    assert_eq!(
        error("[camera]\ntype = \"fisheye\"\n"),
        "scene.toml:2:8: unknown camera type `fisheye`, expected one of `pinhole`, `thin_lens`, `orthographic`"
    );
}
