//! Loaders hand repeated meshes to the build as one shared `Arc`, which it instances: glTF
//! nodes sharing a mesh, Mitsuba `shapegroup` + `instance` (and one `obj` file named by
//! several shapes), TOML `[[shape]]`s naming one file and a mesh's `instances` list. Bad
//! references are located errors.

use std::fs;
use std::path::Path;
use std::sync::Arc;

use candela_core::desc::{GeometryDesc, MeshDesc, SceneDesc};
use candela_core::geometry::Ray;
use candela_scene::gltf::parse_gltf;
use candela_scene::{load_scene, LoadOptions};
use candela_test_support::files;
use candela_test_support::gltf::Glb;
use glam::{Mat4, Vec3};
use serde_json::json;

/// Two triangles: the square [0,1]² at z = 0 facing +z.
const SQUARE_OBJ: &str =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n";

/// Writes `files` (name, text) into a fresh folder and loads the first.
fn load_files(files: &[(&str, &str)]) -> (tempfile::TempDir, Result<SceneDesc, String>) {
    let files: Vec<(&str, &[u8])> = files.iter().map(|(n, t)| (*n, t.as_bytes())).collect();
    let (dir, r) = files::load_files(&files, &LoadOptions::default());
    (dir, r.map(|l| l.desc).map_err(|e| e.to_string()))
}

fn load(files: &[(&str, &str)]) -> SceneDesc {
    load_files(files).1.unwrap_or_else(|e| panic!("{e}"))
}

/// The error, with the temporary folder taken off the file name.
fn load_err(files: &[(&str, &str)]) -> String {
    let (dir, r) = load_files(files);
    files::without_dir(dir.path(), &r.expect_err("should fail"))
}

fn mesh(desc: &SceneDesc, i: usize) -> Arc<MeshDesc> {
    match &desc.shapes[i].geometry {
        GeometryDesc::Mesh(m) => m.clone(),
        g => panic!("shape {i} is {g:?}"),
    }
}

/// Builds the scene and checks it stores `stored` triangles and renders `instanced`, with
/// `instances` instances; then that a ray down −z onto each given point hits at z = 0.
fn check_built(desc: &SceneDesc, instances: usize, stored: usize, rendered: usize, at: &[Vec3]) {
    let scene = candela_core::build::build(desc).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.instances.instances.len(), instances);
    assert_eq!(scene.stored_triangle_count(), stored);
    assert_eq!(scene.triangle_count(), rendered);
    for &p in at {
        let ray = Ray::new(p + Vec3::Z * 10.0, -Vec3::Z);
        let hit = scene.intersect(&ray, f32::INFINITY);
        let hit = hit.unwrap_or_else(|| panic!("no hit at {p}"));
        assert!(hit.p.abs_diff_eq(p, 1e-5), "{} vs {p}", hit.p);
        assert!(hit.ng.abs_diff_eq(Vec3::Z, 1e-6), "{}", hit.ng);
    }
}

const MATERIALS: &str = "[materials.white]\ntype = \"diffuse\"\nalbedo = 0.5\n";

#[test]
fn toml_shapes_naming_one_file_share_its_mesh() {
    let scene = format!(
        "{MATERIALS}
[[shape]]
type = \"mesh\"
file = \"square.obj\"
material = \"white\"

[[shape]]
type = \"mesh\"
file = \"./square.obj\"
material = \"white\"
transform = [{{ translate = [3, 0, 0] }}]
"
    );
    let desc = load(&[("scene.toml", &scene), ("square.obj", SQUARE_OBJ)]);
    assert_eq!(desc.shapes.len(), 2);
    assert!(Arc::ptr_eq(&mesh(&desc, 0), &mesh(&desc, 1)));
    check_built(
        &desc,
        2,
        2,
        4,
        &[Vec3::new(0.25, 0.5, 0.0), Vec3::new(3.75, 0.5, 0.0)],
    );
}

