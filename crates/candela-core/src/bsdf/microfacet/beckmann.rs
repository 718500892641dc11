//! The anisotropic Beckmann distribution (Beckmann & Spizzichino 1963; Walter et al. 2007,
//! §5.1), Mitsuba's default, with the exact Smith Λ and Jakob's visible-normal sampler
//! (W. Jakob 2014, "An Improved Visible Normal Sampling Routine for the Beckmann
//! Distribution", the routine Mitsuba 0.6 and 3 use).
//!
//! Λ is the exact form with erfc, not the rational fit of Walter et al. 2007 (eq. 27) that
//! Mitsuba evaluates: the sampler draws from the exact density of visible normals (its
//! CDF is written with erf), so a pdf built from the fit would disagree with it by up to
//! a few tenths of a percent, which a chi-square test of 4·10⁵ samples can see. Both
//! write erfc(x) as e^(−x²) erfcx(x) (`special::erfcx`, 3·10⁻⁷ relative), sharing the
//! exponential their formulas already hold.

use std::f32::consts::{FRAC_2_SQRT_PI, PI};

use glam::{Vec2, Vec3};

use super::special::{coarse_acos, coarse_powf, erfcx, erfinv};
use super::MicrofacetDistribution;

/// 1/√π.
const FRAC_1_SQRT_PI: f32 = 0.5 * FRAC_2_SQRT_PI;

/// Beckmann with roughness `alpha_x` along the local x axis (the shading frame's tangent)
/// and `alpha_y` along y: slopes are Gaussian with standard deviation α/√2 on each axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beckmann {
    pub alpha_x: f32,
    pub alpha_y: f32,
}

impl Beckmann {
    pub fn new(alpha_x: f32, alpha_y: f32) -> Self {
        Beckmann { alpha_x, alpha_y }
    }
}

/// Smith's Λ of the isotropic α = 1 distribution seen at a = cot θ (Walter et al. 2007,
/// eq. 25): (erf(a) − 1)/2 + e^(−a²)/(2a√π), written with erfc = e^(−a²) erfcx(a), whose
/// two terms cancel less at large a: Λ = e^(−a²)(1/(a√π) − erfcx(a))/2. Where they do
/// cancel (a ≳ 2) Λ < 3·10⁻⁴, so erfcx's 3·10⁻⁷ relative error moves 1 + Λ, the only
/// way G₁ and G use Λ, by less than 10⁻⁸.
///
/// From a = [`NEGLIGIBLE_FROM`] on it answers 0: there Λ < 2⁻²⁴, half an ulp of 1, so
/// 1 + Λ (and 1 + Λ + Λ′), the only way G₁ and G use Λ, rounds to the same `f32` as with
/// 0; that skips erfc and exp for most directions of a smooth-ish surface (a = cot θ/α).
fn lambda_unit(a: f32) -> f32 {
    if a >= NEGLIGIBLE_FROM {
        return 0.0;
    }
    lambda_unit_formula(a)
}

/// Where [`lambda_unit`]'s formula gives less than 2⁻²⁴ (the exact Λ is 2⁻²⁴ at
/// a ≈ 3.31; `tests` checks every `f32` from here to 9, where the code skipped it
/// before, e^(−81) being below f32's smallest normal).
const NEGLIGIBLE_FROM: f32 = 3.4;

/// Λ by its closed form (see [`lambda_unit`]).
fn lambda_unit_formula(a: f32) -> f32 {
    (0.5 * (-a * a).exp() * (FRAC_1_SQRT_PI / a - erfcx(a))).max(0.0)
}

impl MicrofacetDistribution for Beckmann {
    fn alpha(&self) -> (f32, f32) {
        (self.alpha_x, self.alpha_y)
    }

