//! Pixel reconstruction filters, by filter importance sampling (Ernst et al. 2006, "Filter
//! Importance Sampling"): each camera sample's offset from its pixel's centre is drawn
//! with density proportional to the filter, and the pixel keeps the plain mean of its
//! samples. The expected image is the filtered one that splatting renderers such as
//! Mitsuba produce, without samples crossing pixel (and thread) boundaries.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

use glam::Vec2;

use crate::desc::PixelFilterDesc;
#[cfg(target_arch = "x86_64")]
use crate::lane_expf;
use crate::sampling::Distribution1D;

/// Cells of the tabulated Gaussian: its piecewise-constant stand-in differs from the
/// curve by under 1% of its peak within each cell 1/64 of a pixel wide (σ = 0.5).
const GAUSSIAN_CELLS: usize = 256;

/// A separable filter, sampled per axis.
#[derive(Clone, Debug)]
pub enum PixelFilter {
    /// The pixel's square: offsets uniform in [−½, ½)².
    Box,
    /// 1 − |x|/r per axis.
    Tent { radius: f32 },
    /// exp(−x²/2σ²) − exp(−r²/2σ²) per axis, clamped at 0 (Mitsuba's `gaussian`), drawn
    /// from a table.
    Gaussian {
        stddev: f32,
        radius: f32,
        table: Distribution1D,
        /// exp(−r²/2σ²), the curve's value at the radius, which the filter subtracts:
        /// computed once, not in each of the splat's 8 evaluations per sample.
        tail: f32,
    },
}

impl PixelFilter {
    pub fn new(desc: PixelFilterDesc) -> PixelFilter {
        match desc {
            PixelFilterDesc::Box => PixelFilter::Box,
            PixelFilterDesc::Tent { radius } => PixelFilter::Tent { radius },
            PixelFilterDesc::Gaussian { stddev, radius } => {
                let tail = gaussian_curve(radius, stddev);
                let f: Vec<f32> = (0..GAUSSIAN_CELLS)
                    .map(|i| {
                        let x = ((i as f32 + 0.5) / GAUSSIAN_CELLS as f32 * 2.0 - 1.0) * radius;
                        gaussian(x, stddev, tail)
                    })
                    .collect();
                PixelFilter::Gaussian {
                    stddev,
                    radius,
                    table: Distribution1D::new(&f),
                    tail,
                }
            }
        }
    }

    /// Offset of a sample from the pixel's centre, from a uniform `u` ∈ [0, 1)².
    pub fn sample(&self, u: Vec2) -> Vec2 {
        match self {
            PixelFilter::Box => u - Vec2::splat(0.5),
            PixelFilter::Tent { radius } => Vec2::new(sample_tent(u.x), sample_tent(u.y)) * *radius,
            PixelFilter::Gaussian { radius, table, .. } => {
                let axis = |u: f32| (table.sample_continuous(u).0 * 2.0 - 1.0) * radius;
                Vec2::new(axis(u.x), axis(u.y))
            }
        }
    }

    /// Density of [`Self::sample`]'s offsets (per unit area, in pixels).
    pub fn pdf(&self, offset: Vec2) -> f32 {
        match self {
            PixelFilter::Box => {
                let inside = offset.abs().max_element() <= 0.5;
                if inside {
                    1.0
                } else {
                    0.0
                }
            }
            PixelFilter::Tent { radius } => {
                let axis = |x: f32| (1.0 - x.abs() / radius).max(0.0) / radius;
                axis(offset.x) * axis(offset.y)
            }
            PixelFilter::Gaussian { radius, table, .. } => {
                let axis = |x: f32| {
                    if x.abs() > *radius {
                        0.0
                    } else {
                        table.pdf(((x / radius + 1.0) * 0.5).min(1.0 - f32::EPSILON))
                            / (2.0 * radius)
                    }
                };
                axis(offset.x) * axis(offset.y)
            }
        }
    }

    /// How far from a sample, in pixels along each axis, the filter reaches.
    pub fn radius(&self) -> f32 {
        match self {
            PixelFilter::Box => 0.5,
            PixelFilter::Tent { radius } | PixelFilter::Gaussian { radius, .. } => *radius,
        }
    }

