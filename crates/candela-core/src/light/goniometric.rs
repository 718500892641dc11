use glam::{Vec2, Vec3};

use super::{LightProfile, LightSample, ShadingCtx};
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

    pub fn sample_li(&self, ctx: &ShadingCtx) -> Option<LightSample> {
        let to = self.position - ctx.p;
        let d2 = to.length_squared();
        if d2 == 0.0 {
            return None;
        }
        let distance = d2.sqrt();
        let wi = to / distance;
        Some(LightSample {
            radiance: self.intensity_towards(-wi) / d2,
            wi,
            distance,
            pdf: 1.0,
            is_delta: true,
            p_light: self.position,
            n_light: Vec3::ZERO,
        })
    }

    /// Φ = I_peak · ∫ I/I_max dω.
    pub fn power(&self) -> f32 {
        luminance(self.intensity) * self.profile.solid_angle()
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
