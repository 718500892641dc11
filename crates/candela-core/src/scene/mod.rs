//! The render-time scene: flat arrays addressed by small ids, a BVH over all primitives,
//! and the queries the integrator asks of them.
//!
//! Here the [`Scene`] and its ray queries (nearest hit, occlusion); the meshes, spheres
//! and primitive ids in `mesh`; the hit record a query returns, and how it is made for
//! triangles and spheres, in `interaction`.

use glam::{Vec2, Vec3, Vec3A};

use crate::accel::Accel;
use crate::camera::Camera;
use crate::filter::PixelFilter;
use crate::geometry::{Aabb, Ray};
use crate::instance::Instances;
use crate::light::{Light, LightId};
use crate::light_sampler::LightSampler;
use crate::material::Material;
use crate::math::offset_ray_origin_a;
use crate::options::RenderOptions;

mod coherent;
mod interaction;
mod mesh;

pub use interaction::SurfaceInteraction;
use interaction::{instance_triangle_interaction, leaving_ray, negated_unless_a};
pub use mesh::{Mesh, Prim, ShadingRecord, Sphere};

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

    /// Whether the segment from surface point `from` (normal `n_from`) to point `to`
    /// (normal `n_to`, zero for a point light) is unblocked. Both ends are moved off their
    /// surfaces so that neither surface blocks its own ray.
    ///
    /// The set-up runs in SIMD lanes ([`Vec3A`]): glam's lane dot product and length sum
    /// x, y, z in the order of [`Vec3`]'s, so the ray is the scalar code's bit for bit,
    /// for fewer instructions (no packing into lanes and back around the two offsets,
    /// vector subtractions and products). Inlined, so that the render loop's x86-64-v3
    /// copy gets it compiled for v3: out of line, one baseline copy served both loops.
    #[inline(always)]
    pub fn unoccluded(&self, from: Vec3, n_from: Vec3, to: Vec3, n_to: Vec3) -> bool {
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
            return dist == 0.0;
        }
        // A relative margin keeps the far end from blocking itself.
        let ray = Ray::new(o.into(), (d * (1.0 / dist)).into());
        !self.occluded(&ray, dist * (1.0 - 1e-4))
    }

    /// Whether a ray leaving `from` towards `d` escapes the scene (inlined as
    /// [`Scene::unoccluded`]).
    #[inline(always)]
    pub fn escapes(&self, from: Vec3, n_from: Vec3, d: Vec3) -> bool {
        !self.occluded(&leaving_ray(from, n_from, d), f32::INFINITY)
    }
}
