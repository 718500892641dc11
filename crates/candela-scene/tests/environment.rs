//! Environment maps from files: .hdr, .exr (half and float) and sRGB loading, the real
//! panoramas and cube map of ../shared/data sampled in proportion to their pdf
//! (chi-square), and the `[environment]` TOML section with its errors.

use std::path::{Path, PathBuf};

use candela_core::chi2::{sidak_alpha, ChiSquareTest};
use candela_core::color::srgb_decode;
use candela_core::desc::{EnvironmentMapDesc, ImageDesc};
use candela_core::light::envmap::{cubemap, Cubemap, Equirect, Image};
use candela_core::light::{EnvironmentLight, EnvironmentMap, LightSource, ShadingCtx};
use candela_scene::envmap::load_linear_image;
use candela_scene::parse_toml_scene;
use glam::{Mat3, Vec3};

fn data_dir() -> Option<PathBuf> {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data"));
    if dir.exists() {
        Some(dir.to_path_buf())
    } else {
        eprintln!("skipped: ../shared/data not found (the optional HDR and cubemap collection)");
        None
    }
}

const CTX: ShadingCtx = ShadingCtx {
    p: Vec3::ZERO,
    n: Vec3::ZERO,
};

/// Four chi-square tests below (three panoramas, one cube map) share α = 0.01 (Šidák).
fn chi2_test() -> ChiSquareTest {
    ChiSquareTest {
        alpha: sidak_alpha(0.01, 4),
        ..Default::default()
    }
}

fn check_sampling(name: &str, light: &EnvironmentLight) {
    let report = chi2_test().spherical(
        name,
        |u| light.sample_li(&CTX, u).map(|s| s.wi),
        |d| light.pdf_li(&CTX, d),
    );
    println!("{report}");
    report.assert_passed();
}

#[test]
#[ignore = "3 × 10⁶ samples on 1k maps; run in release with --include-ignored"]
fn real_panoramas_are_sampled_by_their_pdf() {
    let Some(dir) = data_dir() else { return };
    for name in ["rooitou_park_1k", "venice_sunset_1k", "studio_small_03_1k"] {
        let img = load_linear_image(&dir.join(format!("hdri/{name}.hdr"))).unwrap();
        assert_eq!((img.width, img.height), (1024, 512));
        let map = EnvironmentMap::Equirect(Equirect::new(Image::from_desc(&img)));
        // A turned map exercises the rotation in both sample and pdf.
        let light = EnvironmentLight::new(map, 1.0, Mat3::from_rotation_y(0.3), 1.0);
        check_sampling(name, &light);
    }
}

#[test]
fn rooitou_park_sun_is_bright_and_peaked() {
    // The file's tiny sun carries most of the energy (SOURCES.md): the brightest 1% of
    // texels (by luminance × solid angle) hold well over half the power.
    let Some(dir) = data_dir() else { return };
    let img = load_linear_image(&dir.join("hdri/rooitou_park_1k.hdr")).unwrap();
    let light = EnvironmentLight::new(
        EnvironmentMap::Equirect(Equirect::new(Image::from_desc(&img))),
        1.0,
        Mat3::IDENTITY,
        1.0,
    );
    let peak = light.peak_fraction(0.01);
    assert!(peak > 0.5, "brightest 1% hold {peak}");
}

fn humus_faces(dir: &Path) -> [ImageDesc; 6] {
    let names = ["+x", "-x", "+y", "-y", "+z", "-z"];
    let paths: Vec<PathBuf> = names
        .iter()
        .map(|n| dir.join(format!("cubemap/humus_magnum/{n}.jpg")))
        .collect();
    let refs: [&Path; 6] = std::array::from_fn(|i| paths[i].as_path());
    // The files are stored bottom row first (SOURCES.md): turn each face upright.
    candela_scene::envmap::load_cube_faces(&refs)
        .unwrap()
        .map(|f| candela_scene::envmap::flip_vertical(&f))
}

#[test]
#[ignore = "10⁶ samples; run in release with --include-ignored"]
fn real_cube_map_is_sampled_by_its_pdf() {
    let Some(dir) = data_dir() else { return };
    let faces = humus_faces(&dir).map(|f| Image::from_desc(&f));
    let light = EnvironmentLight::new(
        EnvironmentMap::Cubemap(Cubemap::new(Box::new(faces))),
        1.0,
        Mat3::IDENTITY,
        1.0,
    );
    check_sampling("humus cube map", &light);
}

