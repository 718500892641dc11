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

    /// [`Self::f`] times |cos θᵢ|, and [`Self::pdf`].
    #[inline]
    pub fn f_cos_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if wo.z * wi.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let cos = wi.z.abs();
        (self.albedo * FRAC_1_PI * cos, cosine_hemisphere_pdf(cos))
    }

    #[inline]
    pub fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let mut wi = sample_cosine_hemisphere(u);
        if wo.z < 0.0 {
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
