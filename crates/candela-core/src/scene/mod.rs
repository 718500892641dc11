//! The render-time scene: flat arrays addressed by small ids, a BVH over all primitives,
//! and the queries the integrator asks of them.
//!
//! Here the [`Scene`] and its ray queries (nearest hit, occlusion); the meshes, spheres
//! and primitive ids in `mesh`; the hit record a query returns, and how it is made for
//! triangles and spheres, in `interaction`; shadow rays and their visibility, one at a
//! time or eight together, in `shadow`.

use glam::Vec2;

use crate::accel::Accel;
use crate::camera::Camera;
use crate::filter::PixelFilter;
use crate::geometry::{Aabb, Ray};
use crate::instance::Instances;
use crate::light::{Light, LightId};
use crate::light_sampler::LightSampler;
use crate::material::Material;
use crate::options::RenderOptions;

mod coherent;
mod interaction;
mod mesh;
mod shadow;

use interaction::instance_triangle_interaction;
pub use interaction::SurfaceInteraction;
pub use mesh::{Mesh, Prim, ShadingRecord, Sphere};
pub use shadow::ShadowRay;

/// The scene as the integrator sees it. Made by [`crate::build::build`].
#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: Camera,
    pub filter: PixelFilter,
    pub settings: RenderOptions,
    pub meshes: Vec<Mesh>,
    pub spheres: Vec<Sphere>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    /// Lights that escaped rays see.
    pub infinite_lights: Vec<LightId>,
    pub light_sampler: LightSampler,
    /// Every primitive, in the order of [`Scene::accel`]'s primitive indices.
    pub prims: Vec<Prim>,
    pub accel: Accel,
    /// Meshes shared by several shapes, stored once and placed by transforms.
    pub instances: Instances,
    /// Participating media and null surfaces; where set, the volumetric path tracer renders.
    pub media: Option<Box<crate::medium::SceneMedia>>,
}

impl Scene {
    pub fn bounds(&self) -> Aabb {
        self.accel.bounds().union(self.instances.bounds())
    }

    /// Triangles as rendered: each instance counts its mesh's triangles.
    pub fn triangle_count(&self) -> usize {
        self.flat_triangle_count() + self.instances.instanced_triangles()
    }

    /// Triangles held in memory: flattened meshes plus each shared mesh once.
    pub fn stored_triangle_count(&self) -> usize {
        self.flat_triangle_count() + self.instances.stored_triangles()
    }

    fn flat_triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.indices.len()).sum()
    }

    #[inline]
    pub fn light(&self, id: LightId) -> &Light {
        &self.lights[id.0 as usize]
    }

    /// The nearest surface along the ray within (0, t_max), its hit record complete.
    ///
    /// Inlined, with the instances and spheres out of line: the hit record of a flat
    /// triangle, the common case, is built in the caller with no call. (Inlining the rare
    /// paths too, so that no record comes back through memory, measured no faster.)
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<SurfaceInteraction> {
        self.nearest::<false>(ray, t_max)
    }

    /// [`Scene::intersect`] for shading: the record's uvs, ∂p/∂u and bitangent sign are
    /// placeholders where nothing that shades the hit reads them (its mesh's
    /// [`Mesh::shading_record`]), and not computed. The path integrator's query.
    #[inline(always)]
    pub fn intersect_for_shading(&self, ray: &Ray, t_max: f32) -> Option<SurfaceInteraction> {
        self.nearest::<true>(ray, t_max)
    }

    /// [`Scene::intersect`], the record as [`Scene::intersect_for_shading`]'s where
    /// `SHADING`.
    #[inline(always)]
    fn nearest<const SHADING: bool>(&self, ray: &Ray, t_max: f32) -> Option<SurfaceInteraction> {
        let hit = self
            .accel
            .intersect(ray, t_max, |i, hit| self.alpha_accepts(i, hit, ray));
        if !self.instances.is_empty() {
            if let Some(si) = self.intersect_instances(ray, hit.map_or(t_max, |h| h.t)) {
                return Some(si);
            }
        }
        let hit = hit?;
        let prim = self.prims[hit.prim as usize];
        self.interaction(ray, prim, hit.t, Vec2::new(hit.b1, hit.b2), SHADING)
    }

    /// The nearest instanced surface along the ray within (0, t_max).
    #[inline(never)]
    fn intersect_instances(&self, ray: &Ray, t_max: f32) -> Option<SurfaceInteraction> {
        let filter = |inst, tri, hit: &_| self.instance_alpha_accepts(inst, tri, hit, ray);
        let h = self.instances.intersect(ray, t_max, filter)?;
        let inst = &self.instances.instances[h.instance as usize];
        let m = &self.instances.meshes[inst.mesh as usize];
        instance_triangle_interaction(m, inst, h.tri, h.t, Vec2::new(h.b1, h.b2))
    }

    /// Whether anything lies on the ray within (0, t_max).
    ///
    /// Inlined, with the instances out of line (as in [`Scene::intersect`]).
    #[inline(always)]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.accel
            .occluded(ray, t_max, |i, hit| self.alpha_accepts(i, hit, ray))
            || (!self.instances.is_empty() && self.occluded_instances(ray, t_max))
    }

    /// Whether an instanced surface lies on the ray within (0, t_max).
    #[inline(never)]
    fn occluded_instances(&self, ray: &Ray, t_max: f32) -> bool {
        self.instances.occluded(ray, t_max, |inst, tri, hit| {
            self.instance_alpha_accepts(inst, tri, hit, ray)
        })
    }
}
