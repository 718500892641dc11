//! The `[camera]` keys of depth of field: what they become in the description, and a
//! located error for every kind of bad lens input.

use std::path::Path;

use candela_core::color::srgb_decode;
use candela_core::desc::{ApertureDesc, ApertureSizeDesc, FocusDesc, SceneDesc};
use candela_scene::{load_scene, parse_toml_scene};
use glam::{Vec2, Vec3};

fn parse_in(text: &str, dir: &Path) -> Result<SceneDesc, String> {
    parse_toml_scene(text, &dir.join("scene.toml")).map_err(|e| e.to_string())
}

fn parse(text: &str) -> Result<SceneDesc, String> {
    parse_toml_scene(text, Path::new("scene.toml")).map_err(|e| e.to_string())
}

fn error(text: &str) -> String {
    parse(text).expect_err("the camera should not load")
}

#[test]
fn thin_lens_keys_become_a_lens() {
    let d = parse(
        "[camera]\ntype = \"thin_lens\"\nfocal_length = 85\nsensor = [24, 16]\n\
         focus_on = [0, 1, -3]\nf_number = 2.8\naperture = { blades = 6, rotation = 15 }\n",
    )
    .unwrap();
    let c = d.camera;
    assert_eq!(c.focal_length_mm, Some(85.0));
    assert_eq!(c.sensor_mm, Vec2::new(24.0, 16.0));
    let lens = c.lens.unwrap();
    assert_eq!(lens.focus, FocusDesc::Point(Vec3::new(0.0, 1.0, -3.0)));
    assert_eq!(lens.size, ApertureSizeDesc::FNumber(2.8));
    assert_eq!(
        lens.aperture,
        ApertureDesc::Polygon {
            blades: 6,
            rotation_deg: 15.0
        }
    );

    let d = parse(
        "[camera]\ntype = \"thin_lens\"\nfov = 30\nfocus_distance = 4\naperture_radius = 0.1\n",
    )
    .unwrap();
    let lens = d.camera.lens.unwrap();
    assert_eq!(d.camera.fov_y_deg, 30.0);
    assert_eq!(lens.focus, FocusDesc::Distance(4.0));
    assert_eq!(lens.size, ApertureSizeDesc::Radius(0.1));
    assert_eq!(lens.aperture, ApertureDesc::Disc);

    // No focus key: focus on look_at. A pinhole stays lens-less.
    let d = parse("[camera]\ntype = \"thin_lens\"\nf_number = 2\naperture = \"disc\"\n").unwrap();
    assert_eq!(d.camera.lens.unwrap().focus, FocusDesc::LookAt);
    assert!(parse("[camera]\nfocal_length = 35\n")
        .unwrap()
        .camera
        .lens
        .is_none());
}

#[test]
fn bad_lens_keys_are_located_errors() {
    let tl = "[camera]\ntype = \"thin_lens\"\n";
    let cases = [
        (
            "[camera]\nf_number = 2\n".to_string(),
            "scene.toml:2:1: unknown field `f_number`, expected one of `type`, `position`, \
             `look_at`, `up`, `fov`, `focal_length`, `sensor`",
        ),
        (
            "[camera]\nfov = 30\nfocal_length = 50\n".into(),
            "scene.toml:3:16: give `fov` or `focal_length`, not both",
        ),
        (
            format!("{tl}f_number = 2\nfocus_distance = 3\nfocus_on = [0, 0, 0]\n"),
            "scene.toml:5:12: give `focus_distance` or `focus_on`, not both",
        ),
        (
            format!("{tl}f_number = 2\naperture_radius = 0.1\n"),
            "scene.toml:4:19: give `f_number` or `aperture_radius`, not both",
        ),
        (
            tl.to_string(),
            "scene.toml:1:2: a thin_lens camera needs `f_number` or `aperture_radius`",
        ),
        (
            format!("{tl}f_number = 2\naperture = \"square\"\n"),
            "scene.toml:4:12: unknown aperture \"square\"; `aperture` must be \"disc\", \
             { blades = N, rotation = DEGREES } or { image = \"FILE\" }",
        ),
        (
            format!("{tl}f_number = 2\naperture = {{ blades = 2 }}\n"),
            "scene.toml:4:12: `blades` must be an integer from 3 to 64; `aperture` must be \
             \"disc\", { blades = N, rotation = DEGREES } or { image = \"FILE\" }",
        ),
        (
            format!("{tl}f_number = 2\naperture = {{ blades = 6, rot = 3 }}\n"),
            "scene.toml:4:12: unknown aperture key `rot`; `aperture` must be \"disc\", \
             { blades = N, rotation = DEGREES } or { image = \"FILE\" }",
        ),
        (
            format!("{tl}f_number = 2\naperture = 6\n"),
            "scene.toml:4:12: found integer; `aperture` must be \"disc\", \
             { blades = N, rotation = DEGREES } or { image = \"FILE\" }",
        ),
        (
            format!("{tl}f_number = nan\n"),
            "scene.toml:3:12: expected a finite number, found nan",
        ),
    ];
    for (text, want) in cases {
        assert_eq!(error(&text), want, "for\n{text}");
    }
}

#[test]
fn out_of_range_lens_values_fail_the_build_at_the_camera() {
    for text in [
        "[camera]\ntype = \"thin_lens\"\nf_number = -2\n",
        "[camera]\ntype = \"thin_lens\"\nf_number = 2\nfocus_distance = 0\n",
        "[camera]\ntype = \"thin_lens\"\nf_number = 2\nfocus_on = [0, 0, 9]\n",
        "[camera]\nfocal_length = 0\n",
    ] {
        let desc = parse(text).unwrap();
        let e = candela_core::build::build(&desc).unwrap_err();
        assert!(e.to_string().starts_with("scene.toml:1:2: "), "{e}");
    }
}