#[test]
fn real_cube_map_faces_are_distinct_and_the_sky_is_up() {
    // The Humus skybox: sky above, ground below. The +y face is brighter than −y, and,
    // once flipped upright, each side face's top rows (which look up by the face table)
    // are brighter than its bottom rows.
    let Some(dir) = data_dir() else { return };
    let faces = humus_faces(&dir);
    assert!(faces.iter().all(|f| f.width == 512 && f.height == 512));
    let mean = |f: &ImageDesc, rows: std::ops::Range<u32>| {
        let n = f.width;
        let s: Vec3 = rows
            .clone()
            .flat_map(|y| (0..n).map(move |x| (x, y)))
            .map(|(x, y)| f.pixels[(y * n + x) as usize])
            .sum();
        s / (rows.len() as f32 * n as f32)
    };
    let all = |f: &ImageDesc| mean(f, 0..f.height).element_sum();
    assert!(all(&faces[2]) > all(&faces[3]), "+y should be sky");
    for f in [0, 1, 4, 5] {
        let top = cubemap::face_to_direction(f, glam::Vec2::new(0.5, 0.0));
        assert!(top.y > 0.5, "top row of face {f} looks up");
        assert!(mean(&faces[f], 0..32).element_sum() > mean(&faces[f], 480..512).element_sum());
    }
}

#[test]
fn exr_half_and_float_and_hdr_files_load_as_linear() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (5usize, 3usize);
    let value = |x: usize, y: usize| Vec3::new(x as f32 * 0.5, y as f32 + 0.25, 100.0);
    let float = dir.path().join("f.exr");
    write_rgb_file(&float, w, h, |x, y| {
        let v = value(x, y);
        (v.x, v.y, v.z)
    })
    .unwrap();
    let half = dir.path().join("h.exr");
    write_rgb_file(&half, w, h, |x, y| {
        let v = value(x, y);
        (f16::from_f32(v.x), f16::from_f32(v.y), f16::from_f32(v.z))
    })
    .unwrap();
    let hdr = dir.path().join("i.hdr");
    let px: Vec<image::Rgb<f32>> = (0..h)
        .flat_map(|y| (0..w).map(move |x| image::Rgb(value(x, y).to_array())))
        .collect();
    image::codecs::hdr::HdrEncoder::new(std::fs::File::create(&hdr).unwrap())
        .encode(&px, w, h)
        .unwrap();
    // Tolerances: exact for float, 2⁻¹¹ relative for half, 1/128 relative for RGBE's
    // shared 8-bit mantissa (relative to the largest channel).
    for (path, tol) in [(&float, 0.0), (&half, 1.0 / 2048.0), (&hdr, 1.0 / 128.0)] {
        let img = load_linear_image(path).unwrap();
        assert_eq!((img.width, img.height), (w as u32, h as u32));
        for y in 0..h {
            for x in 0..w {
                let (got, want) = (img.pixels[y * w + x], value(x, y));
                let err = (got - want).abs().max_element();
                assert!(
                    err <= tol * want.max_element(),
                    "{path:?} ({x},{y}): {got} vs {want}"
                );
            }
        }
    }
}

/// A flat (uncompressed) Radiance file of 2 × 3 pixels with the resolution line
/// `resolution` (`-Y 3 +X 2` top row first, `+Y 3 +X 2` bottom row first), an exposure
/// line and a comment. Pixel (x, y), y from the top, is 2^(x + 2y) in red, ¼ of it in green, 0 blue:
/// RGBE (128, 32, 0, 129 + x + 2y) holds it exactly.
fn flat_hdr(resolution: &str) -> Vec<u8> {
    let mut out = format!(
        "#?RADIANCE\n# written by hand\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n{resolution}\n"
    )
    .into_bytes();
    let rows: Vec<u32> = if resolution.contains("+Y") {
        vec![2, 1, 0]
    } else {
        vec![0, 1, 2]
    };
    for y in rows {
        for x in 0..2 {
            out.extend_from_slice(&[128, 32, 0, (129 + x + 2 * y) as u8]);
        }
    }
    out
}

