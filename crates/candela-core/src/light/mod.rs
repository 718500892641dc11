//! Lights, and the three questions every light answers at a shading point:
//!
//! - **sample** ([`Light::sample_li`]): a direction towards the light with the radiance
//!   arriving along it and its density;
//! - **pdf** ([`Light::pdf_li`]): the density with which `sample_li` would have picked a
//!   given direction, for MIS when a BSDF-sampled ray finds the light;
//! - **radiance** ([`Light::radiance`] when a ray hits an area light, [`Light::le`] when
//!   a ray escapes to an infinite light).
//!
//! The interface is written once, in [`LightSource`] (`source.rs`): every variant of
//! [`Light`] implements it with the same signatures and says what it is through
//! [`LightFlags`] (delta position, delta direction, surface, infinite); [`Light`] only
//! dispatches. All densities are in solid angle at the shading point. Delta lights
//! (points, spots, goniometric, directional and projector lights) report `pdf = 1` and
//! `is_delta`, and are never hit by rays.

pub mod blackbody;
mod bounds;
mod directional;
mod emission_texture;
mod environment;
pub mod envmap;
mod goniometric;
mod importance_lanes;
mod infinite_importance;
mod parallelogram;
mod point;
mod positional;
mod profile;
mod projector;
mod source;
mod sphere;
mod spherical;
mod spot;
mod triangle;

pub use bounds::{cone_measure, cone_union, ImportanceBounds, LightBounds};
pub use directional::DirectionalLight;
pub use emission_texture::EmissionTexture;
pub use environment::{EnvironmentLight, EnvironmentMap, EnvironmentSampling};
pub use goniometric::GoniometricLight;
#[cfg(target_arch = "x86_64")]
pub use importance_lanes::LoadedLanes;
pub use importance_lanes::{ImportanceLanes, LANES};
pub use infinite_importance::{InfiniteImportance, SkyImportance, SkyIrradiance};
pub use parallelogram::ParallelogramLight;
pub use point::PointLight;
pub use profile::LightProfile;
pub use projector::ProjectorLight;
pub use source::{LightFlags, LightSource};
pub use sphere::SphereLight;
pub use spherical::polygon_irradiance;
pub use spot::SpotLight;
pub use triangle::TriangleLight;

use glam::{Vec2, Vec3};

use crate::geometry::Ray;
use crate::math::luminance;
use crate::options::LampSampling;

/// Index of a light in [`crate::Scene::lights`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LightId(pub u32);

/// Where light is being gathered: a point and its shading normal (zero where there is no
/// surface, e.g. in a medium).
#[derive(Clone, Copy, Debug)]
pub struct ShadingCtx {
    pub p: Vec3,
    pub n: Vec3,
}

/// |n·ω| for a unit direction ω, or 1 where there is no normal.
fn receiver_cos(ctx: &ShadingCtx, w: Vec3) -> f32 {
    if ctx.n == Vec3::ZERO {
        1.0
    } else {
        ctx.n.dot(w).abs()
    }
}

/// Importance of a flat one-sided emitter of radiance `le` that subtends `omega` from the
/// shading point, seen along the unit directions `corners` to its corners: luminance ×
/// solid angle × the largest receiver cosine over the corners. A tiny floor on the solid
/// angle keeps grazing but still visible emitters selectable.
fn flat_importance(ctx: &ShadingCtx, le: Vec3, omega: f32, corners: &[Vec3]) -> f32 {
    let cos_r = corners
        .iter()
        .map(|w| receiver_cos(ctx, *w))
        .fold(0.0f32, f32::max);
    luminance(le) * omega.max(1e-12) * cos_r
}

/// Whether 0 < `x` < ∞ (false for NaN): `x > 0.0 && x.is_finite()` in three instructions.
/// The positive finite floats are exactly the bit patterns 1 ..= 0x7f7f_ffff (the
/// smallest subnormal to `f32::MAX`); LLVM turned the two float tests (and also
/// `x > 0.0 && x < f32::INFINITY`) into a class test of a dozen integer instructions.
#[inline(always)]
pub(crate) fn positive_finite(x: f32) -> bool {
    x.to_bits().wrapping_sub(1) < f32::MAX.to_bits()
}

