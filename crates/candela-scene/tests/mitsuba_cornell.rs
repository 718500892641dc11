//! The proof of the Mitsuba import: the Cornell box from `../shared/data/mitsuba`, loaded
//! from its XML and rendered by Candela, agrees with the reference image shipped with it
//! (Bitterli's Tungsten render) within noise.
//!
//! Method: render at `RES`² (the reference, 1024², is block-averaged down to it: a box
//! filter over the same area, so the expectations match), in `K` independent sample
//! ranges. Per block of `BLOCK`² pixels and channel, the K block means give a mean and a
//! standard error; t = (mean − reference) / se. With K − 1 = 7 degrees of freedom,
//! |t| < 3.5 has probability 0.99 under agreement (Student t, two-sided). Path-traced
//! noise is heavier-tailed than normal and the reference has a little noise and half-float
//! rounding of its own, so we accept when at least 95% of the block-channels pass (a wrong
//! import or transport fails far more: a mirrored camera, a missing wall colour or a
//! depth off by one each move most blocks by many standard errors). A relative floor of
//! 1% in the standard error covers the reference's own error (half floats: 0.05%; its
//! noise and Tungsten-vs-Mitsuba conversion differences: a few tenths of a percent).

use std::path::Path;
use std::sync::atomic::AtomicBool;

use candela_core::desc::{FilterSampling, PixelFilterDesc};
use candela_core::integrator;
use candela_scene::{load_scene_with, LoadOptions};
use glam::Vec3;

const RES: usize = 64;
const BLOCK: usize = 4;
const K: u32 = 8;
const SPP_PER_RANGE: u32 = 64;

fn data_dir() -> Option<&'static Path> {
    let p = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data"));
    if p.is_dir() {
        Some(p)
    } else {
        eprintln!(
            "skipped: ../shared/data not found (the optional Mitsuba scenes and reference renders)"
        );
        None
    }
}

/// The reference, block-averaged to `res`².
fn reference(path: &Path, res: usize) -> Vec<Vec3> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![Vec3::ZERO; size.width() * size.height()]),
        |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
        },
    )
    .expect("reference EXR reads");
    let (w, px) = image.layer_data.channel_data.pixels;
    let h = px.len() / w;
    assert_eq!((w % res, h % res), (0, 0), "reference {w}x{h} vs {res}");
    let f = w / res;
    let mut out = vec![Vec3::ZERO; res * res];
    for y in 0..h {
        for x in 0..w {
            out[(y / f) * res + x / f] += px[y * w + x] / (f * f) as f32;
        }
    }
    out
}

fn block_means(img: &[Vec3]) -> Vec<Vec3> {
    let n = RES / BLOCK;
    let mut out = vec![Vec3::ZERO; n * n];
    for (i, v) in img.iter().enumerate() {
        let (x, y) = (i % RES, i / RES);
        out[(y / BLOCK) * n + x / BLOCK] += *v / (BLOCK * BLOCK) as f32;
    }
    out
}

fn render_ranges(scene_file: &Path, defines: &[(&str, &str)]) -> Vec<Vec<Vec3>> {
    let options = LoadOptions {
        defines: defines
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
        lenient: false,
        ..LoadOptions::default()
    };
    let mut desc = load_scene_with(scene_file, &options).unwrap().desc;
    desc.render.width = RES as u32;
    desc.render.height = RES as u32;
    // The file's tent filter is one pixel of its 1024² image; at 64² a box matches the
    // block-averaged reference (a tent of one 64² pixel would blur it 16 times more).
    assert_eq!(desc.render.filter, PixelFilterDesc::Tent { radius: 1.0 });
    desc.render.filter = PixelFilterDesc::Box;
    let scene = candela_core::build::build(&desc).unwrap();
    let cancel = AtomicBool::new(false);
    (0..K)
        .map(|k| {
            let range = k * SPP_PER_RANGE..(k + 1) * SPP_PER_RANGE;
            let film = integrator::render(&scene, range, &cancel, &|_| {}).film;
            block_means(&film.resolve())
        })
        .collect()
}

/// Fraction of block-channels with |t| < 3.5, and the mean relative difference.
fn agreement(ranges: &[Vec<Vec3>], reference: &[Vec3]) -> (f64, f64) {
    let (mut pass, mut total, mut rel) = (0usize, 0usize, 0.0f64);
    for (b, r) in reference.iter().enumerate() {
        for c in 0..3 {
            let xs: Vec<f64> = ranges.iter().map(|img| img[b][c] as f64).collect();
            let mean = xs.iter().sum::<f64>() / K as f64;
            let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (K - 1) as f64;
            let r = r[c] as f64;
            let se = (var / K as f64).sqrt().max(0.01 * r.abs()).max(1e-4);
            let t = (mean - r) / se;
            pass += (t.abs() < 3.5) as usize;
            total += 1;
            rel += (mean - r).abs() / r.abs().max(1e-3);
        }
    }
    (pass as f64 / total as f64, rel / total as f64)
}