#[test]
fn radiance_files_stored_bottom_row_first_load_upright() {
    // Radiance's `+Y h +X w` stores the bottom scanline first; `image` reads only `-Y`.
    // Both must come out top row first, with the same pixels.
    let dir = tempfile::tempdir().unwrap();
    for orientation in ["-Y 3 +X 2", "+Y 3 +X 2", " +Y 3 +X 2"] {
        let path = dir.path().join("o.hdr");
        std::fs::write(&path, flat_hdr(orientation)).unwrap();
        let img = load_linear_image(&path).unwrap_or_else(|e| panic!("{orientation}: {e}"));
        assert_eq!((img.width, img.height), (2, 3), "{orientation}");
        for y in 0..3 {
            for x in 0..2 {
                let v = 2f32.powi(x + 2 * y);
                let want = Vec3::new(v, v / 4.0, 0.0);
                let got = img.pixels[(y * 2 + x) as usize];
                assert_eq!(got, want, "{orientation} ({x},{y})");
            }
        }
    }
    // Column-major orientations stay a clear error.
    let path = dir.path().join("c.hdr");
    std::fs::write(&path, flat_hdr("+X 2 -Y 3")).unwrap();
    let e = load_linear_image(&path).unwrap_err();
    assert!(e.contains("c.hdr") && e.contains("Orientation"), "{e}");
}

#[test]
fn luminance_only_exr_files_load_as_grey_and_others_name_their_channels() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (4usize, 2usize);
    let value = |x: usize, y: usize| x as f32 + 10.0 * y as f32;
    let write = |name: &str, channel: &str| {
        let path = dir.path().join(name);
        let pixels = SpecificChannels::build()
            .with_channel(channel)
            .with_pixel_fn(|p: Vec2<usize>| (f16::from_f32(value(p.x(), p.y())),));
        Image::from_channels((w, h), pixels)
            .write()
            .to_file(&path)
            .unwrap();
        path
    };
    // Half floats hold these small integers exactly.
    let img = load_linear_image(&write("y.exr", "Y")).unwrap();
    assert_eq!((img.width, img.height), (w as u32, h as u32));
    for y in 0..h {
        for x in 0..w {
            assert_eq!(img.pixels[y * w + x], Vec3::splat(value(x, y)), "({x},{y})");
        }
    }
    let e = load_linear_image(&write("z.exr", "Z")).unwrap_err();
    assert!(
        e.contains("z.exr") && e.contains("no layer has R, G and B") && e.contains("channels: Z"),
        "{e}"
    );
}

#[test]
fn srgb_images_are_decoded_to_linear() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("face.png");
    image::RgbImage::from_pixel(2, 2, image::Rgb([0, 128, 255]))
        .save(&path)
        .unwrap();
    let img = load_linear_image(&path).unwrap();
    let want = Vec3::new(0.0, srgb_decode(128.0 / 255.0), 1.0);
    assert!(
        (img.pixels[3] - want).abs().max_element() < 1e-6,
        "{}",
        img.pixels[3]
    );
}

/// Writes a `w × h` PNG of one colour.
fn png(dir: &Path, name: &str, w: u32, h: u32, c: [u8; 3]) {
    image::RgbImage::from_pixel(w, h, image::Rgb(c))
        .save(dir.join(name))
        .unwrap();
}

fn load(dir: &Path, text: &str) -> Result<candela_core::desc::SceneDesc, String> {
    parse_toml_scene(text, &dir.join("scene.toml")).map_err(|e| e.to_string())
}

#[test]
fn toml_environment_forms_load() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    png(d, "pano.png", 8, 4, [255, 255, 255]);
    let names = ["px", "nx", "py", "ny", "pz", "nz"];
    for (i, n) in names.iter().enumerate() {
        png(d, &format!("{n}.png"), 4, 4, [40 * i as u8, 0, 0]);
    }
    png(d, "hcross.png", 16, 12, [1, 2, 3]);
    png(d, "vcross.png", 12, 16, [1, 2, 3]);

    let desc = load(
        d,
        "[environment]\nequirect = \"pano.png\"\nstrength = 2\nrotation = 90\n\
         visible = false\nbackground = [0.1, 0.2, 0.3]\n",
    )
    .unwrap();
    let env = desc.environment.unwrap();
    assert!(matches!(&env.map, EnvironmentMapDesc::Equirect(i) if i.width == 8));
    assert_eq!(env.strength, 2.0);
    assert!((env.rotation * Vec3::Z - Vec3::X).length() < 1e-6);
    assert!(!env.visible);
    assert_eq!(env.background, Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(
        env.span.to_string(),
        format!("{}:1:2", d.join("scene.toml").display())
    );

    let faces = names.map(|n| format!("{n} = \"{n}.png\"")).join(", ");
    let desc = load(d, &format!("[environment]\ncubemap = {{ {faces} }}\n")).unwrap();
    let EnvironmentMapDesc::Cubemap(f) = desc.environment.unwrap().map else {
        panic!("not a cube map")
    };
    // Faces keep their order: +x is px.png (black), −z is nz.png (the reddest).
    assert_eq!(f[0].pixels[0], Vec3::ZERO);
    assert!((f[5].pixels[0].x - srgb_decode(200.0 / 255.0)).abs() < 1e-6);

    for cross in ["hcross.png", "vcross.png"] {
        let desc = load(d, &format!("[environment]\ncubemap = \"{cross}\"\n")).unwrap();
        let EnvironmentMapDesc::Cubemap(f) = desc.environment.unwrap().map else {
            panic!("not a cube map")
        };
        assert!(f.iter().all(|f| f.width == 4 && f.height == 4));
    }

    let desc = load(
        d,
        "[environment]\nconstant = 0.5\ntransform = [{ rotate = { axis = [1, 0, 0], angle = 90 } }]\n",
    )
    .unwrap();
    let env = desc.environment.unwrap();
    assert!(matches!(env.map, EnvironmentMapDesc::Constant(c) if c == Vec3::splat(0.5)));
    assert!((env.rotation * Vec3::Y - Vec3::Z).length() < 1e-6);
    assert!(candela_core::build::build(&SceneDescWith(env).into()).is_ok());
}

