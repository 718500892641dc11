//! Lambertian reflection.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::{BsdfFlags, BsdfSample};
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};

/// Reflects `albedo` of the incident light equally in every direction of the side it
/// arrives from: f = albedo/π. Sampled by the cosine-weighted hemisphere.
#[derive(Clone, Copy, Debug)]
pub struct Diffuse {
    pub albedo: Vec3,
}

impl Diffuse {
    #[inline]
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z * wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        self.albedo * FRAC_1_PI
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z * wi.z <= 0.0 {
            return 0.0;
        }
        cosine_hemisphere_pdf(wi.z.abs())
    }

    /// [`Self::f`] times |cos θᵢ|, and [`Self::pdf`], from the local z of `wo` and `wi`
    /// (all the lobe reads of them).
    #[inline]
    pub fn f_cos_pdf(&self, cos_o: f32, cos_i: f32) -> (Vec3, f32) {
        if cos_o * cos_i <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let cos = cos_i.abs();
        (self.albedo * FRAC_1_PI * cos, cosine_hemisphere_pdf(cos))
    }

    #[inline]
    pub fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        self.sample_from(wo.z, u)
    }

    /// [`Self::sample`] from the local z of `wo`, all it reads of it.
    #[inline]
    pub fn sample_from(&self, cos_o: f32, u: Vec2) -> Option<BsdfSample> {
        let mut wi = sample_cosine_hemisphere(u);
        if cos_o < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = cosine_hemisphere_pdf(wi.z.abs());
        (pdf > 0.0).then(|| BsdfSample {
            f: self.albedo * FRAC_1_PI,
            wi,
            pdf,
            flags: BsdfFlags::REFLECTION.union(BsdfFlags::DIFFUSE),
        })
    }
}