/// A sampled direction towards a light.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Radiance arriving at the shading point from the light along `-wi`.
    pub radiance: Vec3,
    /// Unit direction from the shading point towards the light.
    pub wi: Vec3,
    /// Distance to the sampled point on the light (∞ for infinite lights).
    pub distance: f32,
    /// Solid-angle density of `wi`; 1 for delta lights.
    pub pdf: f32,
    pub is_delta: bool,
    /// The sampled point on the light and its normal (zero for points), for the shadow ray.
    pub p_light: Vec3,
    pub n_light: Vec3,
}

impl LightSample {
    /// The sample if it carries light with a positive, finite density: the check
    /// [`Light::sample_li`] applies to every light's sample.
    #[inline(always)]
    pub fn usable(self) -> Option<LightSample> {
        (positive_finite(self.pdf) && self.radiance != Vec3::ZERO).then_some(self)
    }

    /// The sample of point `p`, drawn uniformly by area on a flat one-sided emitter of
    /// normal `n` and `area`, seen from `from`: the area density turned into solid angle,
    /// d²/(cos θ_l · A). `radiance(wi)` gives the radiance leaving towards −`wi`. `None`
    /// where `p` is the shading point itself or faces away.
    #[inline]
    pub fn uniform_area(
        from: Vec3,
        p: Vec3,
        n: Vec3,
        area: f32,
        radiance: impl FnOnce(Vec3) -> Vec3,
    ) -> Option<LightSample> {
        let to = p - from;
        let d2 = to.length_squared();
        if d2 == 0.0 || area == 0.0 {
            return None;
        }
        let distance = d2.sqrt();
        let wi = to * (1.0 / distance);
        let cos_l = -wi.dot(n);
        if cos_l <= 0.0 {
            return None;
        }
        Some(LightSample {
            radiance: radiance(wi),
            wi,
            distance,
            pdf: d2 / (cos_l * area),
            is_delta: false,
            p_light: p,
            n_light: n,
        })
    }
}

/// Calls the same [`LightSource`] method on whichever light `$light` holds.
macro_rules! dispatch {
    ($light:expr, $l:ident => $call:expr) => {
        match $light {
            Light::Point($l) => $call,
            Light::Triangle($l) => $call,
            Light::Parallelogram($l) => $call,
            Light::Sphere($l) => $call,
            Light::Spot($l) => $call,
            Light::Goniometric($l) => $call,
            Light::Directional($l) => $call,
            Light::Projector($l) => $call,
            Light::Environment($l) => $call,
        }
    };
}

/// Every light Candela has: a closed enum on the hot path, each variant a
/// [`LightSource`].
#[derive(Clone, Debug)]
pub enum Light {
    Point(PointLight),
    Triangle(TriangleLight),
    Parallelogram(ParallelogramLight),
    Sphere(SphereLight),
    Spot(SpotLight),
    Goniometric(GoniometricLight),
    Directional(DirectionalLight),
    Projector(ProjectorLight),
    Environment(EnvironmentLight),
}

impl Light {
    /// How next event estimation draws points on this light, where it is a flat lamp (a
    /// triangle or a parallelogram); other lights have one way only.
    pub fn set_lamp_sampling(&mut self, sampling: LampSampling) {
        match self {
            Light::Triangle(t) => t.sampling = sampling,
            Light::Parallelogram(q) => q.sampling = sampling,
            _ => {}
        }
    }

    /// What kind of emitter this is.
    #[inline]
    pub fn flags(&self) -> LightFlags {
        dispatch!(self, l => flags_of(l))
    }

    /// A direction towards the light, with the radiance arriving along it and its
    /// density; `None` unless the sample carries light with a positive, finite density.
    ///
    /// Point lights and spots, a few instructions of arithmetic, are sampled inline where
    /// next event estimation calls this: out of line, the call, its saves and the sample
    /// returned through memory (copied once more by the usability check) cost as much as
    /// the light's own arithmetic (bench/RESULTS.md, shade: fourth round).
    #[inline(always)]
    pub fn sample_li(&self, ctx: &ShadingCtx, u: Vec2) -> Option<LightSample> {
        match self {
            Light::Point(l) => l.sample_li(ctx, u)?.usable(),
            Light::Spot(l) => l.sample_li(ctx, u)?.usable(),
            _ => self.sample_li_out_of_line(ctx, u),
        }
    }

    /// [`Self::sample_li`] of the other lights.
    #[inline(never)]
    fn sample_li_out_of_line(&self, ctx: &ShadingCtx, u: Vec2) -> Option<LightSample> {
        dispatch!(self, l => l.sample_li(ctx, u))?.usable()
    }

