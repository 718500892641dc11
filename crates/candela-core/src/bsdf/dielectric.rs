//! Glass-like interfaces: smooth or rough (Walter et al. 2007) reflection and
//! refraction with the exact dielectric Fresnel term, and the thin sheet.

use glam::{Vec2, Vec3};

use super::fresnel::{fresnel_dielectric, reflect, refract};
use super::microfacet::TrowbridgeReitz;
use super::{BsdfFlags, BsdfSample};

/// An interface between the outside (the side the normal points to) and a medium of
/// relative index `eta` = η_inside/η_outside. Transmitted radiance is scaled by 1/η'²
/// (η' the relative index crossed), as camera paths need (Veach 1997, §5.2). Follows
/// pbrt-v4's `DielectricBxDF` (§9.5, §9.7).
#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    pub eta: f32,
    pub distrib: TrowbridgeReitz,
}

impl Dielectric {
    pub fn is_delta(&self) -> bool {
        self.eta == 1.0 || self.distrib.effectively_smooth()
    }

    /// The half vector of a reflection or refraction pair, on the +z side, and the
    /// relative index η' crossed (1 for reflection). `None` for degenerate pairs and for
    /// back-facing microfacets.
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32, bool)> {
        let (co, ci) = (wo.z, wi.z);
        if co == 0.0 || ci == 0.0 {
            return None;
        }
        let reflect = co * ci > 0.0;
        let etap = if reflect {
            1.0
        } else if co > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let mut wm = (wi * etap + wo).normalize_or_zero();
        if wm == Vec3::ZERO {
            return None;
        }
        if wm.z < 0.0 {
            wm = -wm;
        }
        if wm.dot(wi) * ci < 0.0 || wm.dot(wo) * co < 0.0 {
            return None;
        }
        Some((wm, etap, reflect))
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if self.is_delta() {
            return Vec3::ZERO;
        }
        let Some((wm, etap, reflect)) = self.half_vector(wo, wi) else {
            return Vec3::ZERO;
        };
        let d = self.distrib.d(wm);
        let g = self.distrib.g(wo, wi);
        let fr = fresnel_dielectric(wo.dot(wm), self.eta);
        let v = if reflect {
            d * g * fr / (4.0 * wo.z * wi.z).abs()
        } else {
            let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2) * wi.z * wo.z;
            d * (1.0 - fr) * g * (wi.dot(wm) * wo.dot(wm) / denom).abs() / (etap * etap)
        };
        Vec3::splat(v)
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.is_delta() {
            return 0.0;
        }
        let Some((wm, etap, reflect)) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let r = fresnel_dielectric(wo.dot(wm), self.eta);
        let dv = self.distrib.d_visible(wo, wm);
        if reflect {
            dv / (4.0 * wo.dot(wm).abs()) * r
        } else {
            let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2);
            dv * wi.dot(wm).abs() / denom * (1.0 - r)
        }
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if self.is_delta() {
            return self.sample_smooth(wo, u_lobe);
        }
        let wm = self.distrib.sample_wm(wo, u);
        let r = fresnel_dielectric(wo.dot(wm), self.eta);
        let (wi, flags) = if u_lobe < r {
            let wi = reflect(wo, wm);
            if wi.z * wo.z <= 0.0 {
                return None;
            }
            (wi, BsdfFlags::REFLECTION)
        } else {
            let (wi, _) = refract(wo, wm, self.eta)?;
            if wi.z * wo.z >= 0.0 {
                return None;
            }
            (wi, BsdfFlags::TRANSMISSION)
        };
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BsdfSample {
            f: self.f(wo, wi),
            wi,
            pdf,
            flags: flags.union(BsdfFlags::GLOSSY),
        })
    }

    fn sample_smooth(&self, wo: Vec3, u_lobe: f32) -> Option<BsdfSample> {
        let r = fresnel_dielectric(wo.z, self.eta);
        // Reflection and transmission are chosen in proportion to R and T = 1 − R, so each
        // sample's weight f·|cos θᵢ|/pdf is 1 (times 1/η'² for transmission).
        if u_lobe < r {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            Some(BsdfSample {
                f: Vec3::splat(1.0 / wi.z.abs()),
                wi,
                pdf: 1.0,
                flags: BsdfFlags::REFLECTION.union(BsdfFlags::DELTA),
            })
        } else {
            let (wi, etap) = refract(wo, Vec3::Z, self.eta)?;
            Some(BsdfSample {
                f: Vec3::splat(1.0 / (wi.z.abs() * etap * etap)),
                wi,
                pdf: 1.0,
                flags: BsdfFlags::TRANSMISSION.union(BsdfFlags::DELTA),
            })
        }
    }
}

/// A thin dielectric sheet (a window pane): both faces smooth, light inside bounces
/// between them; rays that pass leave parallel to how they came, so there is no net
/// refraction and no 1/η² scaling. R' = R + T²R/(1 − R²) sums the inner reflections
/// (pbrt-v4 §9.5.2).
#[derive(Clone, Copy, Debug)]
pub struct ThinDielectric {
    pub eta: f32,
}

impl ThinDielectric {
    /// Reflectance of the sheet at |cos θ| = `cos_o`.
    pub fn reflectance(&self, cos_o: f32) -> f32 {
        let r = fresnel_dielectric(cos_o.abs(), self.eta);
        if r < 1.0 {
            r + (1.0 - r) * (1.0 - r) * r / (1.0 - r * r)
        } else {
            1.0
        }
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32) -> Option<BsdfSample> {
        let r = self.reflectance(wo.z);
        let (wi, flags) = if u_lobe < r {
            (Vec3::new(-wo.x, -wo.y, wo.z), BsdfFlags::REFLECTION)
        } else {
            (-wo, BsdfFlags::TRANSMISSION)
        };
        Some(BsdfSample {
            f: Vec3::splat(1.0 / wi.z.abs()),
            wi,
            pdf: 1.0,
            flags: flags.union(BsdfFlags::DELTA),
        })
    }
}
