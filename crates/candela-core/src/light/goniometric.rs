use glam::{Vec2, Vec3};

use super::{
    positional, LightBounds, LightFlags, LightProfile, LightSample, LightSource, ShadingCtx,
};
use crate::geometry::Aabb;
use crate::math::luminance;

/// A point light whose intensity follows a goniometric profile (an IES file), after
/// pbrt-v4's `GoniometricLight`: I(ω) = `intensity` · I_table(ω)/I_max, so `intensity`
/// is the intensity at the profile's peak.
#[derive(Clone, Debug)]
pub struct GoniometricLight {
    pub position: Vec3,
    pub intensity: Vec3,
    pub profile: LightProfile,
}

impl GoniometricLight {
    /// Radiant intensity (W/sr) towards the unit direction `w` leaving the light.
    pub fn intensity_towards(&self, w: Vec3) -> Vec3 {
        self.intensity * self.profile.relative(w)
    }

    /// An emission direction drawn from the profile table, with its solid-angle density.
    pub fn sample_emission(&self, u: Vec2) -> Option<(Vec3, f32)> {
        let (w, pdf) = self.profile.sample(u);
        (pdf > 0.0).then_some((w, pdf))
    }

    /// Density of [`Self::sample_emission`].
    pub fn emission_pdf(&self, w: Vec3) -> f32 {
        self.profile.pdf(w)
    }
}

impl LightSource for GoniometricLight {
    const FLAGS: LightFlags = LightFlags::DELTA_POSITION;

    fn sample_li(&self, ctx: &ShadingCtx, _u: Vec2) -> Option<LightSample> {
        positional::sample_li(self.position, ctx, |w| self.intensity_towards(w))
    }

    /// The exact potential contribution: luminance of I(ω)/d² towards `ctx` times the
    /// receiver cosine; exactly 0 where the light is dark towards the point.
    fn importance(&self, ctx: &ShadingCtx) -> f32 {
        positional::importance(self.position, ctx, |w| self.intensity_towards(w))
    }

    /// Bounded like a point light emitting everywhere at the profile's peak.
    fn bounds(&self) -> Option<LightBounds> {
        Some(LightBounds {
            aabb: Aabb::from_points(&[self.position]),
            w: self.profile.frame.n,
            intensity: luminance(self.intensity),
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        })
    }

    /// Φ = I_peak · ∫ I/I_max dω.
    fn power(&self) -> f32 {
        luminance(self.intensity) * self.profile.solid_angle()
    }
}
