//! Fresnel reflectance of smooth interfaces and the refraction direction.

use glam::Vec3;

/// Unpolarized Fresnel reflectance of a dielectric interface (pbrt-v4 §9.3.2). `cos_i` is
/// signed against the normal; `eta` = η_inside / η_outside, where "inside" is the side
/// the normal points away from. Returns 1 under total internal reflection.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (mut cos_i, mut eta) = (cos_i.clamp(-1.0, 1.0), eta);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Unpolarized Fresnel reflectance of a conductor with complex index η + ik per channel,
/// from the outside at |cos θᵢ| = `cos_i` (pbrt-v3 §8.2.1, real-arithmetic form).
pub fn fresnel_conductor(cos_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let c = cos_i.abs().clamp(0.0, 1.0);
    let c2 = Vec3::splat(c * c);
    let s2 = Vec3::ONE - c2;
    let eta2 = eta * eta;
    let k2 = k * k;
    let t0 = eta2 - k2 - s2;
    let a2b2 = (t0 * t0 + 4.0 * eta2 * k2).max(Vec3::ZERO).powf(0.5);
    let t1 = a2b2 + c2;
    let a = (0.5 * (a2b2 + t0)).max(Vec3::ZERO).powf(0.5);
    let t2 = 2.0 * c * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = c2 * a2b2 + s2 * s2;
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    (0.5 * (rp + rs)).clamp(Vec3::ZERO, Vec3::ONE)
}

/// Schlick's approximation F₀ + (1 − F₀)(1 − cos θ)⁵ (Schlick 1994), as glTF 2.0 uses.
pub fn fresnel_schlick(f0: Vec3, cos_i: f32) -> Vec3 {
    let m = (1.0 - cos_i.abs()).clamp(0.0, 1.0);
    let m5 = (m * m) * (m * m) * m;
    f0 + (Vec3::ONE - f0) * m5
}

/// Hemispherical average 2∫F(cos θ)cos θ dcos θ of the dielectric Fresnel reflectance for
/// light arriving from the side with relative index `eta` (as [`fresnel_dielectric`]
/// takes it with positive cosines): the "diffuse Fresnel reflectance" F_dr. Computed by
/// the midpoint rule (error < 10⁻⁴ at 512 steps).
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    const N: usize = 512;
    (0..N)
        .map(|i| {
            let mu = (i as f32 + 0.5) / N as f32;
            2.0 * mu * fresnel_dielectric(mu, eta)
        })
        .sum::<f32>()
        / N as f32
}

/// Mirror reflection of `wo` about `n`.
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    -wo + 2.0 * wo.dot(n) * n
}

/// Refraction of `wi` (pointing away from the surface) through the interface with normal
/// `n` and relative index `eta` (η_inside/η_outside, `n` pointing outside). Returns the
/// transmitted direction and the relative index η_t/η_i actually crossed, or `None` under
/// total internal reflection (pbrt-v4 §9.3).
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (mut n, mut eta) = (n, eta);
    let mut cos_i = n.dot(wi);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wi / eta + (cos_i / eta - cos_t) * n, eta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_known_values() {
        // Normal incidence: ((η−1)/(η+1))² = 0.04 for η = 1.5.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
        // Brewster's angle: the parallel part vanishes, R = r_perp²/2.
        let tb = 1.5f32.atan();
        let r = fresnel_dielectric(tb.cos(), 1.5);
        assert!((r - 0.0739).abs() < 1e-3, "{r}");
        // Inside glass beyond the critical angle (41.8°): total internal reflection.
        assert_eq!(fresnel_dielectric(-(50f32.to_radians().cos()), 1.5), 1.0);
    }

    #[test]
    fn conductor_reduces_to_dielectric_for_k_zero() {
        for c in [1.0, 0.7, 0.3, 0.05] {
            let fc = fresnel_conductor(c, Vec3::splat(1.5), Vec3::ZERO);
            assert!((fc.x - fresnel_dielectric(c, 1.5)).abs() < 1e-5, "{c}");
        }
        // Normal incidence: ((η−1)² + k²)/((η+1)² + k²).
        let f = fresnel_conductor(1.0, Vec3::splat(0.2), Vec3::splat(3.0));
        assert!((f.x - (0.64 + 9.0) / (1.44 + 9.0)).abs() < 1e-5);
    }

    #[test]
    fn refraction_obeys_snell_and_diffuse_fresnel_is_known() {
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let (wt, etap) = refract(wi, Vec3::Z, 1.5).unwrap();
        assert_eq!(etap, 1.5);
        assert!((wt.length() - 1.0).abs() < 1e-5 && wt.z < 0.0);
        assert!((wi.x - 1.5 * (-wt.x)).abs() < 1e-5, "sin θi = η sin θt");
        // F_dr for glass seen from outside ≈ 0.0918 (Egan & Hilgeman fit gives 0.092).
        let fdr = fresnel_diffuse_reflectance(1.5);
        assert!((fdr - 0.0918).abs() < 2e-3, "{fdr}");
        // From inside: 1 − (1 − F_dr,out)/η² ≈ 0.596.
        let fdr_in = fresnel_diffuse_reflectance(1.0 / 1.5);
        assert!((1.0 - fdr_in - (1.0 - fdr) / 2.25).abs() < 2e-3, "{fdr_in}");
    }
}
