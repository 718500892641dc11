//! Scenes that load: every key of the format lands in the right field of the description,
//! the documented example stays valid, and the project's Cornell box builds.

use std::fs;
use std::path::Path;

use candela_core::desc::{
    BsdfDesc, GeometryDesc, LightKindDesc, LightSamplerKind, MisMode, SamplerKind, SceneDesc, Span,
    TextureDesc,
};
use candela_core::light::Light;
use candela_scene::{load_scene, parse_toml_scene};
use glam::{Mat4, Vec3};

fn parse(text: &str) -> SceneDesc {
    parse_toml_scene(text, Path::new("scene.toml")).unwrap_or_else(|e| panic!("{e}"))
}

const TRIANGLE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n";

#[test]
fn documented_example_loads_and_builds() {
    let doc = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/scene-format.md");
    let doc = fs::read_to_string(doc).unwrap();
    let start = doc.find("```toml\n").expect("the doc has a toml example") + 8;
    let example = &doc[start..start + doc[start..].find("```").unwrap()];

    let dir = tempfile::tempdir().unwrap();
    fs::create_dir(dir.path().join("meshes")).unwrap();
    fs::write(dir.path().join("meshes/bunny.obj"), TRIANGLE_OBJ).unwrap();
    let scene = dir.path().join("scene.toml");
    fs::write(&scene, example).unwrap();
    let desc = load_scene(&scene).unwrap_or_else(|e| panic!("{e}"));

    assert_eq!((desc.render.width, desc.render.height), (640, 480));
    assert_eq!(desc.materials.len(), 2);
    assert_eq!(desc.shapes.len(), 6);
    assert_eq!(desc.lights.len(), 1);
    assert_eq!(
        desc.shapes.iter().filter(|s| s.emission.is_some()).count(),
        1
    );
    let scene = candela_core::build::build(&desc).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.spheres.len(), 1);
}

