//! What the sampler tests share: drawing one request of one pixel sample, and the
//! chi-square test of points over many pixels.

use candela_core::chi2::{sidak_alpha, ChiSquareTest};
use candela_core::sampler::Sampler;
use glam::{UVec2, Vec2};

/// One request of a pixel sample: `skip` 2D requests first, then a 1D or 2D one.
#[derive(Clone, Copy, Debug)]
pub enum Request {
    OneD { skip: u32 },
    TwoD { skip: u32 },
}

/// Requests the sampler tests check: the first 1D and 2D ones, a few after them, and one
/// far beyond the dimensions a Sobol' table holds (where samplers pad by hashing).
pub const REQUESTS: [Request; 6] = [
    Request::TwoD { skip: 0 },
    Request::OneD { skip: 0 },
    Request::TwoD { skip: 1 },
    Request::OneD { skip: 3 },
    Request::TwoD { skip: 7 },
    Request::TwoD { skip: 40 },
];

/// The numbers of request `req` of sample `index` of `pixel` (a 1D request in x, y zero).
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

/// [`draw`] for each sample index in `indices`.
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

/// Checks three requests (the first 2D one, a later one, one past a Sobol' table's
/// dimensions) of three sample indices, each over pixels: uniform on the square.
pub fn requests_are_uniform_across_pixels<S: Sampler>(mut s: S, tests: usize) {
    for (index, req) in [
        (0u32, Request::TwoD { skip: 0 }),
        (5, Request::TwoD { skip: 7 }),
        (77, Request::TwoD { skip: 40 }),
    ] {
        let report = chi2_over_pixels(tests, &format!("sample {index}, {req:?}"), |p| {
            draw(&mut s, p, index, req)
        });
        eprintln!("sample {index}, {req:?}: p = {:.3}", report.p_value);
        report.assert_passed();
    }
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

/// Whether each of the `grids` (columns × rows) has exactly one point in every cell (the
/// check of a multi-jittered pattern's strata).
pub fn one_per_cell(points: &[Vec2], grids: &[(u32, u32)]) -> bool {
    grids.iter().all(|&(cols, rows)| {
        assert_eq!((cols * rows) as usize, points.len());
        let mut seen = vec![false; points.len()];
        points.iter().all(|p| {
            let ix = (p.x as f64 * cols as f64) as usize;
            let iy = (p.y as f64 * rows as f64) as usize;
            !std::mem::replace(&mut seen[iy * cols as usize + ix], true)
        })
    })
}

/// The cells a multi-jittered request of `n` samples must fill: its strata (1D), or its
/// m × q grid (m the largest divisor of n not above √n) and its n columns and n rows (2D).
pub fn strata(n: u32, req: Request) -> Vec<(u32, u32)> {
    match req {
        Request::OneD { .. } => vec![(n, 1)],
        Request::TwoD { .. } => {
            let m = (1..=n)
                .filter(|m| n.is_multiple_of(*m) && m * m <= n)
                .max()
                .unwrap();
            vec![(m, n / m), (n, 1), (1, n)]
        }
    }
}

/// Whether the points are a (0, k, 2)-net (2D) or a one-per-stratum set (1D), k = log2 n.
pub fn is_stratified(points: &[Vec2], two_d: bool) -> bool {
    let n = points.len();
    assert!(n.is_power_of_two());
    let k = n.trailing_zeros();
    let splits: Vec<(u32, u32)> = if two_d {
        (0..=k).map(|a| (a, k - a)).collect()
    } else {
        vec![(k, 0)]
    };
    splits.into_iter().all(|(a, b)| {
        let mut seen = vec![false; n];
        points.iter().all(|p| {
            let ix = (p.x as f64 * (1u64 << a) as f64) as usize;
            let iy = (p.y as f64 * (1u64 << b) as f64) as usize;
            let cell = (iy << a) | ix;
            !std::mem::replace(&mut seen[cell], true)
        })
    })
}
