//! The correlated multi-jittered sampler's promises, checked as the Sobol' sampler's are
//! (`sobol_sampler.rs`): within a pixel its `n` samples are stratified, and across pixels
//! (and across requests of one pixel sample) they are independent uniform numbers.
//!
//! Stratification is exact, so its checks are counts: for n = m × q samples of one pixel
//! (m the largest divisor of n not above √n), every 1D request has exactly one number in
//! each of the n intervals [j/n, (j+1)/n); every 2D request has exactly one point in each
//! cell of the m × q grid, and one in each of the n columns and n rows of width 1/n. The
//! same holds for each later block of n sample indices. The independent sampler fails the
//! check, so it can fail.
//!
//! Uniformity is statistical: 10⁶ pixels at one sample index give 10⁶ points, histogrammed
//! on 32 × 32 cells by the chi-square harness, α = 0.01 over all the chi-square tests of
//! this file with Šidák's correction. A pair of sample indices of one pixel is *not*
//! uniform on the square (the pair is stratified), and the same test rejects it.

use candela_core::sampler::{CmjSampler, IndependentSampler, Sampler};
use candela_test_support::samplers::{
    chi2_over_pixels, draw, one_per_cell, points, strata, two_requests_are_independent, Request,
    REQUESTS,
};
use glam::{UVec2, Vec2};

#[test]
fn every_request_of_a_pixel_is_stratified() {
    let mut checked = 0;
    for seed in [0u64, 1, 12345] {
        for n in [1u32, 2, 7, 12, 16, 36, 64, 100, 256, 1000] {
            let mut s = CmjSampler::new(seed, n);
            for pixel in [UVec2::new(0, 0), UVec2::new(17, 3), UVec2::new(511, 511)] {
                for req in REQUESTS {
                    // The pattern, and the next block of n indices (a render extended by
                    // more passes).
                    for start in [0, n] {
                        let p = points(&mut s, pixel, start..start + n, req);
                        assert!(
                            one_per_cell(&p, &strata(n, req)),
                            "seed {seed}, n {n}, pixel {pixel}, {req:?}, samples {start}.."
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
fn the_stratification_check_rejects_independent_samples() {
    // n independent points fill the n strata of one grid with probability n!/nⁿ: at
    // n = 36 that is 4·10⁻¹⁵, so the check above could not pass by luck.
    let mut s = IndependentSampler::new(0);
    for req in REQUESTS {
        let p = points(&mut s, UVec2::new(17, 3), 0..36, req);
        assert!(!one_per_cell(&p, &strata(36, req)), "{req:?}");
    }
}

#[test]
fn a_pixel_sample_depends_on_seed_pixel_and_index_alone() {
    // Determinism: the same (seed, pixel, index) gives the same numbers whatever was
    // drawn before, in any order (as the renderer's threads do); another seed, pixel or
    // index gives others.
    let take = |s: &mut CmjSampler, pixel: UVec2, index: u32| -> Vec<f32> {
        s.start_pixel_sample(pixel, index);
        (0..6).flat_map(|_| [s.get_1d(), s.get_2d().x]).collect()
    };
    let (mut a, mut b) = (CmjSampler::new(7, 64), CmjSampler::new(7, 64));
    let want = take(&mut a, UVec2::new(3, 4), 5);
    for (pixel, index) in [(UVec2::new(9, 9), 70), (UVec2::new(3, 4), 6)] {
        take(&mut b, pixel, index);
    }
    assert_eq!(take(&mut b, UVec2::new(3, 4), 5), want);
    assert_ne!(take(&mut b, UVec2::new(3, 4), 6), want);
    assert_ne!(take(&mut b, UVec2::new(4, 3), 5), want);
    assert_ne!(take(&mut CmjSampler::new(8, 64), UVec2::new(3, 4), 5), want);
}

/// Chi-square tests in this file, for the Šidák correction.
const CHI2_TESTS: usize = 7;

#[test]
fn across_pixels_every_request_is_uniform() {
    for (n, index, req) in [
        (64u32, 0u32, Request::TwoD { skip: 0 }),
        (64, 5, Request::TwoD { skip: 7 }),
        (36, 35, Request::OneD { skip: 2 }),
        (12, 77, Request::TwoD { skip: 40 }),
    ] {
        let mut s = CmjSampler::new(4, n);
        let name = format!("n {n}, sample {index}, {req:?}");
        let report = chi2_over_pixels(CHI2_TESTS, &name, |p| match req {
            Request::OneD { .. } => {
                let x = draw(&mut s, p, index, req).x;
                Vec2::new(x, draw(&mut s, p, index, Request::OneD { skip: 3 }).x)
            }
            Request::TwoD { .. } => draw(&mut s, p, index, req),
        });
        eprintln!("{name}: p = {:.3}", report.p_value);
        report.assert_passed();
    }
}

#[test]
fn across_pixels_two_requests_are_independent() {
    two_requests_are_independent(CmjSampler::new(5, 16), CHI2_TESTS);
}

#[test]
fn two_samples_of_a_pixel_are_stratified_not_independent() {
    // With n = 2 samples 0 and 1 of one pixel fall in opposite halves of [0, 1): their
    // pair is far from uniform on the square, and the chi-square test sees it.
    let req = Request::OneD { skip: 2 };
    let mut s = CmjSampler::new(6, 2);
    let report = chi2_over_pixels(CHI2_TESTS, "CMJ, samples 0 and 1 of 2", |p| {
        Vec2::new(draw(&mut s, p, 0, req).x, draw(&mut s, p, 1, req).x)
    });
    eprintln!("CMJ pair: p = {:.3e}", report.p_value);
    assert!(!report.passed(), "the stratified pair looked independent");
}
