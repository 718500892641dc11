//! The Sobol' sampler's two promises: within a pixel its samples are stratified, and
//! across pixels (and across requests of one pixel sample) they are independent uniform
//! numbers, like the independent sampler's.
//!
//! Stratification is exact, so its checks are counts: for 2ᵏ samples of one pixel, every
//! 1D request has exactly one point in each of the 2ᵏ intervals [j/2ᵏ, (j+1)/2ᵏ), and
//! every 2D request is a (0, k, 2)-net, exactly one point in every elementary interval of
//! area 2⁻ᵏ (all 2ᵃ × 2ᵇ grids with a + b = k). The independent sampler fails the same
//! check, so it can fail.
//!
//! Uniformity is statistical: 10⁶ pixels at one sample index give 10⁶ points, histogrammed
//! on 32 × 32 cells by the chi-square harness, α = 0.01 over all the chi-square tests of
//! this file with Šidák's correction. A pair of consecutive sample indices of one pixel is
//! *not* uniform on the square (the pair is stratified), and the same test rejects it.

use candela_core::sampler::{IndependentSampler, SobolSampler};
use candela_test_support::samplers::{
    chi2_over_pixels, draw, is_stratified, points, requests_are_uniform_across_pixels,
    two_requests_are_independent, Request, REQUESTS,
};
use glam::{UVec2, Vec2};

#[test]
fn every_request_of_2k_samples_is_stratified() {
    let mut checked = 0;
    for seed in [0u64, 1, 12345] {
        let mut s = SobolSampler::new(seed);
        for pixel in [UVec2::new(0, 0), UVec2::new(17, 3), UVec2::new(511, 511)] {
            for req in REQUESTS {
                let two_d = matches!(req, Request::TwoD { .. });
                for k in 0..=12u32 {
                    let n = 1u32 << k;
                    // The first 2ᵏ samples, and an aligned later block (a render of the
                    // sample range [3·2ᵏ, 4·2ᵏ)).
                    for start in [0, 3 * n] {
                        let p = points(&mut s, pixel, start..start + n, req);
                        assert!(
                            is_stratified(&p, two_d),
                            "seed {seed}, pixel {pixel}, {req:?}, samples {start}..{}",
                            start + n
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    eprintln!("{checked} sample sets stratified");
}

#[test]
fn a_sample_count_that_is_no_power_of_two_is_a_union_of_nets() {
    // 12 = 8 + 4: samples 0..8 are a net of 8 and samples 8..12 a net of 4 (see the
    // sampler's docs); 1000 = 512 + 256 + 128 + 64 + 32 + 8 likewise.
    let mut s = SobolSampler::new(9);
    for req in REQUESTS {
        let two_d = matches!(req, Request::TwoD { .. });
        for (n, pixel) in [(12u32, UVec2::new(5, 6)), (1000, UVec2::new(40, 2))] {
            let mut start = 0;
            for bit in (0..32).rev().filter(|b| n & (1 << b) != 0) {
                let p = points(&mut s, pixel, start..start + (1 << bit), req);
                assert!(
                    is_stratified(&p, two_d),
                    "{req:?}, n = {n}, block at {start}"
                );
                start += 1 << bit;
            }
        }
    }
}

#[test]
fn the_stratification_check_rejects_independent_samples() {
    // Independent points are a (0, k, 2)-net by chance with probability n!/nⁿ per split:
    // already 1.6·10⁻¹⁰ at n = 32 — the check above could not pass by luck.
    let mut s = IndependentSampler::new(0);
    for req in REQUESTS {
        let two_d = matches!(req, Request::TwoD { .. });
        let p = points(&mut s, UVec2::new(17, 3), 0..32, req);
        assert!(!is_stratified(&p, two_d), "{req:?}");
    }
}

/// Chi-square tests in this file, for the Šidák correction.
const CHI2_TESTS: usize = 6;

#[test]
fn across_pixels_every_request_is_uniform() {
    requests_are_uniform_across_pixels(SobolSampler::new(4), CHI2_TESTS);
}

#[test]
fn across_pixels_two_requests_are_independent() {
    two_requests_are_independent(SobolSampler::new(5), CHI2_TESTS);
}

#[test]
fn consecutive_samples_of_a_pixel_are_stratified_not_independent() {
    // Samples 2j and 2j+1 of one pixel fall in opposite halves of [0, 1): their pair is
    // far from uniform on the square, and the chi-square test sees it. The independent
    // sampler's pair is uniform.
    let req = Request::OneD { skip: 2 };
    let mut sobol = SobolSampler::new(6);
    let report = chi2_over_pixels(CHI2_TESTS, "Sobol', samples 6 and 7", |p| {
        Vec2::new(draw(&mut sobol, p, 6, req).x, draw(&mut sobol, p, 7, req).x)
    });
    eprintln!("Sobol' pair: p = {:.3e}", report.p_value);
    assert!(!report.passed(), "the stratified pair looked independent");
    let mut independent = IndependentSampler::new(6);
    let report = chi2_over_pixels(CHI2_TESTS, "independent, samples 6 and 7", |p| {
        Vec2::new(
            draw(&mut independent, p, 6, req).x,
            draw(&mut independent, p, 7, req).x,
        )
    });
    eprintln!("independent pair: p = {:.3}", report.p_value);
    report.assert_passed();
}
