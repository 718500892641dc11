//! Spotlights: a point light whose intensity is full inside an inner cone, zero outside an
//! outer cone, and falls off between them along one of three stated curves.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{
    positional, LightBounds, LightFlags, LightProfile, LightSample, LightSource, ShadingCtx,
};
use crate::desc::SpotFalloff;
use crate::geometry::Aabb;
use crate::math::{luminance, Frame};

/// A spotlight at `position` aimed along `frame.n`: I(ω) = `intensity` · f(θ) · p(ω),
/// θ the angle between ω and the axis, f the [`SpotFalloff`] curve and p the relative
/// intensity of an optional profile aimed along the axis (1 without one).
///
/// With x = cos θ, t = clamp((x − cos θ_o)/(cos θ_i − cos θ_o), 0, 1):
/// - `Smoothstep` (pbrt-v4): f = t²(3 − 2t);
/// - `Gltf` (KHR_lights_punctual): f = t²;
/// - `Mitsuba` (Mitsuba 3 `spot`): f = clamp((θ_o − θ)/(θ_o − θ_i), 0, 1), linear in angle.
///
/// Inside the inner cone f = 1, outside the outer cone f = 0 (with θ_i = θ_o a hard edge).
#[derive(Clone, Debug)]
pub struct SpotLight {
    pub position: Vec3,
    pub frame: Frame,
    /// Intensity on the axis (W/sr).
    pub intensity: Vec3,
    pub falloff: SpotFalloff,
    pub profile: Option<LightProfile>,
    cos_inner: f32,
    cos_outer: f32,
    inner: f32,
    outer: f32,
    /// ∫ f(θ) p(ω) dω (sr).
    solid_angle: f32,
}

impl SpotLight {
    /// A spotlight; angles are half-angles from the axis in radians, 0 ≤ inner ≤ outer ≤ π.
    pub fn new(
        position: Vec3,
        direction: Vec3,
        inner: f32,
        outer: f32,
        falloff: SpotFalloff,
        intensity: Vec3,
        profile: Option<LightProfile>,
    ) -> SpotLight {
        let mut spot = SpotLight {
            position,
            frame: Frame::from_z(direction.normalize()),
            intensity,
            falloff,
            profile,
            cos_inner: inner.cos(),
            cos_outer: outer.cos(),
            inner,
            outer,
            solid_angle: 0.0,
        };
        spot.solid_angle = match &spot.profile {
            None => spot.cone_solid_angle(),
            Some(_) => spot.integrate_shape(),
        };
        spot
    }

    /// f(θ) for x = cos θ.
    #[inline]
    pub fn falloff_at(&self, cos_theta: f32) -> f32 {
        if cos_theta >= self.cos_inner {
            return 1.0;
        }
        if cos_theta <= self.cos_outer {
            return 0.0;
        }
        let t = ((cos_theta - self.cos_outer) / (self.cos_inner - self.cos_outer)).clamp(0.0, 1.0);
        match self.falloff {
            SpotFalloff::Smoothstep => t * t * (3.0 - 2.0 * t),
            SpotFalloff::Gltf => t * t,
            SpotFalloff::Mitsuba => {
                let theta = cos_theta.clamp(-1.0, 1.0).acos();
                ((self.outer - theta) / (self.outer - self.inner)).clamp(0.0, 1.0)
            }
        }
    }

    /// Radiant intensity (W/sr) towards the unit direction `w` leaving the light.
    #[inline]
    pub fn intensity_towards(&self, w: Vec3) -> Vec3 {
        let f = self.falloff_at(w.dot(self.frame.n));
        if f == 0.0 {
            return Vec3::ZERO;
        }
        let p = self.profile.as_ref().map_or(1.0, |p| p.relative(w));
        self.intensity * (f * p)
    }

    /// Whether the light can send anything towards `p`: false outside the outer cone.
    pub fn reaches(&self, p: Vec3) -> bool {
        let w = (p - self.position).normalize_or_zero();
        w != Vec3::ZERO && w.dot(self.frame.n) > self.cos_outer
    }

    /// ∫ f p dω (sr): the solid angle that turns the axis intensity into a power.
    pub fn solid_angle(&self) -> f32 {
        self.solid_angle
    }

    /// ∫ f dω in closed form: 2π [(1 − cos θ_i) + ∫_{cos θ_o}^{cos θ_i} f dx], where the
    /// falloff integral is (cos θ_i − cos θ_o)/2 for smoothstep, /3 for glTF, and
    /// (Δ cos θ_i + sin θ_i − sin θ_o)/Δ with Δ = θ_o − θ_i for Mitsuba's linear ramp
    /// (by parts: ∫ (θ_o − θ) sin θ dθ = −(θ_o − θ) cos θ − sin θ).
    pub fn cone_solid_angle(&self) -> f32 {
        let band = self.cos_inner - self.cos_outer;
        let ramp = if band <= 0.0 {
            0.0
        } else {
            match self.falloff {
                SpotFalloff::Smoothstep => band / 2.0,
                SpotFalloff::Gltf => band / 3.0,
                SpotFalloff::Mitsuba => {
                    let delta = self.outer - self.inner;
                    (delta * self.cos_inner + self.inner.sin() - self.outer.sin()) / delta
                }
            }
        };
        2.0 * PI * ((1.0 - self.cos_inner) + ramp)
    }