    /// D(ωm) = exp(−(x²/αx² + y²/αy²)/z²) / (π αx αy z⁴) for ωm = (x, y, z).
    fn d(&self, wm: Vec3) -> f32 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let cos2 = wm.z * wm.z;
        let tan2 = ((wm.x / ax).powi(2) + (wm.y / ay).powi(2)) / cos2;
        let d = (-tan2).exp() / (PI * ax * ay * cos2 * cos2);
        // At grazing normals z⁴ may underflow where the exponential already has: 0/0.
        if d.is_finite() {
            d
        } else {
            0.0
        }
    }

    /// The exact Λ at a = 1/(α(φ) tan θ), α(φ)² = αx² cos²φ + αy² sin²φ.
    fn lambda(&self, w: Vec3) -> f32 {
        if w.z == 0.0 {
            return f32::INFINITY;
        }
        let alpha_tan = ((self.alpha_x * w.x).powi(2) + (self.alpha_y * w.y).powi(2)).sqrt();
        lambda_unit(w.z.abs() / alpha_tan)
    }

    /// Jakob 2014: stretch `w` to the α = 1 configuration, draw a slope of the visible
    /// normals there (`sample_unit_slope`), rotate it to `w`'s azimuth and unstretch.
    fn sample_wm(&self, w: Vec3, u: Vec2) -> Vec3 {
        let w = if w.z < 0.0 { -w } else { w };
        let ws = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        let sin_theta = (ws.x * ws.x + ws.y * ws.y).sqrt();
        let (cos_phi, sin_phi) = if sin_theta > 0.0 {
            (ws.x / sin_theta, ws.y / sin_theta)
        } else {
            (1.0, 0.0)
        };
        let (sx, sy) = sample_unit_slope(ws.z, sin_theta, u);
        let mx = (cos_phi * sx - sin_phi * sy) * self.alpha_x;
        let my = (sin_phi * sx + cos_phi * sy) * self.alpha_y;
        Vec3::new(-mx, -my, 1.0).normalize()
    }
}

