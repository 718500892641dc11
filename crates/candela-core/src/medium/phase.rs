//! Phase functions: how a medium scatters light at a collision. Isotropic is
//! Henyey–Greenstein with g = 0; both are sampled exactly (the sample's weight p/pdf is 1).
//!
//! Directions follow the propagation: `d` is the direction the light (or path) travels
//! before the collision and `wi` the one after, so g > 0 scatters forward (`wi` near `d`).
//! In pbrt-v4's terms `d` = −ωo.

use std::f32::consts::{FRAC_1_PI, TAU};

use glam::{Vec2, Vec3};

use crate::math::Frame;

/// The Henyey–Greenstein phase function with asymmetry `g` ∈ (−1, 1): the mean cosine of
/// the scattering angle. g = 0 is isotropic, 1/(4π).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HenyeyGreenstein {
    pub g: f32,
}

/// |g| is kept below this: at |g| = 1 the function is a delta and its density infinite.
pub const MAX_ABS_G: f32 = 0.999;

impl HenyeyGreenstein {
    /// The phase function of asymmetry `g`, clamped to ±[`MAX_ABS_G`].
    pub fn new(g: f32) -> HenyeyGreenstein {
        HenyeyGreenstein {
            g: g.clamp(-MAX_ABS_G, MAX_ABS_G),
        }
    }

    /// The isotropic phase function.
    pub const ISOTROPIC: HenyeyGreenstein = HenyeyGreenstein { g: 0.0 };

    /// Density (per steradian) of scattering from propagation direction `d` into `wi`;
    /// it is also the value of the phase function, since sampling is exact.
    #[inline]
    pub fn pdf(&self, d: Vec3, wi: Vec3) -> f32 {
        hg(d.dot(wi), self.g)
    }

    /// A direction scattered from propagation direction `d` (unit) by inverting the
    /// distribution of cos θ (Henyey and Greenstein 1941; pbrt-v4 §11.3.1), with its
    /// density. The weight p/pdf is exactly 1.
    #[inline]
    pub fn sample(&self, d: Vec3, u: Vec2) -> (Vec3, f32) {
        let g = self.g;
        let cos = if g.abs() < 1e-3 {
            1.0 - 2.0 * u.x
        } else {
            let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u.x);
            ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
        };
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = TAU * u.y;
        let local = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
        let wi = Frame::from_z(d).to_world(local).normalize();
        (wi, hg(cos, g))
    }
}

/// The Henyey–Greenstein density of cos θ (θ between the propagation direction and the
/// scattered one): (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}).
#[inline]
pub fn hg(cos: f32, g: f32) -> f32 {
    // 1 + g² − 2g cos θ, written so that the peak (cos θ near ±1, where the sum cancels
    // to (1 ∓ g)²) keeps its precision in f32.
    let denom = if g >= 0.0 {
        (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - cos)
    } else {
        (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + cos)
    };
    0.25 * FRAC_1_PI * (1.0 - g * g) / (denom * denom.max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chi2::{sidak_alpha, ChiSquareTest};

    /// Gs tested, including |g| near 1 where the lobe is a few cells wide.
    const GS: [f32; 7] = [-0.95, -0.5, 0.0, 0.3, 0.7, 0.9, 0.99];

    #[test]
    fn hg_sampling_matches_its_density_chi2() {
        // Each g against its own density, along an oblique axis so that the frame is
        // exercised; α = 0.01 for the suite of seven (Šidák), 3·10⁵ samples each, finer
        // cells and integration where the lobe is narrow.
        let d = Vec3::new(0.3, -0.5, 0.8).normalize();
        let alpha = sidak_alpha(0.01, GS.len());
        for g in GS {
            let hg = HenyeyGreenstein::new(g);
            let test = ChiSquareTest {
                alpha,
                res: if g.abs() > 0.9 { 48 } else { 16 },
                sample_count: 300_000,
                integration_res: if g.abs() > 0.9 { 16 } else { 6 },
                ..Default::default()
            };
            let r = test.spherical(
                &format!("HG g={g}"),
                |u| Some(hg.sample(d, u).0),
                |wi| hg.pdf(d, wi),
            );
            println!("HG g = {g}: χ² = {:.1}, p = {:.3}", r.statistic, r.p_value);
            r.assert_passed();
        }
    }

    #[test]
    fn hg_is_normalized_and_has_mean_cosine_g() {
        // Midpoint rule in cos θ, with steps of 10⁻⁶ over the last 10⁻³ at either end where
        // the lobes of |g| near 1 are ~10⁻⁴ wide: ∫p dω = 1 and ∫cos θ p dω = g to 10⁻³.
        let pieces = [
            (-1.0, -0.999, 1000),
            (-0.999, 0.999, 200_000),
            (0.999, 1.0, 1000),
        ];
        for g in GS {
            let (mut total, mut mean) = (0.0f64, 0.0f64);
            for (a, b, n) in pieces {
                let h = (b - a) / n as f64;
                for i in 0..n {
                    let c = a + (i as f64 + 0.5) * h;
                    let p = hg(c as f32, g) as f64 * std::f64::consts::TAU * h;
                    total += p;
                    mean += c * p;
                }
            }
            assert!((total - 1.0).abs() < 1e-3, "g {g}: ∫p = {total}");
            assert!((mean - g as f64).abs() < 1e-3, "g {g}: mean cos {mean}");
        }
    }

    #[test]
    fn sample_returns_the_density_of_its_direction() {
        let d = Vec3::new(0.0, 0.6, -0.8);
        for g in GS {
            let hg = HenyeyGreenstein::new(g);
            let (wi, pdf) = hg.sample(d, Vec2::new(0.37, 0.81));
            assert!((pdf - hg.pdf(d, wi)).abs() <= 1e-3 * pdf.max(1.0), "g {g}");
        }
    }
}