    /// Density in solid angle with which [`Self::sample_li`] picks direction `wi` at `ctx`.
    #[inline]
    pub fn pdf_li(&self, ctx: &ShadingCtx, wi: Vec3) -> f32 {
        dispatch!(self, l => l.pdf_li(ctx, wi))
    }

    /// Radiance leaving an area light at a point with geometric normal `n` and texture
    /// coordinates `uv` in direction `w`.
    #[inline]
    pub fn radiance(&self, n: Vec3, uv: Vec2, w: Vec3) -> Vec3 {
        dispatch!(self, l => l.radiance(n, uv, w))
    }

    /// Radiance an infinite light sends along an escaped ray.
    pub fn le(&self, ray: &Ray) -> Vec3 {
        dispatch!(self, l => l.le(ray))
    }

    /// [`Self::le`] along `ray` and [`Self::pdf_li`] of its direction at `ctx`, from
    /// one lookup where the light can (the same values as the two calls).
    #[inline]
    pub fn le_pdf(&self, ctx: &ShadingCtx, ray: &Ray) -> (Vec3, f32) {
        dispatch!(self, l => l.le_pdf(ctx, ray))
    }

    /// What an escaped camera ray sees of an infinite light: [`Self::le`], unless the
    /// light is hidden from the camera.
    pub fn le_camera(&self, ray: &Ray) -> Vec3 {
        match self {
            Light::Environment(l) => l.le_camera(ray),
            _ => self.le(ray),
        }
    }

    /// Total emitted power Φ, as a luminance-weighted scalar (W).
    pub fn power(&self) -> f32 {
        dispatch!(self, l => l.power())
    }

    /// Potential contribution at `ctx` up to a common constant, for choosing among lights
    /// (the RIS target): solid angle × brightness × the largest receiver cosine |n·ω|,
    /// or intensity ÷ d² for points. It is 0 only where the light provably sends nothing
    /// that a BSDF could scatter, e.g. a point behind a one-sided emitter; the receiver
    /// cosine is taken in absolute value so that transmitting BSDFs are not cut off.
    pub fn importance(&self, ctx: &ShadingCtx) -> f32 {
        dispatch!(self, l => l.importance(ctx))
    }

    /// What the light BVH keeps to weigh an infinite light at a shading point (its
    /// [`Self::importance`] without the light); `None` for the lights with bounds.
    pub fn infinite_importance(&self) -> Option<InfiniteImportance> {
        match self {
            Light::Directional(l) => Some(InfiniteImportance::Direction {
                irradiance: luminance(l.irradiance),
                wi: -l.direction,
            }),
            Light::Environment(l) => Some(InfiniteImportance::sky(&l.importance)),
            _ => None,
        }
    }

    /// Bounds for the light BVH; `None` for lights that are not bounded in space (infinite
    /// lights), which the BVH sampler picks apart from the tree.
    pub fn bounds(&self) -> Option<LightBounds> {
        dispatch!(self, l => l.bounds())
    }

    /// Whether the light is a delta in position or direction (see [`LightFlags`]).
    #[inline]
    pub fn is_delta(&self) -> bool {
        self.flags().is_delta()
    }

    /// Whether escaped rays see this light (environment lights).
    pub fn is_infinite(&self) -> bool {
        self.flags().contains(LightFlags::INFINITE)
    }
}

/// A variant's [`LightSource::FLAGS`], through a value.
#[inline(always)]
fn flags_of<L: LightSource>(_: &L) -> LightFlags {
    L::FLAGS
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `positive_finite` is the float test it replaces, on the edges of every class
    /// (zeros, subnormals, normals, infinities, NaNs of both signs) and on 10⁵ random bit
    /// patterns.
    #[test]
    fn positive_finite_is_positive_and_finite() {
        let want = |x: f32| x > 0.0 && x.is_finite();
        let mut edges = vec![
            0.0,
            -0.0,
            f32::from_bits(1),
            f32::MIN_POSITIVE,
            f32::MAX,
            f32::INFINITY,
            f32::NAN,
            1.0,
        ];
        edges.extend(edges.clone().iter().map(|x| -x));
        edges.extend([f32::from_bits(0x7f80_0001), f32::from_bits(0xffff_ffff)]);
        let mut rng = crate::sampler::Pcg32::new(3, 11);
        edges.extend((0..100_000).map(|_| f32::from_bits(rng.next_u32())));
        for x in edges {
            assert_eq!(positive_finite(x), want(x), "{x} ({:#x})", x.to_bits());
        }
    }
}
