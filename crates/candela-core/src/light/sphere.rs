use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::source::one_sided;
use super::{LightBounds, LightFlags, LightSample, LightSource, ShadingCtx};
use crate::geometry::Aabb;
use crate::geometry::{intersect_sphere, Ray};
use crate::math::{luminance, Frame};
use crate::sampling::{sample_uniform_cone, sample_uniform_sphere, uniform_cone_pdf};

/// An emitting sphere. With `inward = false` it emits `le` outwards and, seen from outside,
/// is sampled uniformly within the cone it subtends (pbrt-v4 §6.2.4); otherwise (emitting
/// inwards, or a shading point inside it) it is sampled uniformly by area.
#[derive(Clone, Debug)]
pub struct SphereLight {
    pub center: Vec3,
    pub radius: f32,
    pub le: Vec3,
    pub inward: bool,
}

impl SphereLight {
    fn sees_outside(&self, p: Vec3) -> Option<f32> {
        let d2 = (p - self.center).length_squared();
        let r2 = self.radius * self.radius;
        // cos θ_max of the subtended cone, if the point is clearly outside.
        (!self.inward && d2 > r2 * 1.0001).then(|| (1.0 - r2 / d2).max(0.0).sqrt())
    }

    fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }
}

impl LightSource for SphereLight {
    const FLAGS: LightFlags = LightFlags::SURFACE;

    fn sample_li(&self, ctx: &ShadingCtx, u: Vec2) -> Option<LightSample> {
        if let Some(cos_max) = self.sees_outside(ctx.p) {
            let axis = (self.center - ctx.p).normalize();
            let local = sample_uniform_cone(u, cos_max);
            let wi = Frame::from_z(axis).to_world(local).normalize();
            // The point where wi first meets the sphere; at the cone's rim, the tangent point.
            let ray = Ray::new(ctx.p, wi);
            let t = intersect_sphere(&ray, self.center, self.radius, f32::INFINITY)
                .unwrap_or_else(|| (self.center - ctx.p).dot(wi));
            let n = (ray.at(t) - self.center).normalize();
            let p_light = self.center + n * self.radius;
            return Some(LightSample {
                radiance: self.le,
                wi,
                distance: t,
                pdf: uniform_cone_pdf(cos_max),
                is_delta: false,
                p_light,
                n_light: n,
            });
        }
        let n_out = sample_uniform_sphere(u);
        let p = self.center + n_out * self.radius;
        let n = if self.inward { -n_out } else { n_out };
        let to = p - ctx.p;
        let d2 = to.length_squared();
        if d2 == 0.0 {
            return None;
        }
        let distance = d2.sqrt();
        let wi = to / distance;
        let cos_l = -wi.dot(n);
        if cos_l <= 0.0 {
            return None;
        }
        Some(LightSample {
            radiance: self.le,
            wi,
            distance,
            pdf: d2 / (cos_l * self.area()),
            is_delta: false,
            p_light: p,
            n_light: n,
        })
    }

    fn pdf_li(&self, ctx: &ShadingCtx, wi: Vec3) -> f32 {
        if let Some(cos_max) = self.sees_outside(ctx.p) {
            let axis = (self.center - ctx.p).normalize();
            return if wi.dot(axis) >= cos_max {
                uniform_cone_pdf(cos_max)
            } else {
                0.0
            };
        }
        // Area sampling: the density of the first surface point along wi. A point inside
        // sees exactly one point of the sphere in each direction.
        let ray = Ray::new(ctx.p, wi);
        let Some(t) = intersect_sphere(&ray, self.center, self.radius, f32::INFINITY) else {
            return 0.0;
        };
        let n_out = (ray.at(t) - self.center) / self.radius;
        let n = if self.inward { -n_out } else { n_out };
        let cos_l = -wi.dot(n);
        if cos_l <= 0.0 {
            return 0.0;
        }
        t * t / (cos_l * self.area())
    }

    fn radiance(&self, n: Vec3, _uv: Vec2, w: Vec3) -> Vec3 {
        one_sided(n, w, self.le)
    }

    fn power(&self) -> f32 {
        PI * self.area() * luminance(self.le)
    }

    /// Seen from outside: L × the subtended solid angle 2π(1 − cos θ_max) × the largest
    /// |cos| at the receiver over that cone. Inside (or emitting inwards): L × 4π.
    fn importance(&self, ctx: &ShadingCtx) -> f32 {
        let lum = luminance(self.le);
        let Some(cos_max) = self.sees_outside(ctx.p) else {
            return lum * 4.0 * PI;
        };
        let omega = 2.0 * PI * (1.0 - cos_max);
        let cos_r = if ctx.n == Vec3::ZERO {
            1.0
        } else {
            // Angle from the axis to the nearer of ±n, reduced by the cone's half-angle.
            let axis = (self.center - ctx.p).normalize();
            let theta = axis.dot(ctx.n).abs().min(1.0).acos();
            let theta_max = cos_max.min(1.0).acos();
            // 90° − θ is the angle to the tangent plane; |cos| is largest nearest ±n.
            (theta - theta_max).max(0.0).cos()
        };
        lum * omega.max(1e-12) * cos_r.max(1e-6)
    }

    /// Normals in every direction; peak intensity L·πr² (the projected disk).
    fn bounds(&self) -> Option<LightBounds> {
        let r = Vec3::splat(self.radius);
        Some(LightBounds {
            aabb: Aabb {
                min: self.center - r,
                max: self.center + r,
            },
            w: Vec3::Z,
            intensity: luminance(self.le) * PI * self.radius * self.radius,
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        })
    }
}
