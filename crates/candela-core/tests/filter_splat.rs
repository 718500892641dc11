//! Splatting wide pixel filters (`FilterSampling::Splat`) against filter importance
//! sampling (`FilterSampling::Importance`): the same expected image, less noise, and the
//! same pixels whatever the thread count.
//!
//! Agreement method (as `mis_consistency.rs`): each mode renders a 64×64 scene with sharp
//! emitter edges K = 16 times with different seeds at 16 spp. For each 8×8 tile the tile's
//! mean luminance in each render is one observation; Welch's t-test compares the K
//! observations of splatting with those of importance sampling. α = 0.001 per tile; with
//! 64 tiles per comparison false rejections are Binomial(64, 0.001), P(X ≥ 3) ≈ 4·10⁻⁵,
//! so up to 2 failing tiles are allowed. A 5 % brighter light fails far more tiles, which
//! shows the test can fail.

use std::sync::atomic::AtomicBool;

use candela_core::desc::*;
use candela_core::film::Film;
use candela_core::integrator::render;
use candela_core::math::luminance;
use glam::{Mat4, Vec3};

use candela_test_support::tiles;

const RES: u32 = 64;
const TILE: u32 = 8;
const RENDERS: u64 = 16;
const SPP: u32 = 16;
const ALPHA: f64 = 0.001;
const ALLOWED_FAILURES: usize = 2;

const GAUSSIAN: PixelFilterDesc = PixelFilterDesc::Gaussian {
    stddev: 0.5,
    radius: 2.0,
};
const TENT: PixelFilterDesc = PixelFilterDesc::Tent { radius: 1.5 };

fn shape(geometry: GeometryDesc, material: &str, emission: Option<Vec3>, t: Mat4) -> ShapeDesc {
    ShapeDesc::new(geometry, material)
        .transformed(t)
        .with_emission(emission)
}

/// Small bright spheres seen directly (edges a pixel sharp) over a diffuse sphere and
/// floor they light, under a dim sky (so that no tile is black, where Welch's test would
/// compare rare events); all light scaled by `light_scale`.
fn scene(filter: PixelFilterDesc, sampling: FilterSampling, light_scale: f32) -> SceneDesc {
    let mut desc = SceneDesc {
        render: RenderSettings {
            width: RES,
            height: RES,
            spp: SPP,
            max_depth: 4,
            filter,
            filter_sampling: sampling,
            ..Default::default()
        },
        environment: Some(EnvironmentDesc {
            map: EnvironmentMapDesc::Constant(Vec3::splat(0.2 * light_scale)),
            ..Default::default()
        }),
        ..Default::default()
    };
    desc.materials
        .push(MaterialDesc::diffuse("white", Vec3::new(0.8, 0.6, 0.4)));
    let sphere = |center, radius| GeometryDesc::Sphere { center, radius };
    desc.shapes.push(shape(
        sphere(Vec3::new(0.0, -0.3, 0.0), 0.9),
        "white",
        None,
        Mat4::IDENTITY,
    ));
    desc.shapes.push(shape(
        GeometryDesc::Rectangle,
        "white",
        None,
        Mat4::from_translation(Vec3::new(0.0, -1.2, 0.0))
            * Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2)
            * Mat4::from_scale(Vec3::splat(4.0)),
    ));
    for (i, le) in [Vec3::new(16.0, 12.0, 6.0), Vec3::new(4.0, 8.0, 18.0)]
        .into_iter()
        .enumerate()
    {
        let x = if i == 0 { -1.2 } else { 1.1 };
        desc.shapes.push(shape(
            sphere(Vec3::new(x, 0.9, 0.4), 0.25),
            "white",
            Some(le * light_scale),
            Mat4::IDENTITY,
        ));
    }
    desc
}

fn render_film(desc: &SceneDesc) -> Film {
    let scene = candela_core::build::build(desc).expect("scene builds");
    render(&scene, 0..desc.render.spp, &AtomicBool::new(false), &|_| {}).film
}

/// Per tile, the tile's mean luminance in each of the independent renders.
fn tile_means(
    filter: PixelFilterDesc,
    sampling: FilterSampling,
    light_scale: f32,
) -> Vec<Vec<f64>> {
    tiles::tile_means(RENDERS, RES, TILE, |k| {
        let mut desc = scene(filter, sampling, light_scale);
        desc.render.seed = 100 + k;
        render_film(&desc).resolve()
    })
}

