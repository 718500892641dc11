//! A bare `.obj` or `.ply` file as a scene: its faces split by MTL material, diffuse
//! colours, textures and emission carried over, what is left out named in a warning, a
//! PLY's vertex colours, and the automatic camera and sky of a model without its own.

use candela_core::desc::{BsdfDesc, GeometryDesc, SceneDesc, TextureDesc};
use candela_scene::{LoadOptions, LoadedScene};
use candela_test_support::files::load_files;
use glam::Vec3;

/// Writes `files` into a fresh folder and loads the first as a scene.
fn load(files: &[(&str, &[u8])]) -> Result<LoadedScene, String> {
    let (_dir, r) = load_files(files, &LoadOptions::default());
    r.map_err(|e| e.to_string())
}

fn albedo<'a>(desc: &'a SceneDesc, material: &str) -> &'a TextureDesc {
    let m = desc.materials.iter().find(|m| m.name == material);
    match m.map(|m| &m.bsdf) {
        Some(BsdfDesc::Diffuse { albedo }) => albedo,
        other => panic!("{material}: {other:?}"),
    }
}

/// Two quads side by side and a triangle above them, in three materials.
const OBJ: &str = "mtllib m.mtl
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nv 0 3 0\nv 1 3 0\nv 0.5 4 0
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1
f 7 8 9
usemtl red
f 1/1 2/2 3/3 4/4
usemtl lamp
f 2/1 5/2 6/3 3/4
";

const MTL: &str = "newmtl red
Kd 0.8 0.1 0.1
Ks 0.5 0.5 0.5
Ns 50
newmtl lamp
Kd 0 0 0
Ke 4 3 2
map_Kd maps\\tex.png
";

fn png() -> Vec<u8> {
    let img = image::RgbImage::from_pixel(2, 2, image::Rgb([255, 255, 255]));
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

#[test]
fn an_obj_with_materials_renders_as_its_own_scene() {
    let png = png();
    let loaded = load(&[
        ("model.obj", OBJ.as_bytes()),
        ("m.mtl", MTL.as_bytes()),
        ("maps/tex.png", &png),
    ])
    .unwrap();
    let d = &loaded.desc;
    // One shape per material: faces without one are grey.
    assert_eq!(d.shapes.len(), 3, "{:?}", d.shapes);
    let by_material = |name: &str| d.shapes.iter().find(|s| s.material == name).unwrap();
    let tris = |name: &str| match &by_material(name).geometry {
        GeometryDesc::Mesh(m) => m.indices.len(),
        g => panic!("{g:?}"),
    };
    assert_eq!(
        (tris("(no material)"), tris("red"), tris("lamp")),
        (1, 2, 2)
    );
    assert!(
        matches!(albedo(d, "(no material)"), TextureDesc::Constant(c) if *c == Vec3::splat(0.5))
    );
    assert!(matches!(albedo(d, "red"), TextureDesc::Constant(c) if *c == Vec3::new(0.8, 0.1, 0.1)));
    // map_Kd wins over Kd, found through a Windows path, decoded from sRGB (white stays 1).
    match albedo(d, "lamp") {
        TextureDesc::Image(t) => assert_eq!(t.image.pixels[0], Vec3::ONE),
        t => panic!("{t:?}"),
    }
    assert_eq!(by_material("lamp").emission, Some(Vec3::new(4.0, 3.0, 2.0)));
    assert_eq!(by_material("red").emission, None);
    // It emits, so no sky is added; Ks is named as left out.
    assert!(d.environment.is_none());
    let w = loaded.warnings.join("\n");
    assert!(w.contains("Ks") && w.contains("ignored"), "{w}");
    // The automatic camera looks at the middle of the model's bounds, (1, 2, 0).
    let c = &d.camera;
    let to_center = (Vec3::new(1.0, 2.0, 0.0) - c.position).normalize();
    assert!(to_center.dot((c.look_at - c.position).normalize()) > 0.9999);
    assert!(candela_core::build::build(d).is_ok());
}

#[test]
fn a_missing_mtl_file_leaves_grey_faces_and_a_warning() {
    let loaded = load(&[("model.obj", OBJ.as_bytes())]).unwrap();
    let d = &loaded.desc;
    assert_eq!(d.shapes.len(), 1);
    assert!(
        matches!(albedo(d, "(no material)"), TextureDesc::Constant(c) if *c == Vec3::splat(0.5))
    );
    let w = loaded.warnings.join("\n");
    assert!(
        w.contains("model.obj: materials not read") && w.contains("white environment"),
        "{w}"
    );
    assert!(d.environment.is_some());
}

#[test]
fn a_ply_renders_grey_under_the_default_sky() {
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
               property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
               end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let loaded = load(&[("tri.ply", ply.as_bytes())]).unwrap();
    assert_eq!(loaded.desc.shapes.len(), 1);
    assert!(loaded.desc.environment.is_some());
    assert!(candela_core::build::build(&loaded.desc).is_ok());
}

/// A triangle with one red, one green and one blue vertex (8-bit).
const COLOURED_PLY: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
    property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n\
    property uchar blue\nelement face 1\nproperty list uchar int vertex_indices\n\
    end_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n";

fn mesh_colors(desc: &SceneDesc) -> &[Vec3] {
    match &desc.shapes[0].geometry {
        GeometryDesc::Mesh(m) => &m.colors,
        g => panic!("{g:?}"),
    }
}

#[test]
fn a_plys_vertex_colours_are_its_colour_except_in_mitsuba_scenes() {
    // Alone, the colours are the albedo (times 1).
    let loaded = load(&[("tri.ply", COLOURED_PLY.as_bytes())]).unwrap();
    let d = &loaded.desc;
    assert_eq!(mesh_colors(d), [Vec3::X, Vec3::Y, Vec3::Z]);
    assert!(matches!(albedo(d, "(no material)"), TextureDesc::Constant(c) if *c == Vec3::ONE));
    // In a TOML scene they multiply the scene's material.
    let toml = "[materials.m]\ntype = \"diffuse\"\n[[shape]]\ntype = \"mesh\"\n\
                file = \"tri.ply\"\nmaterial = \"m\"\n";
    let loaded = load(&[
        ("scene.toml", toml.as_bytes()),
        ("tri.ply", COLOURED_PLY.as_bytes()),
    ])
    .unwrap();
    assert_eq!(mesh_colors(&loaded.desc).len(), 3);
    // Mitsuba does not tint a BSDF by them, so neither does its importer.
    let xml = r#"<scene version="3.0.0"><shape type="ply"><string name="filename" value="tri.ply"/></shape></scene>"#;
    let loaded = load(&[
        ("scene.xml", xml.as_bytes()),
        ("tri.ply", COLOURED_PLY.as_bytes()),
    ])
    .unwrap();
    assert!(mesh_colors(&loaded.desc).is_empty());
}

#[test]
fn broken_mesh_scenes_are_located_errors() {
    let e = load(&[("bad.obj", b"v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n")]).unwrap_err();
    assert!(e.contains("bad.obj:3"), "{e}");
    let e = load(&[("empty.obj", b"v 0 0 0\n")]).unwrap_err();
    assert!(e.contains("empty.obj") && e.contains("no faces"), "{e}");
    let e = load(&[("bad.ply", b"ply\nformat ascii 1.0\nend_header\n")]).unwrap_err();
    assert!(e.contains("bad.ply") && e.contains("vertex"), "{e}");
    // A texture that is not there names itself.
    let e = load(&[("model.obj", OBJ.as_bytes()), ("m.mtl", MTL.as_bytes())]).unwrap_err();
    assert!(e.contains("tex.png"), "{e}");
}
