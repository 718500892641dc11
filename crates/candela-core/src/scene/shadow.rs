//! Shadow rays: the segment from a surface point to a point on a light, or the ray leaving
//! a surface towards an infinite light, made into the ray a query traces
//! ([`ShadowRay`]), and whether it is blocked: one at a time ([`Scene::visible`]) or the
//! shadow rays of eight paths together ([`Scene::occluded8`]).

use glam::{Vec3, Vec3A};

use super::interaction::{leaving_ray, negated_unless_a};
use super::Scene;
#[cfg(doc)]
use crate::accel::Accel;
use crate::geometry::Ray;
use crate::math::offset_ray_origin_a;

/// A shadow ray as a query takes it: the ray and the distance within which anything
/// blocks it, or, where the segment needs no query, whether it is unblocked.
#[derive(Clone, Copy, Debug)]
pub enum ShadowRay {
    /// Blocked where anything lies on the ray within (0, `t_max`).
    Traced { ray: Ray, t_max: f32 },
    /// No ray to trace: unblocked where `true` (the ends coincide), blocked where
    /// `false` (the segment is not finite).
    Known(bool),
}

impl ShadowRay {
    /// The segment from surface point `from` (normal `n_from`) to point `to` (normal
    /// `n_to`, zero for a point light). Both ends are moved off their surfaces so that
    /// neither surface blocks its own ray.
    ///
    /// The set-up runs in SIMD lanes ([`Vec3A`]): glam's lane dot product and length sum
    /// x, y, z in the order of [`Vec3`]'s, so the ray is the scalar code's bit for bit,
    /// for fewer instructions (no packing into lanes and back around the two offsets,
    /// vector subtractions and products). Inlined, so that the render loop's x86-64-v3
    /// copy gets it compiled for v3: out of line, one baseline copy served both loops.
    #[inline(always)]
    pub fn between(from: Vec3, n_from: Vec3, to: Vec3, n_to: Vec3) -> ShadowRay {
        let (from, n_from) = (Vec3A::from(from), Vec3A::from(n_from));
        let (to, n_to) = (Vec3A::from(to), Vec3A::from(n_to));
        let d = to - from;
        let o = offset_ray_origin_a(from, negated_unless_a(n_from, d.dot(n_from) >= 0.0));
        let target = if n_to == Vec3A::ZERO {
            to
        } else {
            offset_ray_origin_a(to, negated_unless_a(n_to, d.dot(n_to) <= 0.0))
        };
        let d = target - o;
        let dist = d.length();
        // Not 0 < dist < ∞ (NaN included): two compares, where `is_finite` was a dozen
        // integer instructions on the bits.
        if !(dist > 0.0 && dist < f32::INFINITY) {
            return ShadowRay::Known(dist == 0.0);
        }
        // A relative margin keeps the far end from blocking itself.
        ShadowRay::Traced {
            ray: Ray::new(o.into(), (d * (1.0 / dist)).into()),
            t_max: dist * (1.0 - 1e-4),
        }
    }

    /// The ray leaving surface point `from` (normal `n_from`) towards `d`, unbounded: it
    /// is unblocked where it escapes the scene.
    #[inline(always)]
    pub fn leaving(from: Vec3, n_from: Vec3, d: Vec3) -> ShadowRay {
        ShadowRay::Traced {
            ray: leaving_ray(from, n_from, d),
            t_max: f32::INFINITY,
        }
    }
}

impl Scene {
    /// Whether the shadow ray `shadow` is unblocked. Inlined, as [`Scene::occluded`].
    #[inline(always)]
    pub fn visible(&self, shadow: &ShadowRay) -> bool {
        match *shadow {
            ShadowRay::Traced { ray, t_max } => !self.occluded(&ray, t_max),
            ShadowRay::Known(unblocked) => unblocked,
        }
    }

    /// Whether the segment from surface point `from` (normal `n_from`) to point `to`
    /// (normal `n_to`, zero for a point light) is unblocked ([`ShadowRay::between`]).
    #[inline(always)]
    pub fn unoccluded(&self, from: Vec3, n_from: Vec3, to: Vec3, n_to: Vec3) -> bool {
        self.visible(&ShadowRay::between(from, n_from, to, n_to))
    }

    /// Whether a ray leaving `from` towards `d` escapes the scene ([`ShadowRay::leaving`]).
    #[inline(always)]
    pub fn escapes(&self, from: Vec3, n_from: Vec3, d: Vec3) -> bool {
        self.visible(&ShadowRay::leaving(from, n_from, d))
    }

    /// Which of the rays of `rays` that `active` names (bit `i`) are blocked within
    /// (0, `t_max[i]`): bit `i` set where [`Scene::occluded`] says ray `i` is, bit for
    /// bit. Where the scene packs rays ([`Scene::packs_camera_rays`]) the rays are
    /// traced together ([`Accel::occluded_coherent8`]), else one at a time.
    pub fn occluded8(&self, rays: &[Ray; 8], t_max: &[f32; 8], active: u32) -> u32 {
        if self.packs_camera_rays() {
            return self
                .accel
                .occluded_coherent8(rays, active, t_max, |i, prim, hit| {
                    self.alpha_accepts(prim, hit, &rays[i])
                });
        }
        (0..8).filter(|&i| active & (1 << i) != 0).fold(0, |m, i| {
            m | (self.occluded(&rays[i], t_max[i]) as u32) << i
        })
    }
}
