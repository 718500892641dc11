//! The first-bounce hybrid's promises (`SobolCmjSampler`): the first bounce's BSDF
//! direction of a pixel's planned samples is a multi-jittered pattern, every other request
//! is the Sobol' sampler's number, and every number is uniform and reproducible.
//!
//! Stratification is exact, so its checks are counts: for n = m × q planned samples of one
//! pixel (m the largest divisor of n not above √n), the first direction has exactly one
//! point in each cell of the m × q grid and one in each of the n columns and n rows of
//! width 1/n, at square and non-square n, through a pinhole and a thin lens. Independent
//! points fail the same check (with probability 1 − 4·10⁻¹⁵ at n = 36), so it can fail.
//!
//! Uniformity is statistical: 10⁶ pixels at one sample index give 10⁶ points, histogrammed
//! on 32 × 32 cells by the chi-square harness, α = 0.01 over all the chi-square tests of
//! this file with Šidák's correction. A pair of sample indices of one pixel is *not*
//! uniform on the square (the pair is stratified), and the same test rejects it.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use candela_core::build::build;
use candela_core::desc::*;
use candela_core::integrator::render;
use candela_core::sampler::{
    first_direction_dimension, IndependentSampler, Sampler, SobolCmjSampler, SobolSampler,
};
use candela_test_support::samplers::{chi2_over_pixels, one_per_cell, strata, Request};
use glam::{UVec2, Vec2, Vec3};

/// The first bounce's BSDF direction of a pixel sample, reached through the requests the
/// integrator takes before it (pixel, lens, light pick, light point, deferred lobe).
fn first_direction<S: Sampler>(s: &mut S, pixel: UVec2, index: u32, lens: bool) -> Vec2 {
    s.start_pixel_sample(pixel, index);
    s.get_pixel_2d();
    if lens {
        s.get_2d();
    }
    s.get_1d();
    s.get_2d();
    let _ = s.defer_1d();
    s.get_2d()
}

fn first_directions<S: Sampler>(
    s: &mut S,
    pixel: UVec2,
    indices: std::ops::Range<u32>,
    lens: bool,
) -> Vec<Vec2> {
    indices
        .map(|i| first_direction(s, pixel, i, lens))
        .collect()
}

const PIXELS: [UVec2; 3] = [UVec2::new(0, 0), UVec2::new(17, 3), UVec2::new(511, 511)];

#[test]
fn the_first_direction_is_dimension_6_or_8() {
    // The integrator's order (sampler module docs): pixel 2, lens 2 (thin lens only),
    // light pick 1, light point 2, lobe 1.
    assert_eq!(first_direction_dimension(false), 6);
    assert_eq!(first_direction_dimension(true), 8);
}

#[test]
fn the_first_direction_of_the_planned_samples_is_multi_jittered() {
    let mut checked = 0;
    for seed in [0u64, 1, 12345] {
        for n in [1u32, 2, 7, 12, 16, 36, 64, 100, 256, 1000] {
            for lens in [false, true] {
                let mut s = SobolCmjSampler::new(seed, n, lens);
                for pixel in PIXELS {
                    let p = first_directions(&mut s, pixel, 0..n, lens);
                    assert!(
                        one_per_cell(&p, &strata(n, Request::TwoD { skip: 0 })),
                        "seed {seed}, n {n}, lens {lens}, pixel {pixel}"
                    );
                    checked += 1;
                }
            }
        }
    }
    eprintln!("{checked} patterns stratified");
}

#[test]
fn the_stratification_check_rejects_independent_samples() {
    // n independent points fill the n columns with probability n!/nⁿ: 4·10⁻¹⁵ at n = 36.
    let mut s = IndependentSampler::new(0);
    for n in [36, 64, 12] {
        let p = first_directions(&mut s, UVec2::new(17, 3), 0..n, false);
        assert!(
            !one_per_cell(&p, &strata(n, Request::TwoD { skip: 0 })),
            "n {n}"
        );
    }
}

