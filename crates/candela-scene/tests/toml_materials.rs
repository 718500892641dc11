//! The TOML keys of the material types and their textures, and their errors.

use std::path::Path;

use candela_core::desc::{BsdfDesc, MicrofacetDesc, TextureDesc, WrapMode};
use candela_scene::parse_toml_scene;
use glam::{Vec2, Vec3};

fn material(body: &str) -> Result<BsdfDesc, String> {
    material_in(Path::new("scene.toml"), body)
}

fn material_in(file: &Path, body: &str) -> Result<BsdfDesc, String> {
    let text = format!("[materials.m]\n{body}\n");
    parse_toml_scene(&text, file)
        .map(|d| d.materials[0].bsdf.clone())
        .map_err(|e| e.to_string())
}

#[test]
fn every_material_type_parses() {
    let BsdfDesc::Conductor {
        eta,
        k,
        alpha_u,
        alpha_v,
        ..
    } = material("type = \"conductor\"\npreset = \"Au\"\nalpha_u = 0.1\nalpha_v = 0.3").unwrap()
    else {
        panic!()
    };
    let (au_eta, au_k) = candela_core::desc::metal_preset("Au").unwrap();
    assert_eq!((eta, k, alpha_u, alpha_v), (au_eta, au_k, 0.1, 0.3));
    let BsdfDesc::Conductor { eta, alpha_u, .. } =
        material("type = \"conductor\"\neta = [0.2, 0.9, 1.1]\nk = 3\nalpha = 0.05").unwrap()
    else {
        panic!()
    };
    assert_eq!((eta, alpha_u), (Vec3::new(0.2, 0.9, 1.1), 0.05));
    assert!(matches!(
        material("type = \"dielectric\"\neta = 1.33\nthin = true").unwrap(),
        BsdfDesc::Dielectric { eta, thin: true, alpha_u, .. } if eta == 1.33 && alpha_u == 0.0
    ));
    assert!(matches!(
        material("type = \"plastic\"\nalbedo = [0.1, 0.2, 0.3]").unwrap(),
        BsdfDesc::Plastic { eta, albedo: TextureDesc::Constant(c), alpha, linear: false, .. }
            if eta == 1.5 && c == Vec3::new(0.1, 0.2, 0.3) && alpha == 0.0
    ));
    assert!(matches!(
        material("type = \"plastic\"\nalpha = 0.2\ndistribution = \"beckmann\"").unwrap(),
        BsdfDesc::Plastic { alpha, distribution: MicrofacetDesc::Beckmann, specular, .. }
            if alpha == 0.2 && specular == Vec3::ONE
    ));
    assert!(matches!(
        material("type = \"plastic\"\nspecular = [0.9, 0.7, 0.2]").unwrap(),
        BsdfDesc::Plastic { specular, .. } if specular == Vec3::new(0.9, 0.7, 0.2)
    ));
    assert!(matches!(
        material("type = \"metal_rough\"\nbase_color = 0.9\nmetallic = 1\nroughness = 0.4\ntwo_sided = true").unwrap(),
        BsdfDesc::TwoSided(inner) if matches!(*inner, BsdfDesc::MetalRough { .. })
    ));
}

#[test]
fn textures_parse_and_load_with_the_right_encoding() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([128, 128, 128]))
        .save(dir.path().join("grey.png"))
        .unwrap();
    let file = dir.path().join("scene.toml");
    let body = "type = \"metal_rough\"\n\
        base_color = { type = \"image\", file = \"grey.png\", wrap = \"mirror\", uv_scale = [2, 3], uv_offset = [0.5, 0], scale = 0.5 }\n\
        roughness = { type = \"image\", file = \"grey.png\", channel = 1 }\n\
        metallic = { type = \"image\", file = \"grey.png\", gamma = 2.2 }\n\
        normal_map = { type = \"image\", file = \"grey.png\" }";
    let BsdfDesc::NormalMap { map, inner } = material_in(&file, body).unwrap() else {
        panic!()
    };
    let TextureDesc::Image(n) = map else { panic!() };
    assert!(
        (n.image.pixels[0].x - 128.0 / 255.0).abs() < 1e-6,
        "normal maps are linear data"
    );
    let BsdfDesc::MetalRough {
        base_color,
        metallic,
        roughness,
    } = *inner
    else {
        panic!()
    };
    let TextureDesc::Image(b) = base_color else {
        panic!()
    };
    assert!(
        (b.image.pixels[0].x - 0.2158).abs() < 1e-4,
        "colour is sRGB-decoded"
    );
    assert_eq!((b.wrap, b.scale), (WrapMode::Mirror, Vec3::splat(0.5)));
    assert_eq!(
        b.uv_transform.transform_point2(Vec2::new(1.0, 1.0)),
        Vec2::new(2.5, 3.0)
    );
    let TextureDesc::Image(r) = roughness else {
        panic!()
    };
    assert_eq!(r.channel, Some(1));
    assert!(
        (r.image.pixels[0].x - 128.0 / 255.0).abs() < 1e-6,
        "roughness is linear"
    );
    let TextureDesc::Image(m) = metallic else {
        panic!()
    };
    assert!((m.image.pixels[0].x - (128.0f32 / 255.0).powf(2.2)).abs() < 1e-6);

    let TextureDesc::Checker { a, b, uv_transform } = (match material(
        "type = \"diffuse\"\nalbedo = { type = \"checker\", a = 1, b = [0, 0, 1], uv_scale = [8, 8] }",
    )
    .unwrap()
    {
        BsdfDesc::Diffuse { albedo } => albedo,
        _ => panic!(),
    }) else {
        panic!()
    };
    assert_eq!((a, b), (Vec3::ONE, Vec3::Z));
    assert_eq!(uv_transform.transform_point2(Vec2::ONE), Vec2::splat(8.0));
}