#[test]
fn render_settings_and_camera() {
    let desc = parse(
        "[render]\nresolution = [32, 16]\nspp = 3\nmax_depth = 0\nrr_depth = 2\nseed = 99\n\
         mis = \"none\"\nlight_sampler = \"uniform\"\n\n[camera]\ntype = \"pinhole\"\n\
         position = [1, 2, 3]\nlook_at = [0, 2, 0]\nup = [0, 0, 1]\nfov = 25.5\n",
    );
    let r = &desc.render;
    assert_eq!(
        (r.width, r.height, r.spp, r.max_depth, r.rr_depth, r.seed),
        (32, 16, 3, 0, 2, 99)
    );
    assert_eq!(r.mis, MisMode::NeeOnly);
    assert_eq!(r.light_sampler, LightSamplerKind::Uniform);
    let c = &desc.camera;
    assert_eq!(c.position, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(c.look_at, Vec3::new(0.0, 2.0, 0.0));
    assert_eq!(c.up, Vec3::Z);
    assert_eq!(c.fov_y_deg, 25.5);
    assert_eq!(c.span, Span::new("scene.toml", 10, 2));

    for (name, mode) in [
        ("balance", MisMode::Balance),
        ("power", MisMode::Power),
        ("bsdf", MisMode::BsdfOnly),
    ] {
        assert_eq!(
            parse(&format!("[render]\nmis = \"{name}\"")).render.mis,
            mode
        );
    }
    for (name, kind) in [
        ("independent", SamplerKind::Independent),
        ("sobol", SamplerKind::Sobol),
        ("sobol-cmj", SamplerKind::SobolCmj),
        ("zsobol", SamplerKind::Zsobol),
    ] {
        let r = parse(&format!("[render]\nsampler = \"{name}\"")).render;
        assert_eq!(r.sampler, kind);
    }
    let bad = parse_toml_scene("[render]\nsampler = \"halton\"\n", Path::new("scene.toml"));
    assert_eq!(
        bad.unwrap_err().to_string(),
        "scene.toml:2:11: unknown variant `halton`, expected one of `independent`, `sobol`, `sobol-cmj`, `zsobol`"
    );
    // Defaults when the sections are absent.
    let d = parse("");
    assert_eq!(
        (
            d.render.width,
            d.render.spp,
            d.render.max_depth,
            d.render.rr_depth
        ),
        (512, 64, 8, 5)
    );
    assert_eq!(d.camera.fov_y_deg, 40.0);
}

#[test]
fn materials_lights_and_primitives() {
    let desc = parse(
        "[materials.grey]\ntype = \"diffuse\"\nalbedo = 0.25\n\n\
         [materials.red]\ntype = \"diffuse\"\nalbedo = [0.5, 0, 0]\n\n\
         [[shape]]\ntype = \"sphere\"\ncenter = [1, 2, 3]\nradius = 0.5\nmaterial = \"red\"\n\
         emission = 4\nflip_normals = true\n\n\
         [[shape]]\ntype = \"disk\"\nmaterial = \"grey\"\n\n\
         [[shape]]\ntype = \"rectangle\"\nmaterial = \"grey\"\n\n\
         [[shape]]\ntype = \"cube\"\nmaterial = \"grey\"\n\n\
         [[light]]\ntype = \"point\"\nposition = [0, 5, 0]\nintensity = 7\n",
    );
    let albedo = |name: &str| {
        let m = desc.materials.iter().find(|m| m.name == name).unwrap();
        let BsdfDesc::Diffuse {
            albedo: TextureDesc::Constant(c),
        } = m.bsdf
        else {
            panic!("{name} is not a constant diffuse");
        };
        c
    };
    assert_eq!(albedo("grey"), Vec3::splat(0.25));
    assert_eq!(albedo("red"), Vec3::new(0.5, 0.0, 0.0));

    let s = &desc.shapes[0];
    assert!(matches!(
        s.geometry,
        GeometryDesc::Sphere { center, radius } if center == Vec3::new(1.0, 2.0, 3.0) && radius == 0.5
    ));
    assert_eq!(s.emission, Some(Vec3::splat(4.0)));
    assert!(s.flip_normals);
    assert_eq!(s.span, Span::new("scene.toml", 9, 1));
    assert!(matches!(desc.shapes[1].geometry, GeometryDesc::Disk));
    assert!(matches!(desc.shapes[2].geometry, GeometryDesc::Rectangle));
    assert!(matches!(desc.shapes[3].geometry, GeometryDesc::Cube));
    assert_eq!(desc.shapes[3].span, Span::new("scene.toml", 25, 1));
    assert!(desc.shapes[1..]
        .iter()
        .all(|s| s.emission.is_none() && !s.flip_normals));

    let l = &desc.lights[0];
    let LightKindDesc::Point {
        position,
        intensity,
    } = l.kind
    else {
        panic!("expected a point light, got {:?}", l.kind);
    };
    assert_eq!((position, intensity), (Vec3::Y * 5.0, Vec3::splat(7.0)));
    assert_eq!(l.span, Span::new("scene.toml", 29, 1));
    candela_core::build::build(&desc).unwrap();
}

fn transform_of(steps: &str) -> Mat4 {
    parse(&format!(
        "[[shape]]\ntype = \"cube\"\nmaterial = \"w\"\ntransform = [{steps}]\n"
    ))
    .shapes[0]
        .transform
}

#[test]
fn transforms_apply_in_the_listed_order() {
    let m = transform_of("{ scale = 2 }, { translate = [1, 0, 0] }");
    assert_eq!(m.transform_point3(Vec3::X), Vec3::new(3.0, 0.0, 0.0));
    let m = transform_of("{ translate = [1, 0, 0] }, { scale = 2 }");
    assert_eq!(m.transform_point3(Vec3::X), Vec3::new(4.0, 0.0, 0.0));
    let m = transform_of("{ scale = [1, 2, 3] }");
    assert_eq!(m.transform_point3(Vec3::ONE), Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(transform_of(""), Mat4::IDENTITY);
}

#[test]
fn rotation_is_right_handed_in_degrees() {
    // +90° about +y takes +x to −z and +z to +x.
    let m = transform_of("{ rotate = { axis = [0, 3, 0], angle = 90 } }");
    assert!(m.transform_vector3(Vec3::X).abs_diff_eq(-Vec3::Z, 1e-6));
    assert!(m.transform_vector3(Vec3::Z).abs_diff_eq(Vec3::X, 1e-6));
}

#[test]
fn matrix_is_row_major() {
    let m = transform_of("{ matrix = [1, 0, 0, 5,  0, 1, 0, 6,  0, 0, 1, 7,  0, 0, 0, 1] }");
    assert_eq!(m.transform_point3(Vec3::ZERO), Vec3::new(5.0, 6.0, 7.0));
    let m = transform_of("{ matrix = [0, -1, 0, 0,  1, 0, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1] }");
    assert_eq!(m.transform_vector3(Vec3::X), Vec3::Y);
}

#[test]
fn look_at_aims_the_objects_z_axis() {
    let m =
        transform_of("{ look_at = { origin = [0, 2, 0], target = [0, 0, 0], up = [0, 0, 1] } }");
    assert!(m
        .transform_point3(Vec3::ZERO)
        .abs_diff_eq(Vec3::Y * 2.0, 1e-6));
    assert!(m.transform_vector3(Vec3::Z).abs_diff_eq(-Vec3::Y, 1e-6));
    assert!(m.transform_vector3(Vec3::Y).abs_diff_eq(Vec3::Z, 1e-6));
    assert!((m.determinant() - 1.0).abs() < 1e-5);
}

#[test]
fn inline_and_file_meshes() {
    let dir = tempfile::tempdir().unwrap();
    fs::create_dir(dir.path().join("meshes")).unwrap();
    fs::write(dir.path().join("meshes/tri.obj"), TRIANGLE_OBJ).unwrap();
    fs::write(
        dir.path().join("meshes/quad.ply"),
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_index\nend_header\n\
         0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",
    )
    .unwrap();
    let scene = dir.path().join("scene.toml");
    fs::write(
        &scene,
        "[materials.w]\ntype = \"diffuse\"\n\n\
         [[shape]]\ntype = \"mesh\"\nfile = \"meshes/tri.obj\"\nmaterial = \"w\"\n\n\
         [[shape]]\ntype = \"mesh\"\nfile = \"meshes/quad.ply\"\nmaterial = \"w\"\n\
         emission = [1, 2, 3]\n\n\
         [[shape]]\ntype = \"mesh\"\nmaterial = \"w\"\n\
         positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 2]]\n\
         normals = [[0, 0, 1], [0, 0, 1], [0, 0, 1]]\nuvs = [[0, 0], [1, 0], [0, 1]]\n",
    )
    .unwrap();
    let desc = load_scene(&scene).unwrap_or_else(|e| panic!("{e}"));
    let mesh = |i: usize| match &desc.shapes[i].geometry {
        GeometryDesc::Mesh(m) => m.clone(),
        _ => panic!("shape {i} is not a mesh"),
    };
    assert_eq!(mesh(0).indices.len(), 1);
    assert_eq!(mesh(0).normals, vec![Vec3::Z; 3]);
    assert_eq!(mesh(1).indices, vec![[0, 1, 2], [0, 2, 3]]);
    let inline = mesh(2);
    assert_eq!(inline.positions[1], Vec3::X);
    assert_eq!(inline.uvs[2], glam::Vec2::Y);
    assert_eq!(inline.normals.len(), 3);
    let file = scene.display().to_string();
    assert_eq!(desc.shapes[1].span, Span::new(file.as_str(), 9, 1));

    let built = candela_core::build::build(&desc).unwrap();
    // The quad's two triangles emit, as one parallelogram light.
    assert_eq!(built.lights.len(), 1);
    assert!(matches!(built.lights[0], Light::Parallelogram(_)));
}

#[test]
fn cornell_box() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/cornell.toml"
    ));
    let desc = load_scene(path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(desc.shapes.len(), 8);
    assert_eq!(desc.materials.len(), 3);
    assert_eq!(
        desc.shapes.iter().filter(|s| s.emission.is_some()).count(),
        1
    );
    assert_eq!(desc.camera.fov_y_deg, 39.3077);
    let scene = candela_core::build::build(&desc).unwrap_or_else(|e| panic!("{e}"));
    let triangles: usize = scene.meshes.iter().map(|m| m.indices.len()).sum();
    let emitting: usize = scene.meshes.iter().map(|m| m.lights.len()).sum();
    assert_eq!(triangles, 32);
    assert_eq!(emitting, 2);
    // The lamp's two triangles are one parallelogram light.
    assert_eq!(scene.lights.len(), 1);
}
