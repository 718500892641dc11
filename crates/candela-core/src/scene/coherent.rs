//! Rays eight at a time (camera packets, and the rays of the lanes integrator's eight
//! paths): their closest hits from one packet query of the structure
//! ([`Accel::intersect_coherent8`]), and each hit's record made later, where the path
//! that ray starts needs it. The same hits and records as [`Scene::intersect`] gives each
//! ray, bit for bit.

use glam::Vec2;

use super::{Scene, SurfaceInteraction};
#[cfg(doc)]
use crate::accel::Accel;
use crate::accel::Hit;
use crate::geometry::Ray;

impl Scene {
    /// Whether [`Scene::intersect_coherent8`] and [`Scene::occluded8`] trace packets:
    /// the structure packs rays ([`Accel::packs_rays`]) and the scene has no instances
    /// (their structures take single rays).
    pub fn packs_camera_rays(&self) -> bool {
        self.instances.is_empty() && self.accel.packs_rays()
    }

    /// The nearest hit within (0, ∞) of each ray of `rays` that `active` names (bit `i`),
    /// as the structure reports it (`None` for the others); [`Scene::interaction_of`]
    /// makes its record. With [`Scene::packs_camera_rays`] only: instances are not
    /// searched.
    pub fn intersect_coherent8(&self, rays: &[Ray; 8], active: u32) -> [Option<Hit>; 8] {
        debug_assert!(self.instances.is_empty());
        self.accel
            .intersect_coherent8(rays, active, &[f32::INFINITY; 8], |i, prim, hit| {
                self.alpha_accepts(prim, hit, &rays[i])
            })
    }

    /// The record of `hit` (from [`Scene::intersect_coherent8`]) on `ray` for shading:
    /// what [`Scene::intersect_for_shading`] returns for that ray.
    #[inline(always)]
    pub fn interaction_of(&self, ray: &Ray, hit: Option<Hit>) -> Option<SurfaceInteraction> {
        let hit = hit?;
        let prim = self.prims[hit.prim as usize];
        self.interaction(ray, prim, hit.t, Vec2::new(hit.b1, hit.b2), true)
    }
}