#[test]
fn errors_point_at_the_key() {
    let cases = [
        ("type = \"diffuse\"\nalpha = 0.1", "scene.toml:3:1: unknown key `alpha` for a diffuse material"),
        ("type = \"conductor\"\npreset = \"Unobtainium\"", "scene.toml:3:10: unknown metal preset"),
        ("type = \"conductor\"\neta = 1", "a conductor takes either `preset` or both `eta` and `k`"),
        ("type = \"dielectric\"\neta = [1, 2, 3]", "scene.toml:3:7: a dielectric's `eta` is one number"),
        ("type = \"dielectric\"\neta = -1", "must be positive"),
        ("type = \"wood\"", "scene.toml:2:8"),
        ("type = \"diffuse\"\nalbedo = { type = \"image\" }", "scene.toml:3:10: an image texture needs `file`"),
        ("type = \"diffuse\"\nalbedo = { type = \"image\", file = \"missing.png\" }", "missing.png: cannot read image"),
        ("type = \"diffuse\"\nalbedo = { type = \"image\", file = \"a.png\", wrap = \"around\" }", "scene.toml:3:"),
        ("type = \"diffuse\"\nalbedo = { type = \"checker\", file = \"a.png\" }", "does not belong"),
        ("type = \"diffuse\"\nalbedo = { type = \"checker\", colour = 1 }", "unknown field `colour`"),
        ("type = \"diffuse\"\nalbedo = \"red\"", "scene.toml:3:10"),
        (
            "type = \"conductor\"\nalpha = 0.2\ndistribution = \"phong\"",
            "scene.toml:4:16: unknown variant `phong`, expected `ggx` or `beckmann`",
        ),
        ("type = \"plastic\"\nalpha_u = 0.2", "scene.toml:3:1: unknown key `alpha_u`"),
    ];
    for (body, want) in cases {
        let e = material(body).unwrap_err();
        assert!(e.contains(want), "{body:?}: got {e:?}, want {want:?}");
    }
}

/// `distribution` selects the microfacets of conductors and dielectrics, GGX by default.
#[test]
fn distribution_defaults_to_ggx() {
    let distribution = |body: &str| match material(body).unwrap() {
        BsdfDesc::Conductor { distribution, .. } | BsdfDesc::Dielectric { distribution, .. } => {
            distribution
        }
        other => panic!("{other:?}"),
    };
    for (body, want) in [
        ("type = \"conductor\"\nalpha = 0.2", MicrofacetDesc::Ggx),
        (
            "type = \"conductor\"\nalpha = 0.2\ndistribution = \"ggx\"",
            MicrofacetDesc::Ggx,
        ),
        (
            "type = \"conductor\"\nalpha = 0.2\ndistribution = \"beckmann\"",
            MicrofacetDesc::Beckmann,
        ),
        ("type = \"dielectric\"\nalpha = 0.1", MicrofacetDesc::Ggx),
        (
            "type = \"dielectric\"\nalpha_u = 0.1\nalpha_v = 0.3\ndistribution = \"beckmann\"",
            MicrofacetDesc::Beckmann,
        ),
    ] {
        assert_eq!(distribution(body), want, "{body:?}");
    }
}

#[test]
fn built_scene_rejects_bad_numbers() {
    let text = "[materials.m]\ntype = \"conductor\"\npreset = \"Cu\"\nalpha = -0.5\n\
                [[shape]]\ntype = \"sphere\"\nmaterial = \"m\"\n";
    let desc = parse_toml_scene(text, Path::new("s.toml")).unwrap();
    let e = candela_core::build::build(&desc).unwrap_err().to_string();
    assert!(
        e.starts_with("s.toml:1:") && e.contains("roughness must not be negative"),
        "{e}"
    );
}