#[test]
fn image_apertures_decode_to_linear_luminance() {
    let dir = tempfile::tempdir().unwrap();
    // 3×2 sRGB image: grey 128, pure green, white on top; a half-transparent white pixel
    // and two black ones below.
    let mut img = image::RgbaImage::new(3, 2);
    img.put_pixel(0, 0, image::Rgba([128, 128, 128, 255]));
    img.put_pixel(1, 0, image::Rgba([0, 255, 0, 255]));
    img.put_pixel(2, 0, image::Rgba([255, 255, 255, 255]));
    img.put_pixel(0, 1, image::Rgba([255, 255, 255, 128]));
    img.save(dir.path().join("mask.png")).unwrap();
    let text =
        "[camera]\ntype = \"thin_lens\"\nf_number = 2\naperture = { image = \"mask.png\" }\n";
    let d = parse_in(text, dir.path()).unwrap();
    let Some(ApertureDesc::Image {
        width,
        height,
        luminance,
    }) = d.camera.lens.map(|l| l.aperture)
    else {
        panic!("not an image aperture");
    };
    assert_eq!((width, height), (3, 2));
    let want = [
        srgb_decode(128.0 / 255.0),
        0.7152,
        1.0,
        128.0 / 255.0,
        0.0,
        0.0,
    ];
    for (got, want) in luminance.iter().zip(want) {
        assert!((got - want).abs() < 1e-4, "{luminance:?}");
    }

    // Missing and black images are errors at the aperture value.
    let missing =
        "[camera]\ntype = \"thin_lens\"\nf_number = 2\naperture = { image = \"nope.png\" }\n";
    let e = parse_in(missing, dir.path()).unwrap_err();
    assert!(
        e.contains("scene.toml:4:12: cannot read aperture image `nope.png`"),
        "{e}"
    );
    image::RgbaImage::new(2, 2)
        .save(dir.path().join("black.png"))
        .unwrap();
    let black =
        "[camera]\ntype = \"thin_lens\"\nf_number = 2\naperture = { image = \"black.png\" }\n";
    let e = parse_in(black, dir.path()).unwrap_err();
    assert!(
        e.ends_with("aperture image `black.png` is black: no light would pass"),
        "{e}"
    );
}

#[test]
fn the_dof_example_scene_loads_and_builds() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/dof.toml"
    ));
    let desc = load_scene(path).unwrap();
    let lens = desc.camera.lens.as_ref().expect("a thin lens");
    assert!(matches!(
        lens.aperture,
        ApertureDesc::Polygon { blades: 6, .. }
    ));
    let scene = candela_core::build::build(&desc).unwrap();
    let lens = scene.camera.lens().unwrap();
    // 85 mm at f/1.4 in metres; focused on the subject 1.5 m down the view axis.
    assert!((lens.aperture_radius - 0.085 / 2.8).abs() < 1e-6);
    assert!((lens.focus_distance - 1.5).abs() < 0.01);
}

#[test]
fn documented_thin_lens_example_parses() {
    let doc = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/scene-format.md");
    let doc = std::fs::read_to_string(doc).unwrap();
    let section = doc.find("### `[camera]`").expect("a camera section");
    let start = section
        + doc[section..]
            .find("```toml\n")
            .expect("a thin-lens example")
        + 8;
    let example = &doc[start..start + doc[start..].find("```").unwrap()];
    let d = parse(example).unwrap_or_else(|e| panic!("{e}"));
    let lens = d.camera.lens.as_ref().unwrap();
    assert_eq!(lens.size, ApertureSizeDesc::FNumber(1.4));
    assert!((d.camera.vertical_fov_deg() - 16.07).abs() < 0.01);
}

#[test]
fn orthographic_cameras_take_a_height_and_no_lens() {
    let d = parse(
        "[camera]\ntype = \"orthographic\"\nposition = [0, 5, 0]\nlook_at = [0, 0, 0]\n\
         up = [0, 0, -1]\nheight = 3.5\n",
    )
    .unwrap();
    assert_eq!(d.camera.ortho_height, Some(3.5));
    assert_eq!(d.camera.position, Vec3::new(0.0, 5.0, 0.0));
    assert!(d.camera.lens.is_none());
    // The height is required; a lens or fov key is not one of its keys.
    let e = error("[camera]\ntype = \"orthographic\"\n");
    assert!(
        e.starts_with("scene.toml:1:2: ") && e.contains("`height`"),
        "{e}"
    );
    let e = error("[camera]\ntype = \"orthographic\"\nheight = 2\nfov = 30\n");
    assert!(e.contains("scene.toml:4:1") && e.contains("fov"), "{e}");
    // A view of no height, or a lens put on by the command line, fails the build.
    let desc = parse("[camera]\ntype = \"orthographic\"\nheight = 0\n").unwrap();
    let e = candela_core::build::build(&desc).unwrap_err().to_string();
    assert!(
        e.starts_with("scene.toml:1:2: ") && e.contains("height 0"),
        "{e}"
    );
    let mut desc = parse("[camera]\ntype = \"orthographic\"\nheight = 2\n").unwrap();
    desc.camera.lens = Some(Default::default());
    let e = candela_core::build::build(&desc).unwrap_err().to_string();
    assert!(e.contains("takes no lens"), "{e}");
}
