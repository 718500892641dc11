use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{InfiniteImportance, LightBounds, LightFlags, LightSample, LightSource, ShadingCtx};
use crate::math::luminance;

/// Parallel light from infinitely far away, travelling along `direction`: a surface facing
/// it receives irradiance `irradiance` (W/m²). A delta light in direction; shadow rays go
/// to infinity.
#[derive(Clone, Debug)]
pub struct DirectionalLight {
    /// Unit direction the light travels in.
    pub direction: Vec3,
    pub irradiance: Vec3,
    /// Radius of a sphere bounding the scene, for the power estimate.
    pub scene_radius: f32,
}

impl DirectionalLight {}

impl LightSource for DirectionalLight {
    const FLAGS: LightFlags = LightFlags::DELTA_DIRECTION;

    fn sample_li(&self, ctx: &ShadingCtx, _u: Vec2) -> Option<LightSample> {
        let wi = -self.direction;
        Some(LightSample {
            radiance: self.irradiance,
            wi,
            distance: f32::INFINITY,
            pdf: 1.0,
            is_delta: true,
            p_light: ctx.p + wi * (2.0 * self.scene_radius),
            n_light: Vec3::ZERO,
        })
    }

    /// E × the receiver cosine towards the light (see [`InfiniteImportance`]).
    fn importance(&self, ctx: &ShadingCtx) -> f32 {
        InfiniteImportance::Direction {
            irradiance: luminance(self.irradiance),
            wi: -self.direction,
        }
        .at(ctx)
    }

    /// The power crossing the scene's bounding disk, Φ = π r² E (pbrt-v4 §12.4).
    fn power(&self) -> f32 {
        PI * self.scene_radius * self.scene_radius * luminance(self.irradiance)
    }

    /// Not bounded in space: the BVH sampler picks it apart from the tree.
    fn bounds(&self) -> Option<LightBounds> {
        None
    }
}