/// Every request of a pixel sample in the integrator's order, as numbers: what the
/// hybrid must share with the Sobol' sampler outside its one request.
fn all_requests<S: Sampler>(s: &mut S, pixel: UVec2, index: u32, lens: bool) -> Vec<f32> {
    s.start_pixel_sample(pixel, index);
    let mut v = s.get_pixel_2d().to_array().to_vec();
    if lens {
        v.extend(s.get_2d().to_array());
    }
    for _ in 0..8 {
        v.push(s.get_1d());
        v.extend(s.get_2d().to_array());
        let lobe = s.defer_1d();
        v.push(s.resolve_1d(lobe));
        v.extend(s.get_2d().to_array());
        v.push(s.get_1d());
    }
    v
}

#[test]
fn every_other_request_is_the_sobol_samplers() {
    for lens in [false, true] {
        let first = first_direction_dimension(lens) as usize;
        let (mut hybrid, mut sobol) = (SobolCmjSampler::new(9, 16, lens), SobolSampler::new(9));
        for pixel in PIXELS {
            for index in [0, 5, 15] {
                let mut a = all_requests(&mut hybrid, pixel, index, lens);
                let mut b = all_requests(&mut sobol, pixel, index, lens);
                // Number k of the list is dimension k's.
                assert_ne!(a[first..first + 2], b[first..first + 2]);
                a.drain(first..first + 2);
                b.drain(first..first + 2);
                assert_eq!(a, b, "lens {lens}, pixel {pixel}, index {index}");
            }
        }
    }
}

#[test]
fn past_the_planned_count_the_first_direction_is_the_sobol_samplers() {
    // A render extended by more passes: indices n.. take the Sobol' point, so an aligned
    // block of 2ᵏ of them is a (0, k, 2)-net (checked in sobol_sampler.rs).
    let (mut hybrid, mut sobol) = (SobolCmjSampler::new(4, 16, false), SobolSampler::new(4));
    for index in 16..64 {
        for pixel in PIXELS {
            assert_eq!(
                first_direction(&mut hybrid, pixel, index, false),
                first_direction(&mut sobol, pixel, index, false)
            );
        }
    }
}

#[test]
fn a_pixel_sample_depends_on_seed_pixel_and_index_alone() {
    // Determinism: the same (seed, pixel, index) gives the same numbers whatever was drawn
    // before, in any order (as the renderer's threads do); another seed, pixel or index
    // gives another first direction.
    let (mut a, mut b) = (
        SobolCmjSampler::new(7, 64, false),
        SobolCmjSampler::new(7, 64, false),
    );
    let want = all_requests(&mut a, UVec2::new(3, 4), 5, false);
    for (pixel, index) in [(UVec2::new(9, 9), 70), (UVec2::new(3, 4), 6)] {
        all_requests(&mut b, pixel, index, false);
    }
    assert_eq!(all_requests(&mut b, UVec2::new(3, 4), 5, false), want);
    let dir = |s: &mut SobolCmjSampler, pixel, index| first_direction(s, pixel, index, false);
    let d = dir(&mut a, UVec2::new(3, 4), 5);
    assert_ne!(dir(&mut b, UVec2::new(3, 4), 6), d);
    assert_ne!(dir(&mut b, UVec2::new(4, 3), 5), d);
    assert_ne!(
        dir(&mut SobolCmjSampler::new(8, 64, false), UVec2::new(3, 4), 5),
        d
    );
}

/// Chi-square tests in this file, for the Šidák correction.
const CHI2_TESTS: usize = 7;