    /// ∫ f p dω by a midpoint rule over the outer cone (512 steps in cos θ × 512 in φ).
    fn integrate_shape(&self) -> f32 {
        const N: usize = 512;
        let lo = self.cos_outer;
        let mut sum = 0.0f64;
        for i in 0..N {
            let z = lo + (1.0 - lo) * (i as f32 + 0.5) / N as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            for j in 0..N {
                let phi = 2.0 * PI * (j as f32 + 0.5) / N as f32;
                let w = self
                    .frame
                    .to_world(Vec3::new(r * phi.cos(), r * phi.sin(), z));
                let p = self.profile.as_ref().map_or(1.0, |p| p.relative(w));
                sum += (self.falloff_at(z) * p) as f64;
            }
        }
        (sum * (1.0 - lo as f64) * 2.0 * std::f64::consts::PI / (N * N) as f64) as f32
    }

    /// Probability of drawing from the inner cone rather than the falloff band: their
    /// shares of ∫ f dω, taking the band's mean falloff as 1/2.
    fn inner_probability(&self) -> f32 {
        let inner = 1.0 - self.cos_inner;
        let band = 0.5 * (self.cos_inner - self.cos_outer);
        if band <= 0.0 {
            1.0
        } else {
            inner / (inner + band)
        }
    }

    /// An emission direction and its solid-angle density. Without a profile: uniform in
    /// the inner cone or uniform in the falloff band (in cos θ and φ), picked by
    /// `Self::inner_probability`; with one, the profile's table sampling.
    pub fn sample_emission(&self, u: Vec2) -> Option<(Vec3, f32)> {
        if let Some(p) = &self.profile {
            let (w, pdf) = p.sample(u);
            return (pdf > 0.0).then_some((w, pdf));
        }
        let p_in = self.inner_probability();
        let (lo, hi, ux) = if u.x < p_in {
            (self.cos_inner, 1.0, u.x / p_in)
        } else {
            (self.cos_outer, self.cos_inner, (u.x - p_in) / (1.0 - p_in))
        };
        let z = (hi - (hi - lo) * ux.min(1.0)).clamp(-1.0, 1.0);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let w = self
            .frame
            .to_world(Vec3::new(r * phi.cos(), r * phi.sin(), z));
        let pdf = self.emission_pdf(w);
        (pdf > 0.0).then_some((w, pdf))
    }

    /// Density of [`Self::sample_emission`].
    pub fn emission_pdf(&self, w: Vec3) -> f32 {
        if let Some(p) = &self.profile {
            return p.pdf(w);
        }
        let z = w.dot(self.frame.n);
        let p_in = self.inner_probability();
        if z >= self.cos_inner {
            if self.cos_inner >= 1.0 {
                return 0.0;
            }
            p_in / (2.0 * PI * (1.0 - self.cos_inner))
        } else if z > self.cos_outer {
            (1.0 - p_in) / (2.0 * PI * (self.cos_inner - self.cos_outer))
        } else {
            0.0
        }
    }
}

impl LightSource for SpotLight {
    const FLAGS: LightFlags = LightFlags::DELTA_POSITION;

    #[inline]
    fn sample_li(&self, ctx: &ShadingCtx, _u: Vec2) -> Option<LightSample> {
        positional::sample_li(self.position, ctx, |w| self.intensity_towards(w))
    }

    /// The exact potential contribution: luminance of I(ω)/d² towards `ctx` times the
    /// receiver cosine; exactly 0 where the light is dark towards the point.
    fn importance(&self, ctx: &ShadingCtx) -> f32 {
        positional::importance(self.position, ctx, |w| self.intensity_towards(w))
    }

    /// pbrt-v4's spotlight bounds (§12.6.3): full intensity within the inner cone
    /// (θ_o = θ_i) and emission reaching θ_o − θ_i further (θ_e). A profile only darkens.
    fn bounds(&self) -> Option<LightBounds> {
        Some(LightBounds {
            aabb: Aabb::from_points(&[self.position]),
            w: self.frame.n,
            intensity: luminance(self.intensity),
            cos_theta_o: self.cos_inner,
            cos_theta_e: (self.outer - self.inner).cos(),
            two_sided: false,
        })
    }

    /// Φ = I_axis · ∫ f p dω.
    fn power(&self) -> f32 {
        luminance(self.intensity) * self.solid_angle
    }
}
