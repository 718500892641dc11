//! Light colour from a blackbody temperature.
//!
//! Planck's law integrated against the CIE 1931 2° colour-matching functions, taken from
//! the multi-lobe Gaussian fit of Wyman, Sloan and Shirley, "Simple Analytic
//! Approximations to the CIE XYZ Color Matching Functions", JCGT 2(2), 2013 (errors
//! below the variation between CMF tables), from 360 to 830 nm in 1 nm steps; then XYZ
//! to linear Rec.709 (sRGB primaries, D65 white).

use glam::{DVec3, Vec3};

use crate::math::luminance;

/// Wyman et al.'s piecewise Gaussian: σ₁ left of the mean, σ₂ right of it.
fn g(x: f64, mu: f64, s1: f64, s2: f64) -> f64 {
    let t = (x - mu) / if x < mu { s1 } else { s2 };
    (-0.5 * t * t).exp()
}

/// CIE 1931 x̄, ȳ, z̄ at wavelength `nm` (Wyman et al. 2013, eq. 2).
pub fn cie_xyz(nm: f64) -> DVec3 {
    DVec3::new(
        1.056 * g(nm, 599.8, 37.9, 31.0) + 0.362 * g(nm, 442.0, 16.0, 26.7)
            - 0.065 * g(nm, 501.1, 20.4, 26.2),
        0.821 * g(nm, 568.8, 46.9, 40.5) + 0.286 * g(nm, 530.9, 16.3, 31.1),
        1.217 * g(nm, 437.0, 11.8, 36.0) + 0.681 * g(nm, 459.0, 26.0, 13.8),
    )
}

/// Planck's spectral radiance up to a constant factor: λ⁻⁵ / (exp(c₂/(λT)) − 1).
fn planck(nm: f64, kelvin: f64) -> f64 {
    const C2: f64 = 1.438_776_9e-2; // m·K
    let l = nm * 1e-9;
    1.0 / (l.powi(5) * ((C2 / (l * kelvin)).exp_m1()))
}

/// CIE XYZ of a blackbody at `kelvin`, up to scale.
pub fn blackbody_xyz(kelvin: f64) -> DVec3 {
    (360..=830)
        .map(|nm| cie_xyz(nm as f64) * planck(nm as f64, kelvin))
        .sum()
}

/// Linear Rec.709 from CIE XYZ (IEC 61966-2-1).
pub fn xyz_to_linear_srgb(c: DVec3) -> DVec3 {
    DVec3::new(
        3.240_454_2 * c.x - 1.537_138_5 * c.y - 0.498_531_4 * c.z,
        -0.969_266_0 * c.x + 1.876_010_8 * c.y + 0.041_556_0 * c.z,
        0.055_643_4 * c.x - 0.204_025_9 * c.y + 1.057_225_2 * c.z,
    )
}

/// The colour of a blackbody at `kelvin` in linear Rec.709, with luminance 1. Colours
/// outside the gamut (below about 1900 K, blue goes negative) are clipped to it before
/// normalizing. `None` for a temperature that is not positive and finite.
pub fn blackbody_rgb(kelvin: f32) -> Option<Vec3> {
    if !(kelvin > 0.0 && kelvin.is_finite()) {
        return None;
    }
    let rgb = xyz_to_linear_srgb(blackbody_xyz(kelvin as f64))
        .max(DVec3::ZERO)
        .as_vec3();
    let y = luminance(rgb);
    (y > 0.0 && y.is_finite()).then(|| rgb / y)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chromaticity(kelvin: f64) -> (f64, f64) {
        let c = blackbody_xyz(kelvin);
        let s = c.x + c.y + c.z;
        (c.x / s, c.y / s)
    }

    /// Planckian-locus chromaticities (CIE 15:2004 tables: illuminant A at 2856 K; the
    /// locus at 4000 K and 6500 K). Tolerance 2·10⁻³: the CMF fit's error, about ten
    /// times below the visible difference of a just-noticeable 100 K step at 6500 K.
    #[test]
    fn planckian_locus_chromaticities() {
        for (t, x, y) in [
            (2856.0, 0.44757, 0.40745),
            (4000.0, 0.38052, 0.37673),
            (6500.0, 0.31352, 0.32363),
        ] {
            let (cx, cy) = chromaticity(t);
            assert!(
                (cx - x).abs() < 2e-3 && (cy - y).abs() < 2e-3,
                "{t} K: ({cx:.5}, {cy:.5}) vs ({x}, {y})"
            );
        }
    }

    #[test]
    fn colours_have_unit_luminance_and_redden_as_they_cool() {
        let warm = blackbody_rgb(2700.0).unwrap();
        let cool = blackbody_rgb(9000.0).unwrap();
        assert!((luminance(warm) - 1.0).abs() < 1e-5);
        assert!((luminance(cool) - 1.0).abs() < 1e-5);
        assert!(warm.x > warm.z && cool.z > cool.x, "{warm} {cool}");
        // 6500 K is close to D65, sRGB's white.
        let white = blackbody_rgb(6500.0).unwrap();
        assert!((white.x / white.z - 1.0).abs() < 0.1, "{white}");
        assert!(blackbody_rgb(0.0).is_none() && blackbody_rgb(f32::NAN).is_none());
    }
}
