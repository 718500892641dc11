//! `[[light]]` types of the TOML format (point with units/colour/IES, spot, directional,
//! projector) and IES-shaped area lights: what they load into, that they build, and the
//! errors of bad input (`file:line:col: message`, never a panic).

use std::fs;
use std::path::{Path, PathBuf};

use candela_core::build::build;
use candela_core::desc::*;
use candela_core::light::{Light, LightSource};
use candela_scene::{load_scene, parse_toml_scene};
use glam::{Vec2, Vec3};

/// A tiny rotationally symmetric IES file (LM-63-2002): 100 cd at the nadir, 0 at 90°.
const IES: &str = "IESNA:LM-63-2002\n[TEST] t\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 10\n\
                   0 45 90\n0\n100 50 0\n";

/// A folder with `p.ies` and a 2 × 1 sRGB PNG `img.png` (128 grey, pure red).
fn assets() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("p.ies"), IES).unwrap();
    let img = image::RgbImage::from_fn(2, 1, |x, _| {
        if x == 0 {
            image::Rgb([128, 128, 128])
        } else {
            image::Rgb([255, 0, 0])
        }
    });
    img.save(dir.path().join("img.png")).unwrap();
    let scene = dir.path().join("scene.toml");
    (dir, scene)
}

const HEAD: &str = "[materials.white]\ntype = \"diffuse\"\n\n";

fn load(scene: &Path, text: &str) -> Result<SceneDesc, String> {
    parse_toml_scene(&format!("{HEAD}{text}"), scene).map_err(|e| e.to_string())
}

fn one_light(scene: &Path, text: &str) -> LightKindDesc {
    let desc = load(scene, text).unwrap();
    build(&desc).unwrap();
    desc.lights[0].kind.clone()
}

#[test]
fn point_lights_keep_the_plain_form_and_take_units_colour_and_ies() {
    let (_d, s) = assets();
    let k = one_light(
        &s,
        "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [1, 2, 3]\n",
    );
    assert!(
        matches!(k, LightKindDesc::Point { intensity, .. } if intensity == Vec3::new(1.0, 2.0, 3.0))
    );

    let k = one_light(
        &s,
        "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\npower = 1000\nunits = \"photometric\"\n\
         temperature = 3000\n",
    );
    let LightKindDesc::ShapedPoint(p) = k else {
        panic!("{k:?}")
    };
    assert_eq!(p.amount, LightAmountDesc::Lumens(1000.0));
    assert_eq!(p.color, LightColorDesc::Temperature(3000.0));

    let k = one_light(
        &s,
        "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nies = \"p.ies\"\ndirection = [0, 0, -1]\n",
    );
    let LightKindDesc::ShapedPoint(p) = k else {
        panic!("{k:?}")
    };
    assert_eq!(p.amount, LightAmountDesc::ProfileCandela);
    let profile = p.profile.unwrap();
    assert_eq!(profile.nadir, -Vec3::Z);
    assert!((profile.table.max_intensity() - 100.0).abs() < 1e-3);
}

#[test]
fn spot_directional_and_projector_load_and_build() {
    let (_d, s) = assets();
    let k = one_light(
        &s,
        "[[light]]\ntype = \"spot\"\nposition = [0, 2, 0]\ndirection = [0, -1, 0]\n\
         inner_angle = 10\nouter_angle = 20\nfalloff = \"mitsuba\"\nintensity = 5\ncolor = [1, 0.5, 0.5]\n",
    );
    let LightKindDesc::Spot(sp) = k else {
        panic!("{k:?}")
    };
    assert_eq!((sp.inner_angle_deg, sp.outer_angle_deg), (10.0, 20.0));
    assert_eq!(sp.falloff, SpotFalloff::Mitsuba);
    assert_eq!(sp.amount, LightAmountDesc::WattsPerSr(5.0));

    let k = one_light(
        &s,
        "[[light]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nirradiance = 100000\n\
         units = \"photometric\"\n",
    );
    assert!(
        matches!(k, LightKindDesc::Directional(d) if d.amount == LightAmountDesc::Candela(1e5))
    );

    let desc = load(
        &s,
        "[[light]]\ntype = \"projector\"\nposition = [0, 2, 0]\ndirection = [0, -1, 0]\n\
         up = [0, 0, -1]\nimage = \"img.png\"\nfov = 30\nintensity = 2\n",
    )
    .unwrap();
    let LightKindDesc::Projector(p) = &desc.lights[0].kind else {
        panic!()
    };
    // sRGB 128 decodes to 0.2158 linear; fov_x follows the 2:1 aspect.
    assert!(
        (p.image.pixels[0] - Vec3::splat(0.2158))
            .abs()
            .max_element()
            < 1e-4
    );
    assert_eq!(p.image.pixels[1], Vec3::X);
    let want_x = 2.0 * (2.0 * 15f32.to_radians().tan()).atan().to_degrees();
    assert!((p.fov_x_deg - want_x).abs() < 1e-4 && p.fov_y_deg == 30.0);
    let scene = build(&desc).unwrap();
    assert!(matches!(scene.lights[0], Light::Projector(_)));
}

