//! Conservative bounds on where and how strongly a light (or a group of lights) emits,
//! for the light BVH: a box, a peak radiant intensity and an emission cone (Conty Estevez
//! & Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting", in the
//! form of pbrt-v4 §12.6.3).

use std::f32::consts::PI;

use glam::Vec3;

use super::ShadingCtx;
use crate::geometry::Aabb;

/// Bounds of the emission of one light or of a set of lights.
///
/// Every emitting point lies in `aabb`; every emitting surface normal lies in the cone of
/// half-angle θ_o around `w` (`cos_theta_o`); light leaves a surface at most θ_e away from
/// its normal (`cos_theta_e`, cos(π/2) = 0 for Lambertian emitters); no direction carries
/// more than `intensity` (W/sr, luminance) at unit cosine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    pub aabb: Aabb,
    pub w: Vec3,
    pub intensity: f32,
    pub cos_theta_o: f32,
    pub cos_theta_e: f32,
    /// Whether the emitters also emit on the side opposite their normals.
    pub two_sided: bool,
}

/// cos(a − b) clamped to 1 where a < b, from sines and cosines.
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// sin(a − b) clamped to 0 where a < b.
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

impl LightBounds {
    /// Bounds of both `a` and `b`.
    pub fn union(a: &LightBounds, b: &LightBounds) -> LightBounds {
        if a.intensity == 0.0 {
            return *b;
        }
        if b.intensity == 0.0 {
            return *a;
        }
        let (w, cos_theta_o) = cone_union(a.w, a.cos_theta_o, b.w, b.cos_theta_o);
        LightBounds {
            aabb: a.aabb.union(b.aabb),
            w,
            intensity: a.intensity + b.intensity,
            cos_theta_o,
            cos_theta_e: a.cos_theta_e.min(b.cos_theta_e),
            two_sided: a.two_sided || b.two_sided,
        }
    }

    pub fn centroid(&self) -> Vec3 {
        self.aabb.center()
    }

    /// An upper bound, up to a constant, of the irradiance the bounded lights can send to
    /// `ctx` (pbrt-v4's `LightBounds::Importance`): intensity × the largest emission
    /// cosine towards the point ÷ the squared distance, times the largest cosine at the
    /// receiver where it has a normal. The receiver cosine is taken in absolute value so
    /// that transmitting surfaces are not cut off. Zero only where the cones prove that
    /// no emission reaches the point.
    pub fn importance(&self, ctx: &ShadingCtx) -> f32 {
        ImportanceBounds::new(self).importance(ctx)
    }
}

/// [`LightBounds`] in the form the importance needs, precomputed once per BVH node:
/// the box's bounding sphere and sin θ_o.
#[derive(Clone, Copy, Debug)]
pub struct ImportanceBounds {
    pub(crate) center: Vec3,
    pub(crate) radius: f32,
    pub(crate) w: Vec3,
    pub(crate) intensity: f32,
    pub(crate) cos_theta_o: f32,
    pub(crate) sin_theta_o: f32,
    pub(crate) cos_theta_e: f32,
    pub(crate) two_sided: bool,
}

impl ImportanceBounds {
    pub fn new(b: &LightBounds) -> ImportanceBounds {
        let center = b.aabb.center();
        ImportanceBounds {
            center,
            radius: (b.aabb.max - center).length(),
            w: b.w,
            intensity: b.intensity,
            cos_theta_o: b.cos_theta_o,
            sin_theta_o: safe_sqrt(1.0 - b.cos_theta_o * b.cos_theta_o),
            cos_theta_e: b.cos_theta_e,
            two_sided: b.two_sided,
        }
    }