    /// The filter's value along one axis at offset `x` from a pixel's centre, up to a
    /// constant factor: its weight per axis when splatting (see [`crate::splat`]). The
    /// Gaussian is evaluated exactly, not through the table.
    pub fn eval_axis(&self, x: f32) -> f32 {
        match self {
            PixelFilter::Box => (x.abs() <= 0.5) as u32 as f32,
            PixelFilter::Tent { radius } => (1.0 - x.abs() / radius).max(0.0),
            PixelFilter::Gaussian { stddev, tail, .. } => gaussian(x, *stddev, *tail),
        }
    }

    /// [`Self::eval_axis`] at eight offsets at once, with the same bits, for the v3 render
    /// loop: the Gaussian's exponentials in [`lane_expf`] lanes. `None` where the filter
    /// is not a Gaussian or an exponential's argument is beyond [`lane_expf::in_range`]
    /// (a σ far below the radius): the caller then evaluates the offsets one by one.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma")]
    #[inline]
    pub fn eval_axis8(&self, x: __m256) -> Option<__m256> {
        let PixelFilter::Gaussian { stddev, tail, .. } = self else {
            return None;
        };
        // −x²/(2σ²) rounded as `gaussian_curve` rounds it: (−x·x) / ((2σ)·σ).
        let minus_zero = _mm256_set1_ps(-0.0);
        let arg = _mm256_div_ps(
            _mm256_xor_ps(_mm256_mul_ps(x, x), minus_zero),
            _mm256_set1_ps(2.0 * stddev * stddev),
        );
        // |arg| < 88, `in_range` for every lane (NaN fails the ordered comparison).
        let inside =
            _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(minus_zero, arg), _mm256_set1_ps(88.0));
        if _mm256_movemask_ps(inside) != 0xff {
            return None;
        }
        let curve = lane_expf::expf8(arg);
        // `gaussian`: less the tail, clamped at 0 (`maxps` returns its 0 for a NaN, as
        // `f32::max` does).
        Some(_mm256_max_ps(
            _mm256_sub_ps(curve, _mm256_set1_ps(*tail)),
            _mm256_setzero_ps(),
        ))
    }
}

/// The filter: the curve less its value `tail` at the radius, clamped at 0.
fn gaussian(x: f32, stddev: f32, tail: f32) -> f32 {
    (gaussian_curve(x, stddev) - tail).max(0.0)
}

/// exp(−x²/2σ²).
fn gaussian_curve(x: f32, stddev: f32) -> f32 {
    (-x * x / (2.0 * stddev * stddev)).exp()
}

/// The unit tent 1 − |x| on [−1, 1] by inverting its CDF, one half per half of `u`.
fn sample_tent(u: f32) -> f32 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        1.0 - (2.0 - 2.0 * u).max(0.0).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chi2::ChiSquareTest;

    /// Each filter's offsets follow its density: χ² over a 32 × 32 grid with 10⁶
    /// samples at α = 0.01 per filter (a correct sampler fails with probability 1%; the
    /// seeds are fixed).
    #[test]
    fn offsets_follow_the_filter() {
        for (name, desc, r) in [
            ("box", PixelFilterDesc::Box, 0.5),
            ("tent", PixelFilterDesc::Tent { radius: 1.0 }, 1.0),
            ("tent r=1.5", PixelFilterDesc::Tent { radius: 1.5 }, 1.5),
            (
                "gaussian",
                PixelFilterDesc::Gaussian {
                    stddev: 0.5,
                    radius: 2.0,
                },
                2.0,
            ),
        ] {
            let f = PixelFilter::new(desc);
            let harness = ChiSquareTest {
                alpha: 0.01,
                seed: 7,
                ..Default::default()
            };
            let report = harness.planar(
                name,
                Vec2::splat(-r),
                Vec2::splat(r),
                |u| Some(f.sample(u)),
                |p| f.pdf(p),
            );
            report.assert_passed();
        }
    }

    #[test]
    fn tent_sampling_inverts_its_cdf() {
        assert_eq!(sample_tent(0.5), 0.0);
        assert_eq!(sample_tent(0.0), -1.0);
        // CDF of the unit tent at −½ is ⅛.
        assert!((sample_tent(0.125) + 0.5).abs() < 1e-6);
        assert!((sample_tent(0.875) - 0.5).abs() < 1e-6);
    }
}
