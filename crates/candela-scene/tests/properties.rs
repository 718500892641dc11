//! Property tests: random valid scenes build and render a few samples to finite images
//! with no sample dropped as non-finite; random corruptions of valid files (the project's
//! own scenes, meshes, profiles, a Mitsuba scene and images) are a one-line error or a
//! valid result, never a panic.
//!
//! Case counts keep the file under ~20 s in release; proptest's seed is fixed by its
//! default config unless `PROPTEST_RNG_SEED`/failure persistence says otherwise.

use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A material of any kind, with parameters across their whole valid ranges (roughness
/// 0 and 1 included).
fn material() -> impl Strategy<Value = String> {
    let unit = prop_oneof![Just(0.0f32), Just(1.0f32), 0.0f32..=1.0];
    prop_oneof![
        unit.clone()
            .prop_map(|a| format!("type = \"diffuse\"\nalbedo = {a}")),
        (unit.clone(), unit.clone()).prop_map(|(u, v)| format!(
            "type = \"conductor\"\npreset = \"Cu\"\nalpha_u = {u}\nalpha_v = {v}"
        )),
        (1.0001f32..3.0, unit.clone(), any::<bool>()).prop_map(|(eta, a, inv)| format!(
            "type = \"dielectric\"\neta = {}\nalpha = {a}",
            if inv { 1.0 / eta } else { eta }
        )),
        (unit.clone(), 1.0001f32..3.0, any::<bool>()).prop_map(|(albedo, eta, two)| format!(
            "type = \"plastic\"\nalbedo = {albedo}\neta = {eta}\ntwo_sided = {two}"
        )),
        (unit.clone(), unit.clone(), unit).prop_map(|(c, m, r)| format!(
            "type = \"metal_rough\"\nbase_color = {c}\nmetallic = {m}\nroughness = {r}"
        )),
    ]
}

fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![Just(0.0f32), -3.0f32..3.0]
}

fn point() -> impl Strategy<Value = [f32; 3]> {
    [coord(), coord(), coord()]
}

/// A shape on material `m{0..4}`, perhaps emitting.
fn shape() -> impl Strategy<Value = String> {
    let geometry = prop_oneof![
        (point(), 0.001f32..2.0).prop_map(|(c, r)| format!(
            "type = \"sphere\"\ncenter = {c:?}\nradius = {r}"
        )),
        (point(), 0.001f32..4.0, -180.0f32..180.0).prop_map(|(t, s, a)| format!(
            "type = \"rectangle\"\ntransform = [{{ rotate = {{ axis = [1, 0.3, 0], angle = {a} }} }}, \
             {{ scale = {s} }}, {{ translate = {t:?} }}]"
        )),
        (point(), point(), point()).prop_map(|(a, b, c)| format!(
            "type = \"mesh\"\npositions = [{a:?}, {b:?}, {c:?}]\nindices = [[0, 1, 2]]"
        )),
        Just("type = \"cube\"".to_string()),
    ];
    let emission = prop_oneof![Just(0.0f32), 0.0f32..20.0];
    (geometry, 0..4usize, emission).prop_map(|(g, m, e)| {
        let mut s = format!("[[shape]]\n{g}\nmaterial = \"m{m}\"\n");
        if e > 0.0 {
            writeln!(s, "emission = {e}").unwrap();
        }
        s
    })
}

fn light() -> impl Strategy<Value = String> {
    prop_oneof![
        (point(), 0.0f32..50.0).prop_map(|(p, i)| format!(
            "[[light]]\ntype = \"point\"\nposition = {p:?}\nintensity = {i}\n"
        )),
        (point(), point(), 0.0f32..30.0, 0.0f32..60.0).prop_map(|(p, d, inner, extra)| {
            let d = if d == [0.0; 3] { [0.0, -1.0, 0.0] } else { d };
            format!(
                "[[light]]\ntype = \"spot\"\nposition = {p:?}\ndirection = {d:?}\n\
                 inner_angle = {inner}\nouter_angle = {}\nintensity = 20\n",
                inner + extra + 0.001
            )
        }),
    ]
}

/// A whole scene: a camera somewhere, four materials, 1–6 shapes and 0–3 lights.
fn scene() -> impl Strategy<Value = String> {
    (
        point(),
        prop::collection::vec(material(), 4),
        prop::collection::vec(shape(), 1..6),
        prop::collection::vec(light(), 0..3),
        0..6u32,
        any::<u64>(),
    )
        .prop_map(|(eye, materials, shapes, lights, depth, seed)| {
            let eye = if eye == [0.0, 0.0, 0.5] {
                [0.0, 0.0, 4.0]
            } else {
                eye
            };
            let mut s = format!(
                "[render]\nresolution = [8, 6]\nspp = 2\nmax_depth = {depth}\nseed = {seed}\n\n\
                 [camera]\ntype = \"pinhole\"\nposition = {eye:?}\nlook_at = [0, 0, 0.5]\n\
                 fov = 50\n\n"
            );
            for (i, m) in materials.iter().enumerate() {
                write!(s, "[materials.m{i}]\n{m}\n\n").unwrap();
            }
            for x in shapes.iter().chain(&lights) {
                writeln!(s, "{x}").unwrap();
            }
            s
        })
}

