//! What the sampler tests share: drawing one request of one pixel sample, and the
//! chi-square test of points over many pixels.

#![allow(dead_code)]

use candela_core::chi2::{sidak_alpha, ChiSquareTest};
use candela_core::sampler::Sampler;
use glam::{UVec2, Vec2};

/// One request of a pixel sample: `skip` 2D requests first, then a 1D or 2D one.
#[derive(Clone, Copy, Debug)]
pub enum Request {
    OneD { skip: u32 },
    TwoD { skip: u32 },
}

pub fn draw<S: Sampler>(s: &mut S, pixel: UVec2, index: u32, req: Request) -> Vec2 {
    s.start_pixel_sample(pixel, index);
    match req {
        Request::OneD { skip } => {
            (0..skip).for_each(|_| {
                s.get_2d();
            });
            Vec2::new(s.get_1d(), 0.0)
        }
        Request::TwoD { skip } => {
            (0..skip).for_each(|_| {
                s.get_2d();
            });
            s.get_2d()
        }
    }
}

pub fn points<S: Sampler>(
    s: &mut S,
    pixel: UVec2,
    indices: std::ops::Range<u32>,
    req: Request,
) -> Vec<Vec2> {
    indices.map(|i| draw(s, pixel, i, req)).collect()
}

/// Points over 10⁶ pixels, one per pixel (pixel k at (k mod 1000, k div 1000)),
/// histogrammed on the unit square; `tests` chi-square tests in the calling file share
/// α = 0.01 by Šidák's correction.
pub fn chi2_over_pixels(
    tests: usize,
    name: &str,
    mut point: impl FnMut(UVec2) -> Vec2,
) -> candela_core::chi2::Chi2Report {
    let test = ChiSquareTest {
        alpha: sidak_alpha(0.01, tests),
        ..Default::default()
    };
    let mut k = 0u32;
    test.planar(
        name,
        Vec2::ZERO,
        Vec2::ONE,
        |_| {
            let pixel = UVec2::new(k % 1000, k / 1000);
            k += 1;
            Some(point(pixel))
        },
        |_| 1.0,
    )
}

/// Checks the first coordinate of two different requests of one pixel sample (and a 1D
/// request against a 2D one) over pixels: padding must leave no correlation between them.
pub fn two_requests_are_independent<S: Sampler>(mut s: S, tests: usize) {
    for (a, b) in [(0u32, 1u32), (2, 9)] {
        let report = chi2_over_pixels(tests, &format!("requests {a} and {b}"), |p| {
            let x = draw(&mut s, p, 3, Request::TwoD { skip: a }).x;
            let y = draw(&mut s, p, 3, Request::OneD { skip: b }).x;
            Vec2::new(x, y)
        });
        eprintln!("requests {a}, {b}: p = {:.3}", report.p_value);
        report.assert_passed();
    }
}