/// A scene of nothing but an environment.
struct SceneDescWith(candela_core::desc::EnvironmentDesc);
impl From<SceneDescWith> for candela_core::desc::SceneDesc {
    fn from(e: SceneDescWith) -> Self {
        candela_core::desc::SceneDesc {
            environment: Some(e.0),
            ..Default::default()
        }
    }
}

#[test]
fn toml_environment_errors_point_at_the_cause() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    png(d, "odd.png", 10, 10, [1, 1, 1]);
    png(d, "wide.png", 4, 2, [1, 1, 1]);
    let file = d.join("scene.toml").display().to_string();
    let cases = [
        ("[environment]\nstrength = 2\n", "1:2", "exactly one of"),
        (
            "[environment]\nconstant = 1\nflip_faces = true\n",
            "3:14",
            "only to a `cubemap`",
        ),
        (
            "[environment]\nconstant = 1\nequirect = \"x.hdr\"\n",
            "3:12",
            "exactly one of",
        ),
        (
            "[environment]\nequirect = \"missing.hdr\"\n",
            "2:12",
            "missing.hdr: cannot read",
        ),
        (
            "[environment]\ncubemap = \"odd.png\"\n",
            "2:11",
            "4:3 (horizontal) or 3:4",
        ),
        (
            "[environment]\ncubemap = { px = \"wide.png\" }\n",
            "2:11",
            "missing field `nx`",
        ),
        (
            "[environment]\ncubemap = { up = \"a.png\" }\n",
            "2:11",
            "unknown field `up`",
        ),
        (
            "[environment]\nconstant = [1, 2]\n",
            "2:12",
            "expected an array of 3",
        ),
        (
            "[environment]\nconstant = 1\nrotation = nan\n",
            "3:12",
            "finite",
        ),
        (
            "[environment]\nconstant = 1\nrotation = 3\ntransform = []\n",
            "4:13",
            "not both",
        ),
        (
            "[environment]\nconstant = 1\ntransform = [{ translate = [1, 0, 0] }]\n",
            "3:13",
            "cannot translate",
        ),
        (
            "[environment]\nconstant = 1\nvisble = false\n",
            "3:1",
            "unknown field `visble`",
        ),
    ];
    for (text, at, what) in cases {
        let e = load(d, text).expect_err(text);
        assert!(e.starts_with(&format!("{file}:{at}: ")), "{text:?}: {e}");
        assert!(e.contains(what), "{text:?}: {e}");
    }
    // Six faces of which one is not square: the error names the face.
    let names = ["px", "nx", "py", "ny", "pz", "nz"];
    for n in names {
        png(d, &format!("{n}.png"), 4, 4, [1, 1, 1]);
    }
    png(d, "ny.png", 4, 3, [1, 1, 1]);
    let faces = names.map(|n| format!("{n} = \"{n}.png\"")).join(", ");
    let e = load(d, &format!("[environment]\ncubemap = {{ {faces} }}\n")).unwrap_err();
    assert!(
        e.contains("face ny (ny.png): cube map face is 4x3, not square"),
        "{e}"
    );
    // A scale passes the loader but not the build, which points at the section.
    let desc = load(
        d,
        "[environment]\nconstant = 1\ntransform = [{ scale = 2 }]\n",
    )
    .unwrap();
    let e = candela_core::build::build(&desc).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("{file}:1:2: environment rotation")),
        "{e}"
    );
}
