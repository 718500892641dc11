//! Plastic: a Lambertian base under a smooth dielectric coat.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance};
use super::{BsdfFlags, BsdfSample};
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};

/// A diffuse base of albedo ρ under a smooth coat of relative index η.
///
/// Energy model (as Mitsuba's `plastic`; Kelemen & Szirmay-Kalos 2001 for the idea): the
/// coat reflects F(θo) specularly (a delta lobe); the rest, 1 − F(θo), enters, is
/// reflected diffusely by the base and leaves through the coat with transmittance
/// 1 − F(θi) and the 1/η² of radiance compression. Light that the coat reflects back
/// inside (the internal diffuse Fresnel reflectance F_dr,in) bounces again; summing the
/// geometric series gives
///
/// f_d(ωo, ωi) = (1 − F(θo))(1 − F(θi)) ρ / (π η² (1 − ρ F_dr,in)).
///
/// Since ∫(1 − F(θi)) cos θi/(π η²) dωi = 1 − F_dr,in, the albedo is
/// F(θo) + (1 − F(θo)) ρ(1 − F_dr,in)/(1 − ρ F_dr,in) ≤ 1 for ρ ≤ 1: energy is conserved
/// exactly, with nothing absorbed when ρ = 1.
#[derive(Clone, Copy, Debug)]
pub struct Plastic {
    pub albedo: Vec3,
    pub eta: f32,
    /// F_dr for light inside the coat; see [`Plastic::new`].
    pub fdr_inside: f32,
}

impl Plastic {
    /// Computes the internal diffuse Fresnel reflectance once (a 512-step quadrature).
    pub fn new(albedo: Vec3, eta: f32) -> Plastic {
        Plastic {
            albedo,
            eta,
            fdr_inside: fresnel_diffuse_reflectance(1.0 / eta),
        }
    }

    /// Probability of choosing the specular coat when sampling from `wo`: its share of the
    /// albedo.
    fn specular_probability(&self, cos_o: f32) -> f32 {
        let fo = fresnel_dielectric(cos_o, self.eta);
        let diffuse = (1.0 - fo) * self.albedo.max_element().min(1.0);
        if fo + diffuse <= 0.0 {
            return 1.0;
        }
        fo / (fo + diffuse)
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let fo = fresnel_dielectric(wo.z, self.eta);
        let fi = fresnel_dielectric(wi.z, self.eta);
        let denom = Vec3::ONE - self.albedo * self.fdr_inside;
        self.albedo * ((1.0 - fo) * (1.0 - fi) * FRAC_1_PI / (self.eta * self.eta)) / denom
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        (1.0 - self.specular_probability(wo.z)) * cosine_hemisphere_pdf(wi.z)
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let ps = self.specular_probability(wo.z);
        if u_lobe < ps {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let fo = fresnel_dielectric(wo.z, self.eta);
            return Some(BsdfSample {
                f: Vec3::splat(fo / (ps * wi.z)),
                wi,
                pdf: 1.0,
                flags: BsdfFlags::REFLECTION.union(BsdfFlags::DELTA),
            });
        }
        let wi = sample_cosine_hemisphere(u);
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BsdfSample {
            f: self.f(wo, wi),
            wi,
            pdf,
            flags: BsdfFlags::REFLECTION.union(BsdfFlags::DIFFUSE),
        })
    }
}