#[test]
fn ies_on_an_emitting_shape_shapes_its_triangles() {
    let (_d, s) = assets();
    let desc = load(
        &s,
        "[[shape]]\ntype = \"rectangle\"\nmaterial = \"white\"\nemission = 2\nies = \"p.ies\"\n",
    )
    .unwrap();
    assert_eq!(desc.emission_profiles.len(), 1);
    assert_eq!(desc.emission_profiles[0].shape, 0);
    let scene = build(&desc).unwrap();
    for l in &scene.lights {
        let Light::Triangle(t) = l else { panic!() };
        // Along the normal the profile is at its peak; at 45° it is half.
        assert!(
            (t.radiance(Vec3::Z, Vec2::ZERO, Vec3::Z) - Vec3::splat(2.0))
                .abs()
                .max_element()
                < 1e-4
        );
        let w = Vec3::new(1.0, 0.0, 1.0).normalize();
        assert!(
            (t.radiance(Vec3::Z, Vec2::ZERO, w) - Vec3::splat(1.0))
                .abs()
                .max_element()
                < 1e-3
        );
    }
}

fn err(s: &Path, text: &str) -> String {
    load(s, text).expect_err("should not load")
}

#[test]
fn bad_light_input_gives_located_errors() {
    let (_d, s) = assets();
    let f = s.display().to_string();
    // HEAD has 3 lines, so the light table starts on line 4.
    let cases: &[(&str, &str)] = &[
        ("[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\nimage = \"x.png\"\n", ":7:1: a spot light has no key `image`"),
        ("[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\nintensity = 1\nfalloff = \"cubic\"\n", ":8:11: unknown variant `cubic`"),
        ("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nies = \"none.ies\"\n", ":7:7: IES file"),
        ("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = 1\npower = 2\n", ":8:9: give either an intensity or `power`"),
        ("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = 1\ncolor = 1\ntemperature = 2000\n", ":9:15: `color` and `temperature` exclude"),
        ("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\n", ":4:1: the light needs an intensity"),
        ("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [1, 2, 3]\nunits = \"photometric\"\n", ":7:13: a photometric amount is one number"),
        ("[[light]]\ntype = \"spot\"\nintensity = 1\n", ":4:1: a spot light needs `position`"),
        ("[[light]]\ntype = \"directional\"\ndirection = [0, -1, 0]\n", ":4:1: a directional light needs `irradiance`"),
        ("[[light]]\ntype = \"projector\"\nposition = [0, 1, 0]\nimage = \"img.png\"\nintensity = 1\n", ":4:1: a projector needs either `fov`"),
        ("[[light]]\ntype = \"projector\"\nposition = [0, 1, 0]\nimage = \"gone.png\"\nfov = 3\nintensity = 1\n", ":7:9: image file"),
        ("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = 1\nunits = \"lux\"\n", ":8:9: unknown variant `lux`"),
        ("[[shape]]\ntype = \"rectangle\"\nmaterial = \"white\"\nies = \"p.ies\"\n", ":7:7: `ies` shapes an emitter's radiance"),
        ("[[shape]]\ntype = \"sphere\"\nmaterial = \"white\"\nemission = 1\nies = \"p.ies\"\n", ":8:7: `ies` is not supported on spheres"),
    ];
    for (text, want) in cases {
        let e = err(&s, text);
        assert!(
            e.starts_with(&format!("{f}{want}")),
            "got  {e}\nwant {f}{want}"
        );
    }
    // A malformed IES file reports its own file and line.
    fs::write(
        s.with_file_name("bad.ies"),
        "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 10\n0 45 90\n0\n100 -5 0\n",
    )
    .unwrap();
    let e = err(
        &s,
        "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nies = \"bad.ies\"\n",
    );
    assert!(e.contains("bad.ies:") && e.contains("negative"), "{e}");
}

