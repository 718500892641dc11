use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{receiver_cos, LightBounds, LightFlags, LightSample, LightSource, ShadingCtx};
use crate::geometry::Aabb;
use crate::math::luminance;

/// An isotropic point light: radiant intensity `intensity` (W/sr) in every direction.
#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: Vec3,
}

impl LightSource for PointLight {
    const FLAGS: LightFlags = LightFlags::DELTA_POSITION;

    #[inline]
    fn sample_li(&self, ctx: &ShadingCtx, _u: Vec2) -> Option<LightSample> {
        let to = self.position - ctx.p;
        let d2 = to.length_squared();
        if d2 == 0.0 {
            return None;
        }
        let distance = d2.sqrt();
        Some(LightSample {
            radiance: self.intensity / d2,
            wi: to / distance,
            distance,
            pdf: 1.0,
            is_delta: true,
            p_light: self.position,
            n_light: Vec3::ZERO,
        })
    }

    fn power(&self) -> f32 {
        4.0 * PI * luminance(self.intensity)
    }

    /// I/d² × |cos θ| at the receiver.
    fn importance(&self, ctx: &ShadingCtx) -> f32 {
        let to = self.position - ctx.p;
        let d2 = to.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        luminance(self.intensity) / d2 * receiver_cos(ctx, to / d2.sqrt())
    }

    /// A point emitting into every direction.
    fn bounds(&self) -> Option<LightBounds> {
        Some(LightBounds {
            aabb: Aabb::from_points(&[self.position]),
            w: Vec3::Z,
            intensity: luminance(self.intensity),
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        })
    }
}