/// Tiles whose Welch test rejects equality at [`ALPHA`].
fn failing_tiles(a: &[Vec<f64>], b: &[Vec<f64>]) -> Vec<(usize, f64)> {
    tiles::failing_tiles(a, b, ALPHA)
}

#[test]
fn splatting_and_importance_sampling_agree() {
    for (name, filter) in [("gaussian", GAUSSIAN), ("tent r=1.5", TENT)] {
        let importance = tile_means(filter, FilterSampling::Importance, 1.0);
        let splat = tile_means(filter, FilterSampling::Splat, 1.0);
        let failing = failing_tiles(&splat, &importance);
        eprintln!("{name}: {} tiles fail: {failing:?}", failing.len());
        assert!(
            failing.len() <= ALLOWED_FAILURES,
            "{name}: splatting differs from importance sampling in {} tiles: {failing:?}",
            failing.len()
        );
        if name == "gaussian" {
            // Power: a 5 % brighter light must be detected.
            let brighter = tile_means(filter, FilterSampling::Splat, 1.05);
            let failing = failing_tiles(&brighter, &importance);
            eprintln!("5 % brighter: {} tiles fail", failing.len());
            assert!(failing.len() > 10, "a 5 % bias failed only {failing:?}");
        }
    }
}

/// Splatting spreads each sample over the pixels under the filter, so a pixel averages
/// more samples: at equal spp, the per-pixel variance over seeds must be well below
/// importance sampling's (Mitsuba's Gaussian covers ≈ 3 pixels' worth of weight; the
/// bound 0.7 leaves room for the correlation between neighbours and for noise in the
/// variance estimates, each from 16 renders of 4096 pixels).
#[test]
fn splatting_lowers_the_noise_at_equal_spp() {
    let variance = |sampling| {
        let imgs: Vec<Vec<Vec3>> = (0..RENDERS)
            .map(|k| {
                let mut desc = scene(GAUSSIAN, sampling, 1.0);
                desc.render.seed = 200 + k;
                render_film(&desc).resolve()
            })
            .collect();
        let n = RENDERS as f64;
        (0..imgs[0].len())
            .map(|i| {
                let l: Vec<f64> = imgs.iter().map(|m| luminance(m[i]) as f64).collect();
                let mean = l.iter().sum::<f64>() / n;
                l.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)
            })
            .sum::<f64>()
    };
    let ratio = variance(FilterSampling::Splat) / variance(FilterSampling::Importance);
    eprintln!("splat / importance variance: {ratio:.3}");
    assert!(
        ratio < 0.7,
        "splatting's variance is {ratio} of importance's"
    );
}

/// The same pixels, bit for bit, with one thread and with three.
#[test]
fn splatting_is_independent_of_the_thread_count() {
    for filter in [GAUSSIAN, TENT] {
        let mut desc = scene(filter, FilterSampling::Splat, 1.0);
        desc.render.spp = 20;
        let with = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            pool.install(|| render_film(&desc))
        };
        let one = with(1);
        assert_eq!(one.total_samples(), (RES * RES * 20) as u64);
        assert!(one == with(3), "{filter:?}: 1 and 3 threads differ");
    }
}

/// A scene of one constant radiance resolves to it in every pixel, edges and corners
/// included: every pixel's weights are normalised.
#[test]
fn splatting_normalises_every_pixel() {
    let c = Vec3::new(0.25, 1.0, 3.0);
    for filter in [GAUSSIAN, TENT] {
        let desc = SceneDesc {
            render: RenderSettings {
                width: 13,
                height: 7,
                spp: 5,
                filter,
                ..Default::default()
            },
            environment: Some(EnvironmentDesc {
                map: EnvironmentMapDesc::Constant(c),
                ..Default::default()
            }),
            ..Default::default()
        };
        for v in render_film(&desc).resolve() {
            assert!(
                (v - c).abs().max_element() < 1e-5 * 3.0,
                "{filter:?}: {v} ≠ {c}"
            );
        }
    }
}

/// The box filter renders the same pixels with either setting.
#[test]
fn box_filter_ignores_the_setting() {
    let mut a = scene(PixelFilterDesc::Box, FilterSampling::Splat, 1.0);
    a.render.spp = 4;
    let mut b = a.clone();
    b.render.filter_sampling = FilterSampling::Importance;
    assert!(render_film(&a) == render_film(&b));
}
