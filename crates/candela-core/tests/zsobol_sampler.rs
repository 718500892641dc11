//! The blue-noise Sobol' sampler's promises (`ZSobolSampler`): each pixel's samples are
//! stratified as the Sobol' sampler's are, so are the samples of every aligned block of
//! pixels taken together, every number is uniform, two requests of a pixel sample are
//! independent, and so the per-pixel errors are blue noise: negatively correlated between
//! neighbours, with little power at low spatial frequencies.
//!
//! Stratification is exact, so its checks are counts (a (0, k, 2)-net has exactly one point
//! in every elementary interval of area 2⁻ᵏ); the Sobol' sampler, whose pixels are
//! independent, fails the block check, so it can fail. Uniformity is statistical:
//! chi-square on 32 × 32 cells of 10⁶ points, over pixels (one sample index, every pixel
//! of a 1000² image) and over seeds (one pixel sample, 10⁶ seeds), α = 0.01 over all the
//! chi-square tests of this file with Šidák's correction.

use candela_core::chi2::{sidak_alpha, ChiSquareTest};
use candela_core::sampler::{Sampler, SobolSampler, ZSobolSampler};
use candela_test_support::samplers::{
    draw, is_stratified, points, requests_are_uniform_across_pixels, two_requests_are_independent,
    Request, REQUESTS,
};
use candela_test_support::spectrum::low_frequency_power_ratio;
use glam::{UVec2, Vec2};

