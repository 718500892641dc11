//! The light interface: what every light answers, written once.
//!
//! Every variant of [`super::Light`] implements [`LightSource`] with these signatures, so
//! the enum only dispatches. It is pbrt-v4's `Light` (`SampleLi`, `PDF_Li`, `L`, `Le`,
//! `Phi`, `Bounds`, `Type`) and Mitsuba 3's `Emitter` with its `EmitterFlags`; the
//! defaults are what a light that a ray can never find answers.

use glam::{Vec2, Vec3};

use super::{LightBounds, LightSample, ShadingCtx};
use crate::geometry::Ray;

/// What kind of emitter a light is (pbrt-v4's `LightType`, Mitsuba's `EmitterFlags`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightFlags(u8);

impl LightFlags {
    /// Emits from a single point (point, spot, goniometric and projector lights).
    pub const DELTA_POSITION: LightFlags = LightFlags(1);
    /// Emits along a single direction (directional lights).
    pub const DELTA_DIRECTION: LightFlags = LightFlags(2);
    /// Emits from a surface that rays can hit (triangles, parallelograms, spheres).
    pub const SURFACE: LightFlags = LightFlags(4);
    /// Surrounds the scene: escaped rays see it (environment lights).
    pub const INFINITE: LightFlags = LightFlags(8);

    /// Whether every flag of `other` is set.
    pub const fn contains(self, other: LightFlags) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether the light is a delta in position or direction: sampled with `pdf = 1`,
    /// never hit by a ray, so MIS never weighs it against BSDF sampling.
    pub const fn is_delta(self) -> bool {
        self.0 & (Self::DELTA_POSITION.0 | Self::DELTA_DIRECTION.0) != 0
    }
}

/// The questions every light answers at a shading context. Densities are in solid angle
/// at the shading point; radiance in W·sr⁻¹·m⁻².
pub trait LightSource {
    /// What kind of emitter this is.
    const FLAGS: LightFlags;

    /// A direction towards the light with the radiance arriving along it and its density.
    /// `u` is ignored by lights that have one direction only (the deltas).
    fn sample_li(&self, ctx: &ShadingCtx, u: Vec2) -> Option<LightSample>;

    /// Density with which [`Self::sample_li`] picks direction `wi` at `ctx`: 0 for lights
    /// that a ray cannot find.
    fn pdf_li(&self, _ctx: &ShadingCtx, _wi: Vec3) -> f32 {
        0.0
    }

    /// Radiance leaving a point of a surface light with geometric normal `n` and texture
    /// coordinates `uv` towards `w`: zero for lights without a surface.
    fn radiance(&self, _n: Vec3, _uv: Vec2, _w: Vec3) -> Vec3 {
        Vec3::ZERO
    }

    /// Radiance an infinite light sends along an escaped ray: zero for the others.
    fn le(&self, _ray: &Ray) -> Vec3 {
        Vec3::ZERO
    }

    /// [`Self::le`] along `ray` and [`Self::pdf_li`] of its direction at `ctx`, as MIS
    /// weighs an escaped ray: lights whose lookup serves both answer from one.
    fn le_pdf(&self, ctx: &ShadingCtx, ray: &Ray) -> (Vec3, f32) {
        (self.le(ray), self.pdf_li(ctx, ray.d))
    }

    /// Total emitted power Φ, as a luminance-weighted scalar (W).
    fn power(&self) -> f32;

    /// Potential contribution at `ctx` up to a common constant, for choosing among lights
    /// (see [`super::Light::importance`]).
    fn importance(&self, ctx: &ShadingCtx) -> f32;

    /// Bounds for the light BVH; `None` for lights not bounded in space.
    fn bounds(&self) -> Option<LightBounds>;
}

/// Radiance `le` of a one-sided Lambertian emitter with normal `n`, seen from direction
/// `w` (pointing away from the surface): `le` on the side the normal faces, zero behind.
#[inline(always)]
pub(super) fn one_sided(n: Vec3, w: Vec3, le: Vec3) -> Vec3 {
    if n.dot(w) > 0.0 {
        le
    } else {
        Vec3::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::LightFlags;

    #[test]
    fn delta_flags_are_the_delta_ones() {
        assert!(LightFlags::DELTA_POSITION.is_delta());
        assert!(LightFlags::DELTA_DIRECTION.is_delta());
        assert!(!LightFlags::SURFACE.is_delta());
        assert!(!LightFlags::INFINITE.is_delta());
        assert!(LightFlags::INFINITE.contains(LightFlags::INFINITE));
        assert!(!LightFlags::SURFACE.contains(LightFlags::INFINITE));
    }
}
