use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{flat_importance, LightBounds, LightProfile, LightSample, ShadingCtx};
use crate::geometry::Aabb;
use crate::geometry::{Ray, WatertightRay};
use crate::math::luminance;
use crate::sampling::sample_uniform_triangle;

/// One emitting triangle of a mesh. Emits `le` on the side its normal `n` points to.
/// Sampled uniformly by area; the density is converted to solid angle at the shading
/// point, p_ω = d² / (|cos θ_l| · A).
///
/// With a `profile` (an IES-shaped area light) the radiance leaving towards ω is
/// `le` · I(ω)/I_max, the profile's nadir along `n`: each point of the surface emits with
/// the profile's shape times the Lambertian cos θ, so the triangle's intensity is
/// A · `le` · cos θ · I(ω)/I_max. Sampling stays uniform by area (its density does not
/// depend on the emitted radiance; only the value does).
#[derive(Clone, Debug)]
pub struct TriangleLight {
    pub p: [Vec3; 3],
    pub n: Vec3,
    pub area: f32,
    pub le: Vec3,
    pub profile: Option<LightProfile>,
    /// ∫ (radiance / `le`) cos θ dω over the hemisphere: π without a profile.
    pub projected_solid_angle: f32,
}

impl TriangleLight {
    /// A light for a triangle with unit normal `n` (the emitting side).
    pub fn new(p: [Vec3; 3], n: Vec3, le: Vec3) -> TriangleLight {
        let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
        TriangleLight {
            p,
            n,
            area,
            le,
            profile: None,
            projected_solid_angle: PI,
        }
    }

    /// The same triangle shaped by `profile` (its nadir should be `n`), whose
    /// [`LightProfile::projected_solid_angle`] is `projected`.
    pub fn with_profile(self, profile: LightProfile, projected: f32) -> TriangleLight {
        TriangleLight {
            profile: Some(profile),
            projected_solid_angle: projected,
            ..self
        }
    }

    /// Radiance leaving towards the unit direction `w` on the emitting side.
    fn emitted(&self, w: Vec3) -> Vec3 {
        match &self.profile {
            None => self.le,
            Some(p) => self.le * p.relative(w),
        }
    }

    pub fn sample_li(&self, ctx: &ShadingCtx, u: Vec2) -> Option<LightSample> {
        let b = sample_uniform_triangle(u);
        let p = self.p[0] * b.x + self.p[1] * b.y + self.p[2] * b.z;
        LightSample::uniform_area(ctx.p, p, self.n, self.area, |wi| self.emitted(-wi))
    }

    pub fn pdf_li(&self, ctx: &ShadingCtx, wi: Vec3) -> f32 {
        let cos_l = -wi.dot(self.n);
        if cos_l <= 0.0 || self.area == 0.0 {
            return 0.0;
        }
        let ray = Ray::new(ctx.p, wi);
        match WatertightRay::new(&ray).intersect(self.p[0], self.p[1], self.p[2], f32::INFINITY) {
            Some(hit) => hit.t * hit.t / (cos_l * self.area),
            None => 0.0,
        }
    }

    pub fn radiance(&self, n: Vec3, w: Vec3) -> Vec3 {
        if n.dot(w) > 0.0 {
            self.emitted(w)
        } else {
            Vec3::ZERO
        }
    }

    /// Φ = A · L · ∫ shape · cos θ dω: π · A · L for a one-sided Lambertian emitter.
    pub fn power(&self) -> f32 {
        self.projected_solid_angle * self.area * luminance(self.le)
    }

    /// L × Ω × the largest |cos| at the receiver over the three corners, where Ω is the
    /// exact solid angle of the triangle (Van Oosterom & Strackee 1983):
    /// tan(Ω/2) = |a·(b×c)| / (abc + (a·b)c + (a·c)b + (b·c)a).
    /// Zero where the point lies behind the emitting side: the plane through the triangle
    /// separates the point from the whole emitting hemisphere, so nothing reaches it.
    pub fn importance(&self, ctx: &ShadingCtx) -> f32 {
        if (ctx.p - self.p[0]).dot(self.n) <= 0.0 || self.area == 0.0 {
            return 0.0;
        }
        let [a, b, c] = self.p.map(|q| q - ctx.p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let omega = solid_angle([a, b, c], [la, lb, lc]);
        flat_importance(ctx, self.le, omega, &[a / la, b / lb, c / lc])
    }

    /// One-sided Lambertian emitter: normal cone of zero width, emission up to 90°;
    /// peak intensity L·A along the normal.
    pub fn bounds(&self) -> LightBounds {
        LightBounds {
            aabb: Aabb::from_points(&self.p),
            w: self.n,
            intensity: luminance(self.le) * self.area,
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        }
    }
}

/// Solid angle of the triangle with corners `v` relative to the viewer, whose lengths are
/// `len` (Van Oosterom & Strackee 1983).
pub(super) fn solid_angle(v: [Vec3; 3], len: [f32; 3]) -> f32 {
    let ([a, b, c], [la, lb, lc]) = (v, len);
    let num = a.dot(b.cross(c)).abs();
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}