#[test]
fn toml_instances_place_one_mesh_after_its_transform() {
    let scene = format!(
        "{MATERIALS}
[[shape]]
type = \"mesh\"
file = \"square.obj\"
material = \"white\"
transform = [{{ scale = 2 }}]
instances = [
  [],
  [{{ translate = [5, 0, 0] }}],
  [{{ rotate = {{ axis = [0, 0, 1], angle = 90 }} }}, {{ translate = [0, 10, 0] }}],
]
"
    );
    let desc = load(&[("scene.toml", &scene), ("square.obj", SQUARE_OBJ)]);
    assert_eq!(desc.shapes.len(), 3);
    for i in 1..3 {
        assert!(Arc::ptr_eq(&mesh(&desc, 0), &mesh(&desc, i)));
    }
    // Each instance's steps come after the shape's own `transform`.
    let scale = Mat4::from_scale(Vec3::splat(2.0));
    assert_eq!(desc.shapes[0].transform, scale);
    assert!(desc.shapes[2].transform.abs_diff_eq(
        Mat4::from_translation(Vec3::new(0.0, 10.0, 0.0))
            * Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2)
            * scale,
        1e-6
    ));
    // The square [0,2]² placed at x + 5, and turned a quarter about z then up by 10.
    check_built(
        &desc,
        3,
        2,
        6,
        &[
            Vec3::new(1.5, 0.5, 0.0),
            Vec3::new(6.5, 1.5, 0.0),
            Vec3::new(-1.5, 11.0, 0.0),
        ],
    );

    // Inline meshes take `instances` too.
    let inline = format!(
        "{MATERIALS}
[[shape]]
type = \"mesh\"
positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
indices = [[0, 1, 2]]
material = \"white\"
instances = [[], [{{ translate = [0, 0, 1] }}]]
"
    );
    let desc = load(&[("scene.toml", &inline)]);
    assert!(Arc::ptr_eq(&mesh(&desc, 0), &mesh(&desc, 1)));
    check_built(&desc, 2, 1, 2, &[Vec3::new(0.2, 0.2, 1.0)]);
}

