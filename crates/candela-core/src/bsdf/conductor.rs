//! Metals: smooth (a perfect mirror) or rough (GGX or Beckmann microfacets), with the
//! complex Fresnel reflectance of a conductor per RGB channel.

use glam::{Vec2, Vec3};

use super::fresnel::{fresnel_conductor, fresnel_schlick, reflect};
use super::microfacet::{Microfacet, MicrofacetDistribution};
use super::{BsdfFlags, BsdfSample};

/// How a conductor's reflectance depends on the angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConductorFresnel {
    /// Complex index of refraction η + ik per channel, relative to the outside medium.
    Complex { eta: Vec3, k: Vec3 },
    /// Schlick's approximation from the normal-incidence reflectance F₀ (glTF metals;
    /// F₀ = 1 gives the ideal white conductor of the furnace test).
    Schlick { f0: Vec3 },
    /// [`ConductorFresnel::Complex`] times a colour (Mitsuba's `specular_reflectance`, a
    /// factor its conductors apply to the Fresnel term).
    ScaledComplex { eta: Vec3, k: Vec3, scale: Vec3 },
}

impl ConductorFresnel {
    pub fn eval(&self, cos_i: f32) -> Vec3 {
        match *self {
            ConductorFresnel::Complex { eta, k } => fresnel_conductor(cos_i, eta, k),
            ConductorFresnel::Schlick { f0 } => fresnel_schlick(f0, cos_i),
            ConductorFresnel::ScaledComplex { eta, k, scale } => {
                scale * fresnel_conductor(cos_i, eta, k)
            }
        }
    }
}

/// A conductor: a delta mirror when the distribution is [effectively
/// smooth](MicrofacetDistribution::effectively_smooth), otherwise the Torrance–Sparrow
/// BRDF D·G·F/(4 cos θo cos θi) sampled by visible normals (pbrt-v4 §9.6.4). Reflection
/// only; `wo` must lie in the upper hemisphere (the [`super::Lobe`] mirrors the back
/// side).
#[derive(Clone, Copy, Debug)]
pub struct Conductor {
    pub distrib: Microfacet,
    pub fresnel: ConductorFresnel,
}

impl Conductor {
    pub fn is_delta(&self) -> bool {
        self.distrib.effectively_smooth()
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
        if self.is_delta() || wo.z <= 0.0 || wi.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let Some((wm, dg, pdf)) = self.distrib.reflection(wo, wi) else {
            return (Vec3::ZERO, 0.0);
        };
        (self.fresnel.eval(wo.dot(wm)) * dg, pdf)
    }

    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        if self.is_delta() {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                f: self.fresnel.eval(wi.z) / wi.z,
                wi,
                pdf: 1.0,
                flags: BsdfFlags::REFLECTION.union(BsdfFlags::DELTA),
            });
        }
        let wm = self.distrib.sample_wm(wo, u);
        let wi = reflect(wo, wm);
        if wi.z <= 0.0 {
            return None;
        }
        let (f, pdf) = self.f_pdf(wo, wi);
        (pdf > 0.0).then_some(BsdfSample {
            f,
            wi,
            pdf,
            flags: BsdfFlags::REFLECTION.union(BsdfFlags::GLOSSY),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::desc::metal_preset;

    #[test]
    fn presets_have_their_metals_colours() {
        let r0 = |name| {
            let (eta, k) = metal_preset(name).unwrap();
            fresnel_conductor(1.0, eta, k)
        };
        let (au, ag, cu, al) = (r0("au"), r0("Ag"), r0("Cu"), r0("Al"));
        assert!(
            au.x > au.y && au.y > au.z && au.z < 0.5,
            "gold is yellow: {au}"
        );
        assert!(cu.x > cu.y && cu.x > cu.z, "copper is red: {cu}");
        assert!(ag.min_element() > 0.9, "silver is bright and grey: {ag}");
        assert!(al.min_element() > 0.85, "aluminium is bright: {al}");
        assert!(metal_preset("unobtainium").is_none());
    }
}