#[test]
fn a_mix_names_two_materials_defined_anywhere_in_the_table() {
    // The mix comes before the materials it names, and one side is itself a mix.
    let text = r#"
[materials.worn]
type = "mix"
materials = ["paint", "patina"]
weight = { type = "checker", a = 0.25, b = 0.75 }
normal_map = [0.5, 0.5, 1]

[materials.paint]
type = "plastic"
albedo = [0.8, 0.1, 0.1]

[materials.patina]
type = "mix"
materials = ["gold", "rust"]
weight = 0.5

[materials.gold]
type = "conductor"
preset = "Au"

[materials.rust]
type = "diffuse"
albedo = [0.3, 0.1, 0.05]
"#;
    let desc = parse_toml_scene(text, Path::new("scene.toml")).unwrap();
    let worn = &desc
        .materials
        .iter()
        .find(|m| m.name == "worn")
        .unwrap()
        .bsdf;
    let BsdfDesc::NormalMap { inner, .. } = worn else {
        panic!("{worn:?}")
    };
    let BsdfDesc::Mix { weight, a, b } = inner.as_ref() else {
        panic!("{inner:?}")
    };
    assert!(matches!(weight, TextureDesc::Checker { a, b, .. }
        if *a == Vec3::splat(0.25) && *b == Vec3::splat(0.75)));
    assert!(matches!(a.as_ref(), BsdfDesc::Plastic { .. }), "{a:?}");
    let BsdfDesc::Mix { weight, a, b } = b.as_ref() else {
        panic!("{b:?}")
    };
    assert!(matches!(weight, TextureDesc::Constant(c) if *c == Vec3::splat(0.5)));
    assert!(matches!(a.as_ref(), BsdfDesc::Conductor { .. }), "{a:?}");
    assert!(matches!(b.as_ref(), BsdfDesc::Diffuse { .. }), "{b:?}");
    candela_core::build::build(&desc).expect("the mixes build");
}

#[test]
fn a_mix_without_its_materials_or_weight_or_in_a_loop_is_an_error_at_its_place() {
    let cases = [
        (
            "[materials.m]\ntype = \"mix\"\nweight = 0.5\n",
            "scene.toml:1:1: a mix needs `materials",
        ),
        (
            "[materials.m]\ntype = \"mix\"\nmaterials = [\"a\"]\nweight = 0.5\n",
            "scene.toml:3:13: a mix takes 2 materials, not 1",
        ),
        (
            "[materials.a]\ntype = \"diffuse\"\n[materials.m]\ntype = \"mix\"\nmaterials = [\"a\", \"a\"]\n",
            "scene.toml:3:1: a mix needs a `weight`",
        ),
        (
            "[materials.a]\ntype = \"diffuse\"\n[materials.m]\ntype = \"mix\"\nmaterials = [\"a\", \"b\"]\nweight = 1\n",
            "scene.toml:5:19: unknown material \"b\" in a mix",
        ),
        (
            "[materials.m]\ntype = \"mix\"\nmaterials = [\"n\", \"n\"]\nweight = 1\n\
             [materials.n]\ntype = \"mix\"\nmaterials = [\"m\", \"m\"]\nweight = 0\n",
            "scene.toml:7:14: material \"m\" mixes itself",
        ),
        (
            "[materials.m]\ntype = \"mix\"\nmaterials = [\"m\", \"m\"]\nweight = 1\n",
            "scene.toml:3:14: material \"m\" mixes itself",
        ),
        (
            "[materials.m]\ntype = \"mix\"\nalbedo = 0.5\n",
            "scene.toml:3:1: unknown key `albedo` for a mix material",
        ),
    ];
    // A chain of 20 mixes, each naming the next.
    let chain: String = (0..20)
        .map(|i| format!("[materials.m{i:02}]\ntype = \"mix\"\nmaterials = [\"m{:02}\", \"d\"]\nweight = 0.5\n", i + 1))
        .chain(["[materials.m20]\ntype = \"diffuse\"\n[materials.d]\ntype = \"diffuse\"\n".into()])
        .collect();
    let e = parse_toml_scene(&chain, Path::new("scene.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("mixes nest more than 16 deep here"), "{e}");
    for (text, expected) in cases {
        let e = parse_toml_scene(text, Path::new("scene.toml"))
            .unwrap_err()
            .to_string();
        eprintln!("{e}");
        assert!(e.starts_with(expected), "{text}\n→ {e}");
    }
}