/// A slope (x̃, ỹ) of the visible normals of the isotropic α = 1 Beckmann distribution
/// seen from θ (azimuth 0; the normal is (−x̃, −ỹ, 1) normalized). Its density factors:
/// ∝ (1 − x̃ tan θ)⁺ e^(−x̃²) along x̃ (towards the viewer) and e^(−ỹ²) across. x̃ inverts
/// the CDF F(b) = (1 + b + tan θ e^(−x̃²)/√π)/(1 + c + tan θ e^(−cot²θ)/√π) in the variable
/// b = erf(x̃) ∈ [−1, c = erf(cot θ)] by Newton's method safeguarded by bisection, from
/// Jakob's fitted first guess, to |F(b) − u₁| < 10⁻⁵; ỹ = erfinv(2u₂ − 1).
///
/// c = 1 − e^(−cot²θ) erfcx(cot θ) shares its exponential with the normalization. The
/// first guess takes θ and the power in it from [`coarse_acos`] and [`coarse_powf`]
/// (errors 10⁻⁴): the guess only decides where the iteration starts, so they change the
/// result within the stopping tolerance, as any other start would, not the density.
fn sample_unit_slope(cos_theta: f32, sin_theta: f32, u: Vec2) -> (f32, f32) {
    // Keeps b and 2u₂ − 1 inside (−1, 1), where erfinv is finite (it is ±3.9 there).
    const B_MAX: f32 = 1.0 - f32::EPSILON / 2.0;
    let cos_theta = cos_theta.max(1e-7);
    let tan_theta = sin_theta / cos_theta;
    let cot_theta = cos_theta / sin_theta; // ∞ at normal incidence: c = 1, e^(−∞) = 0
    let exp_cot2 = (-cot_theta * cot_theta).exp();
    // erfcx(∞) = 0, so c = 1 at normal incidence.
    let c = 1.0 - exp_cot2 * erfcx(cot_theta);
    let ux = u.x.max(1e-6);
    let theta = coarse_acos(cos_theta.min(1.0));
    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let mut b = c - (1.0 + c) * coarse_powf(1.0 - ux, fit);
    let tan_over_sqrt_pi = tan_theta * FRAC_1_SQRT_PI;
    let norm = 1.0 / (1.0 + c + tan_over_sqrt_pi * exp_cot2);
    let (mut lo, mut hi) = (-1.0f32, c);
    // erfinv of the b the iteration converged at: what the last step below would
    // recompute (b is unchanged since, and inside [lo, hi], so that step keeps it).
    let mut converged = None;
    for _ in 0..10 {
        // Also catches a NaN step.
        if !(b >= lo && b <= hi) {
            b = 0.5 * (lo + hi);
        }
        let x = erfinv(b.clamp(-B_MAX, B_MAX));
        let value = norm * (1.0 + b + tan_over_sqrt_pi * (-x * x).exp()) - ux;
        if value.abs() < 1e-5 {
            converged = Some(x);
            break;
        }
        if value > 0.0 {
            hi = b;
        } else {
            lo = b;
        }
        let derivative = norm * (1.0 - x * tan_theta);
        b -= value / derivative;
    }
    let sx = converged.unwrap_or_else(|| {
        if !(b >= lo && b <= hi) {
            b = 0.5 * (lo + hi);
        }
        erfinv(b.clamp(-B_MAX, B_MAX))
    });
    let sy = erfinv((2.0 * u.y.max(1e-6) - 1.0).clamp(-B_MAX, B_MAX));
    (sx, sy)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`sample_unit_slope`] as it was before [`special`](super::super::special): c by
    /// `libm`'s erf, the first guess by `acos` and `powf`.
    fn sample_unit_slope_libm(cos_theta: f32, sin_theta: f32, u: Vec2) -> (f32, f32) {
        const B_MAX: f32 = 1.0 - f32::EPSILON / 2.0;
        let cos_theta = cos_theta.max(1e-7);
        let tan_theta = sin_theta / cos_theta;
        let cot_theta = cos_theta / sin_theta;
        let c = libm::erff(cot_theta);
        let ux = u.x.max(1e-6);
        let theta = cos_theta.min(1.0).acos();
        let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
        let mut b = c - (1.0 + c) * (1.0 - ux).powf(fit);
        let tan_over_sqrt_pi = tan_theta * FRAC_1_SQRT_PI;
        let norm = 1.0 / (1.0 + c + tan_over_sqrt_pi * (-cot_theta * cot_theta).exp());
        let (mut lo, mut hi) = (-1.0f32, c);
        for _ in 0..10 {
            if !(b >= lo && b <= hi) {
                b = 0.5 * (lo + hi);
            }
            let x = erfinv(b.clamp(-B_MAX, B_MAX));
            let value = norm * (1.0 + b + tan_over_sqrt_pi * (-x * x).exp()) - ux;
            if value.abs() < 1e-5 {
                break;
            }
            if value > 0.0 {
                hi = b;
            } else {
                lo = b;
            }
            let derivative = norm * (1.0 - x * tan_theta);
            b -= value / derivative;
        }
        if !(b >= lo && b <= hi) {
            b = 0.5 * (lo + hi);
        }
        let sx = erfinv(b.clamp(-B_MAX, B_MAX));
        let sy = erfinv((2.0 * u.y.max(1e-6) - 1.0).clamp(-B_MAX, B_MAX));
        (sx, sy)
    }

    /// A unit-slope sampler: (cos θ, sin θ, u) to (x̃, ỹ).
    type SlopeSampler = fn(f32, f32, Vec2) -> (f32, f32);

    /// The exact CDFs, in f64 with `libm`'s erf, at a sampled slope (x̃, ỹ) seen from θ:
    /// F(x̃) along the view (see [`sample_unit_slope`]) and (1 + erf ỹ)/2 across.
    fn exact_cdfs(cos_theta: f32, sin_theta: f32, (x, y): (f32, f32)) -> (f64, f64) {
        let (cos_t, sin_t) = (cos_theta.max(1e-7) as f64, sin_theta as f64);
        let (tan_t, cot_t) = (sin_t / cos_t, cos_t / sin_t);
        let k = tan_t / std::f64::consts::PI.sqrt();
        let x = x as f64;
        let fx = (1.0 + libm::erf(x) + k * (-x * x).exp())
            / (1.0 + libm::erf(cot_t) + k * (-cot_t * cot_t).exp());
        (fx, 0.5 * (1.0 + libm::erf(y as f64)))
    }

    /// The sampler inverts the exact CDFs: over 4·10⁵ random directions (normal incidence
    /// every 97th, grazing ones included) and numbers, |F(x̃) − u₁| and |(1 + erf ỹ)/2 − u₂|
    /// stay below 1.5·10⁻⁵, the stopping tolerance 10⁻⁵ plus erfinv's 10⁻⁶ relative error
    /// through the density (≤ 2/√π) and f32 rounding. This bounds how far the sampled
    /// density can stray from the one `d_visible` reports, whatever the special functions
    /// inside; the `libm` version it replaced is held to the same bound, and both worst
    /// cases are printed.
    #[test]
    fn unit_slope_inverts_the_exact_cdf() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = move || {
            state = crate::sampler::mix64(state);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut worst = [0.0f64; 2];
        for i in 0..400_000 {
            let cos_theta = if i % 97 == 0 { 1.0 } else { uniform() };
            let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
            let u = Vec2::new(uniform(), uniform());
            let (ux, uy) = (u.x.max(1e-6) as f64, u.y.max(1e-6) as f64);
            let samplers: [SlopeSampler; 2] = [sample_unit_slope, sample_unit_slope_libm];
            for (w, sample) in worst.iter_mut().zip(samplers) {
                let (fx, fy) = exact_cdfs(cos_theta, sin_theta, sample(cos_theta, sin_theta, u));
                let err = (fx - ux).abs().max((fy - uy).abs());
                *w = w.max(err);
                assert!(err < 1.5e-5, "cos θ {cos_theta}, u {u}: F {fx} {fy}");
            }
        }
        eprintln!(
            "largest CDF error: {:.2e} (special functions), {:.2e} (libm)",
            worst[0], worst[1]
        );
    }

    /// [`lambda_unit`]'s shortcut keeps G's bits: at every `f32` a from
    /// [`NEGLIGIBLE_FROM`] up to 9 (12·10⁶ values) the formula gives less than 2⁻²⁴, so
    /// adding it to any sum ≥ 1 changes nothing (beyond 9 Λ was skipped before).
    #[test]
    fn lambda_is_negligible_where_it_is_skipped() {
        for bits in NEGLIGIBLE_FROM.to_bits()..9.0f32.to_bits() {
            let a = f32::from_bits(bits);
            let l = lambda_unit_formula(a);
            assert!(l < 2f32.powi(-24), "Λ({a}) = {l:e}");
            assert_eq!(1.0 + l, 1.0);
        }
        // Below the cut the formula still counts: the shortcut is not premature there.
        assert!(lambda_unit_formula(3.2) > 2f32.powi(-24));
    }

    /// Λ against Smith's definition (Smith 1967; Heitz 2014, eq. 70): with μ = cot θ,
    /// Λ(ω) = (1/μ) ∫∫ (q − μ)⁺ P₂₂(x̃, ỹ) dx̃ dỹ, q = x̃ cos φ + ỹ sin φ the slope along ω's
    /// azimuth and P₂₂ the anisotropic Gaussian slope density
    /// exp(−x̃²/αx² − ỹ²/αy²)/(π αx αy), by a 2000² midpoint rule over ±6α (the mass
    /// beyond is e^(−36)) in f64. Tolerance 10⁻⁴ relative plus 10⁻⁶: the rule's error is
    /// far below that (the integrand is smooth but for the kink at q = μ, whose error is
    /// O(h²)), f32 evaluation of the closed form costs ~10⁻⁶; a wrong α(φ) or a missing
    /// factor ½ costs percents. Also G₁ = 1/(1 + Λ) ≤ 1, 1 at normal incidence.
    #[test]
    fn lambda_matches_smiths_definition() {
        let n = 2000;
        for (ax, ay) in [(0.3f64, 0.3f64), (0.1, 0.5), (1.0, 0.7)] {
            let m = Beckmann::new(ax as f32, ay as f32);
            for (th, ph) in [(45.0f64, 0.0f64), (70.0, 30.0), (85.0, 100.0), (89.0, 45.0)] {
                let (th, ph) = (th.to_radians(), ph.to_radians());
                let mu = th.cos() / th.sin();
                let (hx, hy) = (12.0 * ax / n as f64, 12.0 * ay / n as f64);
                let mut integral = 0.0f64;
                for i in 0..n {
                    let x = -6.0 * ax + (i as f64 + 0.5) * hx;
                    for j in 0..n {
                        let y = -6.0 * ay + (j as f64 + 0.5) * hy;
                        let q = x * ph.cos() + y * ph.sin();
                        if q > mu {
                            let p = (-(x / ax).powi(2) - (y / ay).powi(2)).exp()
                                / (PI as f64 * ax * ay);
                            integral += (q - mu) * p * hx * hy;
                        }
                    }
                }
                let want = integral / mu;
                let w = Vec3::new(
                    (th.sin() * ph.cos()) as f32,
                    (th.sin() * ph.sin()) as f32,
                    th.cos() as f32,
                );
                let got = m.lambda(w) as f64;
                assert!(
                    (got - want).abs() <= 1e-4 * want + 1e-6,
                    "α=({ax},{ay}) θ={:.0}° φ={:.0}°: Λ = {got}, definition {want}",
                    th.to_degrees(),
                    ph.to_degrees()
                );
                assert_eq!(m.lambda(-w), m.lambda(w), "Λ is even");
            }
            assert_eq!(m.g1(Vec3::Z), 1.0);
        }
    }
}