    /// See [`LightBounds::importance`].
    #[inline]
    pub fn importance(&self, ctx: &ShadingCtx) -> f32 {
        let to = ctx.p - self.center;
        let d2 = to.length_squared();
        let inv_d = if d2 > 0.0 { d2.sqrt().recip() } else { 0.0 };
        let wi = if d2 > 0.0 { to * inv_d } else { Vec3::Z };
        // Clamp the distance so that points near or inside the box do not blow up (pbrt
        // clamps d² by half the box diagonal).
        let d2c = d2.max(self.radius);
        let mut cos_w = self.w.dot(wi);
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
        // The cone of directions from the point that the box's bounding sphere subtends.
        let (sin_b, cos_b) = if d2 <= self.radius * self.radius {
            (0.0, -1.0)
        } else {
            let sin_b = self.radius * inv_d;
            (sin_b, safe_sqrt(1.0 - sin_b * sin_b))
        };
        // θ' = max(0, θ_w − θ_o − θ_b): the smallest angle between an emitter's normal
        // and the direction to the point.
        let cos_x = cos_sub_clamped(sin_w, cos_w, self.sin_theta_o, self.cos_theta_o);
        let sin_x = sin_sub_clamped(sin_w, cos_w, self.sin_theta_o, self.cos_theta_o);
        let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
        // Strictly beyond θ_e only: a light with θ_e = 0 (a projector's or a hard-edged
        // spot's cone, emission exactly within θ_o) gives cos θ' = 1 inside its cone.
        if cos_p < self.cos_theta_e {
            return 0.0;
        }
        let mut importance = self.intensity * cos_p / d2c;
        if ctx.n != Vec3::ZERO {
            let cos_i = wi.dot(ctx.n).abs();
            let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
            importance *= cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
        }
        importance.max(0.0)
    }
}

/// The smallest cone (axis, cos half-angle) containing two cones (pbrt-v4 §3.8.4).
pub fn cone_union(wa: Vec3, cos_a: f32, wb: Vec3, cos_b: f32) -> (Vec3, f32) {
    if wa == wb {
        return (wa, cos_a.min(cos_b));
    }
    let theta_a = cos_a.clamp(-1.0, 1.0).acos();
    let theta_b = cos_b.clamp(-1.0, 1.0).acos();
    let theta_d = wa.dot(wb).clamp(-1.0, 1.0).acos();
    if (theta_d + theta_b).min(PI) <= theta_a {
        return (wa, cos_a);
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return (wb, cos_b);
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if theta_o >= PI {
        return (wa, -1.0);
    }
    let wr = wa.cross(wb);
    if wr.length_squared() < 1e-12 {
        return (wa, -1.0);
    }
    let theta_r = theta_o - theta_a;
    let w = glam::Quat::from_axis_angle(wr.normalize(), theta_r) * wa;
    // Round-off may leave an input cone a hair outside; widen slightly to stay conservative.
    (w.normalize(), (theta_o + 1e-4).min(PI).cos())
}

/// Solid angle of a cone of half-angle θ_o around normals that emit up to θ_e beyond it,
/// weighted by cosine (pbrt-v4's M_Ω, the orientation term of the SAOH cost).
pub fn cone_measure(cos_theta_o: f32, cos_theta_e: f32) -> f32 {
    let theta_o = cos_theta_o.clamp(-1.0, 1.0).acos();
    let theta_e = cos_theta_e.clamp(-1.0, 1.0).acos();
    let theta_w = (theta_o + theta_e).min(PI);
    let sin_o = safe_sqrt(1.0 - cos_theta_o * cos_theta_o);
    2.0 * PI * (1.0 - cos_theta_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                + cos_theta_o)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cone with no falloff (θ_e = 0, a projector's) has importance inside its cone and
    /// none outside.
    #[test]
    fn a_cone_without_falloff_is_important_inside_it() {
        let b = LightBounds {
            aabb: Aabb::from_points(&[Vec3::new(0.0, 2.0, 0.0)]),
            w: -Vec3::Y,
            intensity: 1.0,
            cos_theta_o: 30f32.to_radians().cos(),
            cos_theta_e: 1.0,
            two_sided: false,
        };
        let at = |x: f32| {
            b.importance(&ShadingCtx {
                p: Vec3::new(x, 0.0, 0.0),
                n: Vec3::Y,
            })
        };
        // tan 30° · 2 ≈ 1.155: the cone's edge on the floor.
        assert!(at(0.0) > 0.0 && at(1.1) > 0.0);
        assert_eq!(at(1.3), 0.0);
    }
}