#[test]
fn build_errors_of_loaded_lights_point_at_the_light() {
    let (_d, s) = assets();
    let desc = load(
        &s,
        "[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\ninner_angle = 50\nouter_angle = 40\nintensity = 1\n",
    )
    .unwrap();
    let e = build(&desc).map(|_| ()).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("{}:4:1: inner_angle 50°", s.display())),
        "{e}"
    );
}

#[test]
fn the_ies_room_example_loads_and_builds() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/ies-room.toml"
    ));
    let desc = load_scene(path).unwrap();
    let scene = build(&desc).unwrap();
    let gonio = scene
        .lights
        .iter()
        .filter(|l| matches!(l, Light::Goniometric(_)))
        .count();
    assert_eq!(gonio, 3);
    assert!(scene.lights.iter().any(|l| matches!(l, Light::Spot(_))));
    assert!(scene
        .lights
        .iter()
        .any(|l| matches!(l, Light::Triangle(t) if t.profile.is_some())));
}

#[test]
fn emission_takes_a_texture() {
    let (_d, s) = assets();
    // A colour stays the radiance.
    let desc = load(
        &s,
        "[[shape]]\ntype = \"rectangle\"\nmaterial = \"white\"\nemission = 3\n",
    )
    .unwrap();
    assert_eq!(desc.shapes[0].emission, Some(Vec3::splat(3.0)));
    assert!(desc.shapes[0].emission_texture.is_none());
    // An image (sRGB-decoded, as a colour slot) multiplies a radiance of one.
    let desc = load(
        &s,
        "[[shape]]\ntype = \"rectangle\"\nmaterial = \"white\"\n\
         emission = { type = \"image\", file = \"img.png\", scale = 4 }\n",
    )
    .unwrap();
    assert_eq!(desc.shapes[0].emission, Some(Vec3::ONE));
    let Some(TextureDesc::Image(t)) = &desc.shapes[0].emission_texture else {
        panic!("{:?}", desc.shapes[0].emission_texture)
    };
    assert_eq!(t.scale, Vec3::splat(4.0));
    assert!(
        (t.image.pixels[0].x - 0.2158605).abs() < 1e-5,
        "{}",
        t.image.pixels[0]
    );
    let scene = build(&desc).unwrap();
    // Textured triangles stay apart (no parallelogram), each with the texture.
    assert_eq!(scene.lights.len(), 2);
    for l in &scene.lights {
        let Light::Triangle(t) = l else {
            panic!("{l:?}")
        };
        assert!(t.texture.is_some());
    }
    // A checker too; spheres refuse a texture, at the shape.
    let sphere = "[[shape]]\ntype = \"sphere\"\nmaterial = \"white\"\n\
                  emission = { type = \"checker\", a = 2, b = 0 }\n";
    let err = build(&load(&s, sphere).unwrap()).unwrap_err().to_string();
    assert!(
        err.contains("scene.toml:4:1") && err.contains("not supported on spheres"),
        "{err}"
    );
    let err = load(
        &s,
        "[[shape]]\ntype = \"disk\"\nmaterial = \"white\"\nemission = { type = \"image\" }\n",
    )
    .unwrap_err();
    assert!(
        err.contains("scene.toml:7:12") && err.contains("needs `file`"),
        "{err}"
    );
}