fn runner(cases: u32) -> TestRunner {
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    // A fixed seed: the same cases every run, so a failure reproduces.
    TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
}

#[test]
fn random_valid_scenes_build_and_render_finite() {
    runner(256)
        .run(&scene(), |text| {
            let desc = candela_scene::parse_toml_scene(&text, Path::new("random.toml"))
                .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
            // A degenerate random triangle or a camera inside a shape is still valid.
            let scene = match candela_core::build::build(&desc) {
                Ok(s) => s,
                Err(e) => return Err(TestCaseError::fail(format!("{e}\n{text}"))),
            };
            let film =
                candela_core::integrator::render(&scene, 0..2, &AtomicBool::new(false), &|_| {})
                    .film;
            let pixels = film.resolve();
            prop_assert!(pixels.iter().all(|p| p.is_finite()), "{text}");
            prop_assert_eq!(film.rejected_samples(), 0, "{}", text);
            Ok(())
        })
        .unwrap();
}

/// A corruption of `bytes`: bytes overwritten, inserted, removed, or the file cut.
fn corrupt(bytes: Vec<u8>) -> impl Strategy<Value = Vec<u8>> {
    let n = bytes.len();
    let edit = (0..n, any::<u8>(), 0..3u8);
    (prop::collection::vec(edit, 1..8), 0..=n, any::<bool>()).prop_map(
        move |(edits, cut, do_cut)| {
            let mut b = bytes.clone();
            for (at, v, kind) in edits {
                let at = at.min(b.len().saturating_sub(1));
                match kind {
                    0 if !b.is_empty() => b[at] = v,
                    1 => b.insert(at, v),
                    _ if !b.is_empty() => {
                        b.remove(at);
                    }
                    _ => {}
                }
            }
            if do_cut {
                b.truncate(cut);
            }
            b
        },
    )
}

/// Corrupts `file` `cases` times and hands each version to `parse`, which must return
/// and, on error, give one line.
fn corruptions_are_errors(file: &str, cases: u32, parse: impl Fn(&[u8]) -> Result<(), String>) {
    let path = root().join(file);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(parse(&bytes).is_ok(), "{file} itself parses");
    runner(cases)
        .run(&corrupt(bytes), |b| {
            if let Err(e) = parse(&b) {
                prop_assert!(!e.contains('\n') && !e.is_empty(), "{e:?}");
            }
            Ok(())
        })
        .unwrap();
}

fn text(b: &[u8]) -> Result<&str, String> {
    std::str::from_utf8(b).map_err(|e| e.to_string())
}

#[test]
fn corrupted_scenes_are_errors_not_panics() {
    corruptions_are_errors("scenes/cornell.toml", 1000, |b| {
        let desc = candela_scene::parse_toml_scene(text(b)?, &root().join("scenes/cornell.toml"))
            .map_err(|e| e.to_string())?;
        candela_core::build::build(&desc)
            .map(|_| ())
            .map_err(|e| e.to_string())
    });
    corruptions_are_errors("scenes/mitsuba-cornell.xml", 1000, |b| {
        let options = candela_scene::LoadOptions::default();
        let path = root().join("scenes/mitsuba-cornell.xml");
        let loaded = candela_scene::mitsuba::parse_mitsuba(text(b)?, &path, &options)
            .map_err(|e| e.to_string())?;
        candela_core::build::build(&loaded.desc)
            .map(|_| ())
            .map_err(|e| e.to_string())
    });
}

#[test]
fn corrupted_meshes_profiles_and_images_are_errors_not_panics() {
    corruptions_are_errors("scenes/cornell/tall.obj", 1000, |b| {
        candela_scene::obj::parse_obj(b, Path::new("tall.obj"))
            .map(|_| ())
            .map_err(|e| e.to_string())
    });
    corruptions_are_errors("scenes/ies/batwing.ies", 1000, |b| {
        let ies = candela_scene::ies::parse_ies(b, "batwing.ies").map_err(|e| e.to_string())?;
        ies.table().map(|_| ()).map_err(|e| e.to_string())
    });
    corruptions_are_errors("docs/gallery/cornell.png", 200, |b| {
        use candela_scene::image_texture::{decode_image, Encoding};
        decode_image(b, Path::new("cornell.png"), Encoding::Srgb).map(|_| ())
    });
}
