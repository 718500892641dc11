//! The glTF 2.0 metallic-roughness material (glTF 2.0 specification, Appendix B).

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::fresnel::{fresnel_schlick, reflect};
use super::microfacet::{MicrofacetDistribution, TrowbridgeReitz};
use super::{BsdfFlags, BsdfSample};
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};

/// glTF's BRDF: F₀ = mix(0.04, base, metallic) (0.04 is ior 1.5); specular = F·D·G/(4
/// cos θo cos θi) with GGX of α = roughness² and Schlick's F at ωo·ωh; diffuse =
/// (1 − F(θo))(1 − F(θi))(1 − metallic)·base/π.
///
/// The diffuse weight departs from the spec's `fresnel_mix` (1 − F(ωo·ωh)): that form
/// returns up to 2.5% more energy than it receives for a white base (measured by
/// `tests/bsdf_energy.rs` at roughness 0.05, θo = 60°). Weighting by the Fresnel
/// transmittance in and out (as a coat would) is reciprocal and stays below 1. Sampled by choosing the
/// specular lobe (visible normals) or the cosine-weighted diffuse one in proportion to
/// their rough share of the albedo; `pdf` is the mixture density of both.
#[derive(Clone, Copy, Debug)]
pub struct MetalRough {
    pub base_color: Vec3,
    pub metallic: f32,
    pub distrib: TrowbridgeReitz,
}

impl MetalRough {
    pub fn new(base_color: Vec3, metallic: f32, roughness: f32) -> MetalRough {
        // Clamp α away from 0: the glTF model has no delta lobe, so a mirror-like surface
        // becomes a very sharp GGX lobe instead.
        let alpha = TrowbridgeReitz::roughness_to_alpha(roughness.clamp(0.0, 1.0)).max(2e-3);
        MetalRough {
            base_color,
            metallic: metallic.clamp(0.0, 1.0),
            distrib: TrowbridgeReitz::new(alpha, alpha),
        }
    }

    fn f0(&self) -> Vec3 {
        Vec3::splat(0.04).lerp(self.base_color, self.metallic)
    }

    fn diffuse_color(&self) -> Vec3 {
        self.base_color * (1.0 - self.metallic)
    }

    fn specular_probability(&self, cos_o: f32) -> f32 {
        let s = fresnel_schlick(self.f0(), cos_o).max_element();
        let d = (1.0 - s) * self.diffuse_color().max_element();
        if d <= 0.0 {
            1.0
        } else {
            (s / (s + d)).clamp(0.1, 0.9)
        }
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.f_pdf(wo, wi).0
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.f_pdf(wo, wi).1
    }

    /// [`Self::f`] and [`Self::pdf`] at once: one half vector, one D and one Λ(ωo) for
    /// both.
    pub fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let ps = self.specular_probability(wo.z);
        let diffuse_pdf = (1.0 - ps) * cosine_hemisphere_pdf(wi.z);
        let Some((wm, dg, specular_pdf)) = self.distrib.reflection(wo, wi) else {
            return (Vec3::ZERO, ps * 0.0 + diffuse_pdf);
        };
        let f0 = self.f0();
        let spec = fresnel_schlick(f0, wo.dot(wm)) * dg;
        let transmit =
            (Vec3::ONE - fresnel_schlick(f0, wo.z)) * (Vec3::ONE - fresnel_schlick(f0, wi.z));
        let f = spec + transmit * self.diffuse_color() * FRAC_1_PI;
        (f, ps * specular_pdf + diffuse_pdf)
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let ps = self.specular_probability(wo.z);
        let wi = if u_lobe < ps {
            reflect(wo, self.distrib.sample_wm(wo, u))
        } else {
            sample_cosine_hemisphere(u)
        };
        if wi.z <= 0.0 {
            return None;
        }
        let (f, pdf) = self.f_pdf(wo, wi);
        let flags = if u_lobe < ps {
            BsdfFlags::GLOSSY
        } else {
            BsdfFlags::DIFFUSE
        };
        (pdf > 0.0).then_some(BsdfSample {
            f,
            wi,
            pdf,
            flags: BsdfFlags::REFLECTION.union(flags),
        })
    }
}