#[test]
fn across_pixels_the_first_direction_is_uniform() {
    for (n, index, lens) in [
        (64u32, 0u32, false),
        (64, 37, true),
        (12, 11, false),
        (36, 50, false),
    ] {
        let mut s = SobolCmjSampler::new(4, n, lens);
        let name = format!("n {n}, sample {index}, lens {lens}");
        let report = chi2_over_pixels(CHI2_TESTS, &name, |p| {
            first_direction(&mut s, p, index, lens)
        });
        eprintln!("{name}: p = {:.3}", report.p_value);
        report.assert_passed();
    }
}

#[test]
fn across_pixels_the_first_direction_is_independent_of_the_other_requests() {
    // Its coordinates against the pixel position's and the light point's.
    let mut s = SobolCmjSampler::new(5, 16, false);
    for (name, other) in [("pixel x", 0usize), ("light point y", 4)] {
        let report = chi2_over_pixels(CHI2_TESTS, name, |p| {
            let v = all_requests(&mut s, p, 3, false);
            Vec2::new(v[6 + (other == 0) as usize], v[other])
        });
        eprintln!("first direction against {name}: p = {:.3}", report.p_value);
        report.assert_passed();
    }
}

#[test]
fn two_samples_of_a_pixel_are_stratified_not_independent() {
    // With n = 2 the first directions of samples 0 and 1 fall in opposite halves of
    // [0, 1) in x: their pair is far from uniform on the square, and the test sees it.
    let mut s = SobolCmjSampler::new(6, 2, false);
    let report = chi2_over_pixels(CHI2_TESTS, "samples 0 and 1 of 2", |p| {
        let a = first_direction(&mut s, p, 0, false);
        Vec2::new(a.x, first_direction(&mut s, p, 1, false).x)
    });
    eprintln!("pair: p = {:.3e}", report.p_value);
    assert!(!report.passed(), "the stratified pair looked independent");
}

/// A diffuse floor under a square lamp, seen from above at an angle.
fn lamp_over_floor(lens: bool) -> SceneDesc {
    let quad = |c: [[f32; 3]; 4]| {
        GeometryDesc::Mesh(Arc::new(MeshDesc {
            positions: c.iter().map(|&p| Vec3::from_array(p)).collect(),
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        }))
    };
    let mut desc = SceneDesc {
        camera: CameraDesc {
            position: Vec3::new(0.0, 2.0, 3.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 50.0,
            lens: lens.then(|| LensDesc {
                focus: FocusDesc::LookAt,
                size: ApertureSizeDesc::FNumber(0.5),
                aperture: ApertureDesc::default(),
            }),
            span: Span::code(),
            ..Default::default()
        },
        render: RenderSettings {
            width: 24,
            height: 16,
            spp: 16,
            sampler: SamplerKind::SobolCmj,
            ..Default::default()
        },
        ..Default::default()
    };
    desc.materials
        .push(MaterialDesc::diffuse("white", Vec3::splat(0.7)));
    for (corners, emission) in [
        (
            [
                [-2.0, 0.0, -2.0],
                [-2.0, 0.0, 2.0],
                [2.0, 0.0, 2.0],
                [2.0, 0.0, -2.0],
            ],
            None,
        ),
        (
            [
                [-0.5, 1.5, -0.5],
                [0.5, 1.5, -0.5],
                [0.5, 1.5, 0.5],
                [-0.5, 1.5, 0.5],
            ],
            Some(Vec3::splat(5.0)),
        ),
    ] {
        desc.shapes
            .push(ShapeDesc::new(quad(corners), "white").with_emission(emission));
    }
    desc
}

#[test]
fn renders_do_not_depend_on_threads_and_split_ranges_add_up() {
    for lens in [false, true] {
        let scene = build(&lamp_over_floor(lens)).expect("scene builds");
        let cancel = AtomicBool::new(false);
        let run = |threads: usize, range: std::ops::Range<u32>| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| render(&scene, range, &cancel, &|_| {}).film)
        };
        let whole = run(1, 0..16);
        assert_eq!(whole.resolve(), run(2, 0..16).resolve(), "lens {lens}");
        // Two processes rendering halves of the planned samples: the same pattern.
        let mut halves = run(2, 0..8);
        halves.merge(&run(1, 8..16));
        assert_eq!(whole.resolve(), halves.resolve(), "lens {lens}");
        // The hook takes effect: plain Sobol' renders another image.
        let mut desc = lamp_over_floor(lens);
        desc.render.sampler = SamplerKind::Sobol;
        let sobol = build(&desc).unwrap();
        let plain = render(&sobol, 0..16, &cancel, &|_| {}).film;
        assert_ne!(whole.resolve(), plain.resolve(), "lens {lens}");
    }
}

