//! The shadow rays of a bounce's next event estimation where the scene packs rays: held
//! lane by lane while the scalar stage shades each lane, then traced together
//! ([`Scene::occluded8`]: eight rays in lanes) and each unblocked lane's light added to
//! its radiance, as the path integrator adds it after its own shadow ray. (Elsewhere a
//! lane traces its shadow ray at once: holding it cost the scenes of several nodes
//! 40–50 instructions a path for nothing.)

use glam::Vec3;

use super::simd::LANES;
use crate::geometry::Ray;
use crate::scene::{Scene, ShadowRay};

/// One bounce's light samples of every lane, their shadow rays not yet traced.
pub(super) struct ShadowLanes {
    /// What a lane adds to its radiance (its throughput included) where its shadow ray is
    /// unblocked.
    light: [Vec3; LANES],
    /// The lanes' shadow rays and the distances within which they are blocked.
    rays: [Ray; LANES],
    t_max: [f32; LANES],
    /// Lanes with a shadow ray to trace (bit `i` for lane `i`).
    traced: u32,
    /// Lanes whose light needs no ray: it is added as it is.
    lit: u32,
}

impl ShadowLanes {
    pub fn new() -> ShadowLanes {
        ShadowLanes {
            light: [Vec3::ZERO; LANES],
            rays: [Ray::new(Vec3::ZERO, Vec3::Z); LANES],
            t_max: [0.0; LANES],
            traced: 0,
            lit: 0,
        }
    }

    /// Forgets the last bounce's samples.
    #[inline(always)]
    pub fn clear(&mut self) {
        self.traced = 0;
        self.lit = 0;
    }

    /// Holds lane `i`'s light `light`, to be added where `shadow` is unblocked.
    #[inline(always)]
    pub fn hold(&mut self, i: usize, light: Vec3, shadow: ShadowRay) {
        match shadow {
            ShadowRay::Traced { ray, t_max } => {
                self.light[i] = light;
                self.rays[i] = ray;
                self.t_max[i] = t_max;
                self.traced |= 1 << i;
            }
            ShadowRay::Known(true) => {
                self.light[i] = light;
                self.lit |= 1 << i;
            }
            ShadowRay::Known(false) => {}
        }
    }

    /// Traces the held shadow rays and adds each unblocked lane's light to its radiance
    /// `l[i]`. (A blocked lane's light is not added, where the path integrator adds
    /// zero: the same radiance, which is never −0.)
    #[inline(always)]
    pub fn finish(&self, scene: &Scene, l: &mut [Vec3; LANES]) {
        let blocked = if self.traced != 0 {
            scene.occluded8(&self.rays, &self.t_max, self.traced)
        } else {
            0
        };
        let mut unblocked = (self.traced & !blocked) | self.lit;
        while unblocked != 0 {
            let i = unblocked.trailing_zeros() as usize;
            unblocked &= unblocked - 1;
            l[i] += self.light[i];
        }
    }
}