#[test]
fn each_pixels_samples_are_stratified() {
    let mut checked = 0;
    for k in 0..=8u32 {
        let spp = 1u32 << k;
        for seed in [0u64, 12345] {
            let mut s = ZSobolSampler::new(seed, spp, 64, 48);
            for pixel in [UVec2::new(0, 0), UVec2::new(17, 3), UVec2::new(63, 47)] {
                for req in REQUESTS {
                    let two_d = matches!(req, Request::TwoD { .. });
                    // The planned samples, and those of a later pass (epoch 3).
                    for start in [0, 3 * spp] {
                        let p = points(&mut s, pixel, start..start + spp, req);
                        assert!(
                            is_stratified(&p, two_d),
                            "spp {spp}, seed {seed}, pixel {pixel}, {req:?}, from {start}"
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    eprintln!("{checked} pixel sample sets stratified");
}

/// The points of request `req` of all planned samples of the `side` × `side` pixels at
/// `corner`.
fn block_points<S: Sampler>(
    s: &mut S,
    corner: UVec2,
    side: u32,
    spp: u32,
    req: Request,
) -> Vec<Vec2> {
    let mut out = Vec::new();
    for y in corner.y..corner.y + side {
        for x in corner.x..corner.x + side {
            out.extend(points(s, UVec2::new(x, y), 0..spp, req));
        }
    }
    out
}

#[test]
fn every_aligned_block_of_pixels_is_stratified_together() {
    // The point of the sampler: the 4ʲ·spp samples of an aligned 2ʲ × 2ʲ block of pixels
    // are one net, for every request (odd and even log₂ spp, a non-square image).
    for spp in [1u32, 2, 4, 8] {
        let mut s = ZSobolSampler::new(7, spp, 64, 40);
        for j in 0..=3u32 {
            let side = 1 << j;
            for corner in [
                UVec2::ZERO,
                UVec2::new(side, 0),
                UVec2::new(5 * side, 3 * side),
            ] {
                for req in REQUESTS {
                    let two_d = matches!(req, Request::TwoD { .. });
                    let p = block_points(&mut s, corner, side, spp, req);
                    assert!(
                        is_stratified(&p, two_d),
                        "spp {spp}, block {side}² at {corner}, {req:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn the_block_check_rejects_independent_pixels() {
    // The Sobol' sampler's pixels are independent: four of them at 4 spp are a net of 16
    // by chance with probability below 10⁻³ per request; all six requests, never.
    let mut s = SobolSampler::new(7);
    let stratified = REQUESTS
        .iter()
        .filter(|&&req| {
            let p = block_points(&mut s, UVec2::new(2, 2), 2, 4, req);
            is_stratified(&p, matches!(req, Request::TwoD { .. }))
        })
        .count();
    assert!(
        stratified < REQUESTS.len(),
        "independent pixels looked stratified"
    );
}

/// Whether no two of `points` share an elementary interval of area 2⁻ᵏ (1D: an interval
/// of length 2⁻ᵏ): a subset of a (0, k, 2)-net.
fn subset_of_a_net(points: &[Vec2], k: u32, two_d: bool) -> bool {
    let splits: Vec<(u32, u32)> = if two_d {
        (0..=k).map(|a| (a, k - a)).collect()
    } else {
        vec![(k, 0)]
    };
    splits.into_iter().all(|(a, b)| {
        let mut seen = std::collections::HashSet::new();
        points.iter().all(|p| {
            let ix = (p.x as f64 * (1u64 << a) as f64) as u64;
            let iy = (p.y as f64 * (1u64 << b) as f64) as u64;
            seen.insert((ix, iy))
        })
    })
}

#[test]
fn a_sample_count_that_is_no_power_of_two_is_part_of_a_net() {
    // n planned samples take n of the pixel's block of 2ᵏ ≥ n indices, in the scrambled
    // order of its digits: they are a subset of a 2ᵏ-net. Where the low digit is whole
    // they are also a union of nets: 12 samples are three quartets sharing the high
    // base-4 digit (aligned blocks of 4); 6 samples three pairs differing in the lowest
    // bit alone (k = 3 is odd). 3 of 4 and 5 of 8 are only part of a net.
    for (spp, k, group) in [(12u32, 4u32, 4u32), (6, 3, 2), (3, 2, 1), (5, 3, 1)] {
        let mut s = ZSobolSampler::new(9, spp, 32, 32);
        for pixel in [UVec2::new(5, 6), UVec2::new(31, 0)] {
            for req in REQUESTS {
                let two_d = matches!(req, Request::TwoD { .. });
                let all = points(&mut s, pixel, 0..spp, req);
                assert!(subset_of_a_net(&all, k, two_d), "spp {spp}, {req:?}");
                for chunk in all.chunks(group as usize) {
                    assert!(is_stratified(chunk, two_d), "spp {spp}, {req:?}");
                }
            }
        }
    }
}

#[test]
fn a_pixel_sample_depends_on_seed_pixel_and_index_alone() {
    // Two samplers of the same settings give the same numbers in any order of pixels;
    // another seed, pixel or index gives other numbers.
    let numbers = |s: &mut ZSobolSampler, pixel: UVec2, index: u32| -> Vec<f32> {
        s.start_pixel_sample(pixel, index);
        (0..12).map(|_| s.get_1d()).collect()
    };
    let mut a = ZSobolSampler::new(3, 16, 100, 50);
    let mut b = ZSobolSampler::new(3, 16, 100, 50);
    let want = numbers(&mut a, UVec2::new(40, 20), 5);
    numbers(&mut b, UVec2::new(99, 49), 15);
    assert_eq!(numbers(&mut b, UVec2::new(40, 20), 5), want);
    assert_ne!(numbers(&mut b, UVec2::new(41, 20), 5), want);
    assert_ne!(numbers(&mut b, UVec2::new(40, 20), 6), want);
    assert_ne!(
        numbers(
            &mut ZSobolSampler::new(4, 16, 100, 50),
            UVec2::new(40, 20),
            5
        ),
        want
    );
}

#[test]
fn deferred_and_skipped_requests_keep_the_later_ones_in_place() {
    let mut a = ZSobolSampler::new(3, 8, 16, 16);
    let mut b = a.clone();
    for index in 0..4 {
        a.start_pixel_sample(UVec2::new(5, 6), index);
        b.start_pixel_sample(UVec2::new(5, 6), index);
        assert_eq!(a.get_pixel_2d(), b.get_2d());
        let want = a.get_1d();
        let d = b.defer_1d();
        a.get_1d();
        b.skip_1d();
        assert_eq!(a.get_2d(), b.get_2d());
        assert_eq!(b.resolve_1d(d), want);
    }
}

#[test]
fn large_images_are_cut_into_tiles_of_their_own() {
    // At 2¹⁶ spp the extended index leaves 16 bits, 8 per axis: tiles of 256² pixels,
    // each a blue-noise set of its own, rescrambled by its position (pixels 256 apart
    // differ although their offsets in the tile are equal).
    let mut s = ZSobolSampler::new(1, 1 << 16, 1024, 1024);
    let mut numbers = |x: u32| {
        s.start_pixel_sample(UVec2::new(x, 7), 3);
        (s.get_2d(), s.get_1d())
    };
    assert_ne!(numbers(10), numbers(266));
    assert_eq!(numbers(10), numbers(10));
}

/// Chi-square tests in this file, for the Šidák correction.
const CHI2_TESTS: usize = 7;

#[test]
fn across_pixels_every_request_is_uniform() {
    requests_are_uniform_across_pixels(ZSobolSampler::new(4, 16, 1000, 1000), CHI2_TESTS);
}

#[test]
fn over_seeds_one_pixel_samples_numbers_are_uniform() {
    // The randomization itself: one pixel sample's request over 10⁶ seeds is uniform on
    // the square (across pixels the points are stratified, which a bias could hide in).
    let test = ChiSquareTest {
        alpha: sidak_alpha(0.01, CHI2_TESTS),
        ..Default::default()
    };
    for (pixel, index, req) in [
        (UVec2::new(3, 5), 2u32, Request::TwoD { skip: 0 }),
        (UVec2::new(60, 1), 13, Request::TwoD { skip: 3 }),
    ] {
        let mut seed = 0u64;
        let report = test.planar(
            &format!("{pixel} sample {index} {req:?} over seeds"),
            Vec2::ZERO,
            Vec2::ONE,
            |_| {
                seed += 1;
                Some(draw(
                    &mut ZSobolSampler::new(seed, 16, 64, 64),
                    pixel,
                    index,
                    req,
                ))
            },
            |_| 1.0,
        );
        eprintln!("{pixel}, sample {index}: p = {:.3}", report.p_value);
        report.assert_passed();
    }
}

#[test]
fn across_pixels_two_requests_are_independent() {
    two_requests_are_independent(ZSobolSampler::new(5, 16, 1000, 1000), CHI2_TESTS);
}

/// Per pixel of an `n` × `n` image, the error of the `spp`-sample estimate of a pixel
/// integral made of terms over separate requests, the kind of sum a path's contributions
/// make: an edge crossing the pixel (pixel position), a smooth light term (1D and 2D
/// requests). The exact integral is 0.5 + 1/3 + 1/4.
fn pixel_errors<S: Sampler>(s: &mut S, n: u32, spp: u32) -> Vec<f64> {
    let mut out = Vec::with_capacity((n * n) as usize);
    for y in 0..n {
        for x in 0..n {
            let mut sum = 0.0f64;
            for i in 0..spp {
                s.start_pixel_sample(UVec2::new(x, y), i);
                let p = s.get_pixel_2d();
                let edge = if p.x + 0.3 * p.y < 0.65 { 1.0 } else { 0.0 };
                let u = s.get_1d() as f64;
                let q = s.get_2d();
                sum += edge + u * u + (q.x * q.y) as f64;
            }
            out.push(sum / spp as f64 - (0.5 + 1.0 / 3.0 + 0.25));
        }
    }
    out
}

/// Pearson correlation of each pixel's error with that of the pixel `(dx, dy)` away.
fn neighbour_correlation(err: &[f64], n: usize, dx: usize, dy: usize) -> f64 {
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    let mean = err.iter().sum::<f64>() / err.len() as f64;
    for y in 0..n - dy {
        for x in 0..n - dx {
            let (a, b) = (err[y * n + x] - mean, err[(y + dy) * n + x + dx] - mean);
            (sab, saa, sbb) = (sab + a * b, saa + a * a, sbb + b * b);
        }
    }
    sab / (saa * sbb).sqrt()
}

#[test]
fn neighbouring_pixels_err_in_opposite_directions() {
    // 256² pixels at 4 spp. Independent pixels: correlation 0 ± 1/256 (one standard
    // error), bound 0.02 (5 of them). Blue noise: below 0 between neighbours (measured
    // −0.089 both ways: about −1/6 for the half of the pairs in one 2 × 2 block, as the
    // edge term's variance ∝ N^-1.5 predicts, less across blocks), bound −0.05 (more than
    // 10 standard errors of independent pixels); and 0 between pixels 16 apart (in one
    // 32² block at most, whose stratification spreads over 4096 samples).
    let n = 256;
    let blue = pixel_errors(&mut ZSobolSampler::new(11, 4, n, n), n, 4);
    let white = pixel_errors(&mut SobolSampler::new(11), n, 4);
    let n = n as usize;
    for (dx, dy) in [(1, 0), (0, 1)] {
        let (b, w) = (
            neighbour_correlation(&blue, n, dx, dy),
            neighbour_correlation(&white, n, dx, dy),
        );
        eprintln!("({dx}, {dy}): zsobol {b:.3}, sobol {w:.3}");
        assert!(b < -0.05, "zsobol's neighbours correlate {b}");
        assert!(w.abs() < 0.02, "sobol's neighbours correlate {w}");
    }
    let far = neighbour_correlation(&blue, n, 16, 0);
    eprintln!("(16, 0): zsobol {far:.3}");
    assert!(far.abs() < 0.02, "zsobol's pixels 16 apart correlate {far}");
}

#[test]
fn the_error_is_blue_noise() {
    // Power below 1/8 cycle per pixel over the mean power, 128² pixels at 4 and 16 spp:
    // white noise's is 1 ± 0.05 (about 400 independent powers below the cutoff), and the
    // Sobol' sampler's, whose pixels are independent, must stay above 0.7 (measured 0.99
    // and 0.91). Blue noise's was measured at 0.37 and 0.28 (seed 3; on 64², 0.37 and
    // 0.26, and with another hash picking the digit permutations 0.44 and 0.21, which is
    // how far one realization moves it): the bound 0.5 is clear of all of them, and far
    // below white noise's. Not lower: the edge term, a discontinuity, is
    // stratified less well than smooth terms (variance ∝ N^-1.5 rather than N^-3), and it
    // rules this integrand's error as edges rule a render's.
    for spp in [4u32, 16] {
        let n = 128;
        let ratio = |err: Vec<f64>| low_frequency_power_ratio(&err, n as usize, 0.125);
        let blue = ratio(pixel_errors(&mut ZSobolSampler::new(3, spp, n, n), n, spp));
        let white = ratio(pixel_errors(&mut SobolSampler::new(3), n, spp));
        eprintln!("{spp} spp: low-frequency power ratio zsobol {blue:.3}, sobol {white:.3}");
        assert!(blue < 0.5, "{spp} spp: zsobol's error is not blue ({blue})");
        assert!(white > 0.7, "{spp} spp: sobol's error looks blue ({white})");
    }
}