/// One request as the integrator makes it: its kind and its first dimension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Event {
    Pixel(u32),
    OneD(u32),
    Skip(u32),
    TwoD(u32),
    Defer(u32),
}

/// Independent numbers, with every pixel sample's requests logged (shared by the clones
/// the render makes per work item).
#[derive(Clone)]
struct Recorder {
    inner: IndependentSampler,
    dimension: u32,
    /// The log's entry of this clone's current pixel sample: the render loop keeps a
    /// clone a sample of a camera packet, whose requests interleave in time.
    entry: usize,
    log: Arc<std::sync::Mutex<Vec<Vec<Event>>>>,
}

impl Recorder {
    fn push(&mut self, event: fn(u32) -> Event, width: u32) {
        let mut log = self.log.lock().unwrap();
        log[self.entry].push(event(self.dimension));
        self.dimension += width;
    }
}

impl Sampler for Recorder {
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        self.inner.start_pixel_sample(pixel, index);
        self.dimension = 0;
        let mut log = self.log.lock().unwrap();
        self.entry = log.len();
        log.push(Vec::new());
    }
    fn get_1d(&mut self) -> f32 {
        self.push(Event::OneD, 1);
        self.inner.get_1d()
    }
    fn get_2d(&mut self) -> Vec2 {
        self.push(Event::TwoD, 2);
        self.inner.get_2d()
    }
    fn skip_1d(&mut self) {
        self.push(Event::Skip, 1);
        self.inner.skip_1d();
    }
    fn get_pixel_2d(&mut self) -> Vec2 {
        self.push(Event::Pixel, 2);
        self.inner.get_2d()
    }
    type Deferred1d = f32;
    fn defer_1d(&mut self) -> f32 {
        self.push(Event::Defer, 1);
        self.inner.get_1d()
    }
    fn resolve_1d(&self, u: f32) -> f32 {
        u
    }
}

#[test]
fn the_integrator_takes_the_first_direction_at_that_dimension() {
    // The hybrid relies on the integrator's order of requests: pixel, lens, then the first
    // bounce's light pick (skipped: one light), light point, lobe, direction.
    for lens in [false, true] {
        let scene = build(&lamp_over_floor(lens)).unwrap();
        let log = Arc::new(std::sync::Mutex::new(Vec::new()));
        let recorder = Recorder {
            inner: IndependentSampler::new(1),
            dimension: 0,
            entry: 0,
            log: log.clone(),
        };
        let cancel = AtomicBool::new(false);
        // One worker: each clone of the recorder appends to its pixel sample's entry,
        // which two threads would still log in an order of their own.
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        pool.install(|| {
            candela_core::integrator::render_with(&scene, recorder, 0..2, &cancel, &|_| {})
        });
        let d = first_direction_dimension(lens);
        let mut want = vec![Event::Pixel(0)];
        if lens {
            want.push(Event::TwoD(2));
        }
        want.extend([Event::Skip(d - 4), Event::TwoD(d - 3), Event::Defer(d - 1)]);
        want.push(Event::TwoD(d));
        let log = log.lock().unwrap();
        assert_eq!(log.len(), 24 * 16 * 2);
        for events in log.iter() {
            assert_eq!(events[..want.len()], want[..], "lens {lens}");
        }
    }
}