#[test]
fn documented_instancing_example_loads_and_builds() {
    let doc = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/scene-format.md");
    let doc = fs::read_to_string(doc).unwrap();
    let at = doc
        .find("#### Instancing")
        .expect("the doc has an instancing section");
    let start = at + doc[at..].find("```toml\n").unwrap() + 8;
    let example = &doc[start..start + doc[start..].find("```").unwrap()];
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
               property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
               end_header\n0 0 0\n100 0 0\n0 100 0\n3 0 1 2\n";
    let scene = format!("[materials.wood]\ntype = \"diffuse\"\nalbedo = 0.5\n\n{example}");
    let dir = tempfile::tempdir().unwrap();
    fs::create_dir(dir.path().join("meshes")).unwrap();
    fs::write(dir.path().join("meshes/chair.ply"), ply).unwrap();
    fs::write(dir.path().join("scene.toml"), scene).unwrap();
    let desc = load_scene(&dir.path().join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(desc.shapes.len(), 3);
    // The 100-unit triangle scaled to 1, then placed at x = 2.
    check_built(&desc, 3, 1, 3, &[Vec3::new(2.2, 0.2, 0.0)]);
}

#[test]
fn toml_instance_errors_are_located() {
    let shape = |extra: &str| {
        format!(
            "{MATERIALS}\n[[shape]]\ntype = \"mesh\"\nfile = \"square.obj\"\nmaterial = \"white\"\n{extra}\n"
        )
    };
    let e = load_err(&[
        ("scene.toml", &shape("instances = []")),
        ("square.obj", SQUARE_OBJ),
    ]);
    assert!(e.contains("scene.toml:9:13: `instances` is empty"), "{e}");
    let e = load_err(&[
        ("scene.toml", &shape("instances = [[{ shear = 1 }]]")),
        ("square.obj", SQUARE_OBJ),
    ]);
    assert!(e.starts_with("scene.toml:9:"), "{e}");
    assert!(e.contains("shear"), "{e}");
    // Only meshes are instanced.
    let sphere = format!(
        "{MATERIALS}\n[[shape]]\ntype = \"sphere\"\nmaterial = \"white\"\ninstances = [[]]\n"
    );
    let e = load_err(&[("scene.toml", &sphere)]);
    assert!(e.starts_with("scene.toml:"), "{e}");
    assert!(e.contains("instances"), "{e}");
}

fn mitsuba(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>")
}

#[test]
fn mitsuba_shapegroup_instances_share_the_group_meshes() {
    // The instance before its group: groups are read first.
    let xml = mitsuba(
        r#"<shape type="instance">
             <ref id="g"/>
             <transform name="to_world"><translate x="5"/></transform>
           </shape>
           <shape type="shapegroup" id="g">
             <shape type="obj">
               <string name="filename" value="square.obj"/>
               <transform name="to_world"><scale value="2"/></transform>
             </shape>
             <shape type="rectangle"/>
           </shape>
           <shape type="instance"><ref id="g"/></shape>"#,
    );
    let desc = load(&[("scene.xml", &xml), ("square.obj", SQUARE_OBJ)]);
    // Two instances of a group of two shapes; the group itself places nothing.
    assert_eq!(desc.shapes.len(), 4);
    assert!(Arc::ptr_eq(&mesh(&desc, 0), &mesh(&desc, 2)));
    assert!(matches!(desc.shapes[1].geometry, GeometryDesc::Rectangle));
    let scale = Mat4::from_scale(Vec3::splat(2.0));
    assert!(desc.shapes[0]
        .transform
        .abs_diff_eq(Mat4::from_translation(Vec3::X * 5.0) * scale, 1e-6));
    assert_eq!(desc.shapes[2].transform, scale);
    // The obj is instanced (stored once); the rectangles stay flattened (2 triangles each).
    check_built(
        &desc,
        2,
        2 + 2 * 2,
        2 * 2 + 2 * 2,
        &[Vec3::new(6.5, 1.5, 0.0), Vec3::new(1.5, 1.5, 0.0)],
    );
}

#[test]
fn mitsuba_shapes_naming_one_file_share_its_mesh() {
    let xml = mitsuba(
        r#"<shape type="obj"><string name="filename" value="square.obj"/></shape>
           <shape type="obj"><string name="filename" value="square.obj"/>
             <transform name="to_world"><translate z="1"/></transform></shape>
           <shape type="obj"><string name="filename" value="square.obj"/>
             <boolean name="face_normals" value="true"/></shape>"#,
    );
    let desc = load(&[("scene.xml", &xml), ("square.obj", SQUARE_OBJ)]);
    assert!(Arc::ptr_eq(&mesh(&desc, 0), &mesh(&desc, 1)));
    // Loaded differently, so a mesh of its own.
    assert!(!Arc::ptr_eq(&mesh(&desc, 0), &mesh(&desc, 2)));
    check_built(&desc, 2, 2 + 2, 6, &[Vec3::new(0.5, 0.7, 1.0)]);
}

#[test]
fn mitsuba_instance_errors_are_located() {
    let cases = [
        (
            r#"<shape type="instance"><ref id="nope"/></shape>"#,
            "scene.xml:2:24: no <shape type=\"shapegroup\"> has the id \"nope\"",
        ),
        (
            r#"<shape type="instance"/>"#,
            "scene.xml:2:1: an instance needs a <ref id> to a shapegroup",
        ),
        (
            r#"<shape type="shapegroup"><shape type="cube"/></shape>"#,
            "scene.xml:2:1: <shape> lacks the attribute \"id\"",
        ),
        (
            r#"<shape type="shapegroup" id="g"><shape type="cube">
                 <emitter type="area"/></shape></shape>"#,
            "scene.xml:3:18: a shape in a shapegroup cannot emit",
        ),
        (
            r#"<shape type="shapegroup" id="g"><shape type="instance"><ref id="g"/></shape></shape>"#,
            "scene.xml:2:33: a shapegroup cannot hold a",
        ),
        (
            r#"<shape type="shapegroup" id="g"><shape type="cube"/></shape>
               <shape type="shapegroup" id="g"><shape type="cube"/></shape>"#,
            "scene.xml:3:16: id \"g\" is used twice",
        ),
    ];
    for (body, want) in cases {
        let e = load_err(&[("scene.xml", &mitsuba(body))]);
        assert!(e.starts_with(want), "{body}\n  gave {e}\n  want {want}");
    }
}

#[test]
fn gltf_nodes_sharing_a_mesh_become_instances() {
    let mut g = Glb::new();
    let mat = g.material(json!({"name": "m"}));
    let quad = g.quad(mat);
    let m = g.mesh(vec![quad]);
    for x in [0.0, 4.0, 8.0] {
        g.node(json!({"mesh": m, "translation": [x, 0.0, 0.0]}), true);
    }
    let loaded = parse_gltf(
        &g.bytes(),
        Path::new("t.glb"),
        None,
        &LoadOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let desc = loaded.desc;
    assert_eq!(desc.shapes.len(), 3);
    assert!(Arc::ptr_eq(&mesh(&desc, 0), &mesh(&desc, 2)));
    check_built(
        &desc,
        3,
        2,
        6,
        &[
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(3.5, -0.5, 0.0),
            Vec3::new(8.9, 0.9, 0.0),
        ],
    );
}

#[test]
fn gallery_scene_stores_its_knot_once() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/instances.toml");
    let desc = load_scene(Path::new(path)).unwrap_or_else(|e| panic!("{e}"));
    let scene = candela_core::build::build(&desc).unwrap_or_else(|e| panic!("{e}"));
    let knot = scene.instances.meshes[0].indices.len();
    assert_eq!(knot, 12288);
    assert_eq!(scene.instances.instances.len(), 400);
    assert_eq!(scene.instances.meshes.len(), 1);
    // The floor and the light are rectangles, flattened.
    assert_eq!(scene.stored_triangle_count(), knot + 4);
    assert_eq!(scene.triangle_count(), 400 * knot + 4);
}