/// Mirrors each block image left to right.
fn mirrored(ranges: &[Vec<Vec3>]) -> Vec<Vec<Vec3>> {
    let n = RES / BLOCK;
    ranges
        .iter()
        .map(|img| {
            (0..n * n)
                .map(|i| img[(i / n) * n + (n - 1 - i % n)])
                .collect()
        })
        .collect()
}

#[test]
fn cornell_box_agrees_with_its_reference_image() {
    let Some(data) = data_dir() else { return };
    let dir = data.join("mitsuba/cornell-box");
    let reference = block_means(&reference(&dir.join("TungstenRender.exr"), RES));
    let ranges = render_ranges(&dir.join("scene.xml"), &[("integrator", "path")]);
    let (fraction, rel) = agreement(&ranges, &reference);
    eprintln!(
        "cornell-box: {:.1}% of block-channels pass, mean relative difference {rel:.4}",
        100.0 * fraction
    );
    assert!(
        fraction >= 0.95,
        "only {:.1}% of blocks agree",
        100.0 * fraction
    );
    // The same comparison fails for a mirrored image (red and green walls swapped): the
    // test can tell a camera imported with the wrong handedness.
    let (fraction, _) = agreement(&mirrored(&ranges), &reference);
    eprintln!("cornell-box mirrored: {:.1}% pass", 100.0 * fraction);
    assert!(fraction < 0.8, "a mirrored image passed ({fraction})");
}

#[test]
fn truncated_transport_is_detected() {
    // The comparison must also fail when light transport is cut short: Mitsuba's
    // max_depth 3 (two bounces) against the reference's full transport.
    let Some(data) = data_dir() else { return };
    let dir = data.join("mitsuba/cornell-box");
    let reference = block_means(&reference(&dir.join("TungstenRender.exr"), RES));
    let ranges = render_ranges(
        &dir.join("scene.xml"),
        &[("integrator", "path"), ("max_depth", "3")],
    );
    let (fraction, rel) = agreement(&ranges, &reference);
    eprintln!(
        "cornell-box at max_depth 3: {:.1}% pass, mean relative difference {rel:.4}",
        100.0 * fraction
    );
    assert!(fraction < 0.8);
}

/// Renders the Cornell box at Mitsuba depth `m`, 64², `spp` samples.
fn render_at_depth(m: &str, spp: u32) -> Option<Vec<Vec3>> {
    let data = data_dir()?;
    let options = LoadOptions {
        defines: [
            ("integrator", "path"),
            ("max_depth", m),
            ("resx", "64"),
            ("resy", "64"),
        ]
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect(),
        lenient: false,
        ..LoadOptions::default()
    };
    let mut desc = load_scene_with(&data.join("mitsuba/cornell-box/scene.xml"), &options)
        .unwrap()
        .desc;
    desc.render.spp = spp;
    // Each pixel keeps its own few samples, drawn from the scene's tent: then a pixel on
    // the light's strip, one or two pixels tall here, can see nothing but the light.
    // Splatting would mix in samples from up to a pixel around, off the strip.
    desc.render.filter_sampling = FilterSampling::Importance;
    let scene = candela_core::build::build(&desc).unwrap();
    let film = integrator::render(&scene, 0..spp, &AtomicBool::new(false), &|_| {}).film;
    Some(film.resolve())
}

#[test]
fn mitsuba_depth_one_shows_emitters_only_and_two_is_direct_light() {
    // Mitsuba's max_depth 1: only the light's own radiance (17, 12, 4) is visible.
    let Some(img) = render_at_depth("1", 4) else {
        return;
    };
    let lit = img.iter().filter(|v| v.max_element() > 0.0).count();
    assert!(lit > 0 && lit < img.len() / 50, "{lit} lit pixels");
    let brightest = img.iter().fold(Vec3::ZERO, |a, &b| a.max(b));
    assert!((brightest - Vec3::new(17.0, 12.0, 4.0)).abs().max_element() < 1e-3);
    // max_depth 2 is direct light only: the ceiling beside the downward-facing light gets
    // none (its top rows at columns 4..16 see the ceiling in front of the light); one
    // more bounce lights it.
    let ceiling = |img: &[Vec3]| -> f32 {
        (0..3)
            .flat_map(|y| (4..16).map(move |x| y * 64 + x))
            .map(|i| img[i].element_sum())
            .sum()
    };
    let direct = render_at_depth("2", 16).unwrap();
    assert_eq!(ceiling(&direct), 0.0);
    assert!(direct.iter().filter(|v| v.max_element() > 0.0).count() > img.len() / 2);
    let indirect = render_at_depth("3", 16).unwrap();
    assert!(ceiling(&indirect) > 0.1, "{}", ceiling(&indirect));
}
