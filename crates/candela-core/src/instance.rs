//! Instancing: a mesh that several shapes share is stored once, in object space, with its
//! own acceleration structure (the BLAS); each shape that places it is an [`Instance`]
//! with a transform, and a small binary BVH over the instances' world boxes (the TLAS)
//! finds the instances a ray meets.
//!
//! A ray is taken into an instance's object space by the inverse transform, its direction
//! not renormalised: o' + t·d' = W(o + t·d), so the object-space t is the world-space t and
//! hits of the BLAS and of the world-space [`crate::accel::Accel`] compare directly.
//! The hit record is then made from the hit triangle's vertices carried to world space by
//! the same [`Transform`] the build uses to flatten a mesh, so that it matches the
//! flattened mesh's record bit for bit at equal barycentrics; only t and the barycentrics
//! come from different arithmetic (the object-space ray).
//!
//! Which meshes are instanced is the build's choice (see [`crate::build`]): a mesh that
//! non-emitting shapes reference two or more times. Everything else, and every area light,
//! stays flattened in the world-space accelerator, so scenes without repetition take no
//! detour through here.

use glam::{Mat3, Mat4, Vec3, Vec4};

use crate::accel::{Accel, AccelLayout, Geometry, LeafLayout, NodeLayout, Simd, TriangleMesh};
use crate::alpha::AlphaMask;
use crate::bvh::Bvh;
use crate::desc::AccelStorage;
use crate::geometry::{Aabb, Ray, TriangleHit};
use crate::material::MaterialId;
use crate::scene::Mesh;

/// An affine object-to-world map with what carrying points, normals and tangents needs.
#[derive(Clone, Copy, Debug)]
pub struct Transform {
    pub to_world: Mat4,
    pub to_object: Mat4,
    linear: Mat3,
    /// The inverse transpose of `linear`, which keeps normals perpendicular to the surface.
    normal: Mat3,
    /// Whether the map mirrors (negative determinant).
    mirrors: bool,
}

impl Transform {
    /// `m` must be affine and invertible (the build checks).
    pub fn new(m: Mat4) -> Transform {
        let linear = Mat3::from_mat4(m);
        Transform {
            to_world: m,
            to_object: m.inverse(),
            linear,
            normal: linear.inverse().transpose(),
            mirrors: linear.determinant() < 0.0,
        }
    }

    pub fn point(&self, p: Vec3) -> Vec3 {
        self.to_world.transform_point3(p)
    }

    /// A unit normal carried by the inverse transpose.
    pub fn normal(&self, n: Vec3) -> Vec3 {
        (self.normal * n).normalize_or_zero()
    }

    /// A unit tangent carried by the linear part. A mirroring map reverses n × t against
    /// the carried bitangent, so it flips the handedness w.
    pub fn tangent(&self, t: Vec4) -> Vec4 {
        let w = if self.mirrors { -t.w } else { t.w };
        (self.linear * t.truncate()).normalize_or_zero().extend(w)
    }

    /// The box around the eight corners of `b` carried to world space.
    pub fn bounds(&self, b: Aabb) -> Aabb {
        if b.is_empty() {
            return b;
        }
        let corner = |i: u32| {
            Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            )
        };
        let world = (0..8).fold(Aabb::EMPTY, |acc, i| acc.grow(self.point(corner(i))));
        // Rounding in the corners' transform may shrink the box by an ulp or so; a
        // relative margin keeps every object-space hit inside it.
        let pad = (world.max - world.min).max(world.max.abs().max(world.min.abs())) * 1e-6;
        Aabb {
            min: world.min - pad,
            max: world.max + pad,
        }
    }
}

/// One placement of a shared mesh.
#[derive(Clone, Debug)]
pub struct Instance {
    /// Index into [`Instances::meshes`] (and [`Instances::blas`]).
    pub mesh: u32,
    pub transform: Transform,
    pub material: MaterialId,
    pub flip_normals: bool,
    pub alpha: Option<AlphaMask>,
}

/// A ray's nearest hit on an instance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InstanceHit {
    pub instance: u32,
    pub tri: u32,
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// The instanced part of a scene: object-space meshes, one BLAS each, the instances and
/// the TLAS over them. Empty in scenes without shared meshes.
#[derive(Clone, Debug, Default)]
pub struct Instances {
    /// Object-space meshes; their `material` and `flip_normals` are unused (each
    /// instance has its own) and they carry no lights.
    pub meshes: Vec<Mesh>,
    pub blas: Vec<Accel>,
    pub instances: Vec<Instance>,
    tlas: Bvh,
}

impl Instances {
    /// Builds a BLAS per mesh, its leaves as `storage` asks, and the TLAS over the
    /// instances. Hits on a mesh must pass the filter where some instance of it has
    /// alpha.
    pub fn new(meshes: Vec<Mesh>, instances: Vec<Instance>, storage: AccelStorage) -> Instances {
        let mut filtered = vec![false; meshes.len()];
        for i in &instances {
            filtered[i.mesh as usize] |= i.alpha.is_some();
        }
        let blas: Vec<Accel> = meshes
            .iter()
            .zip(&filtered)
            .map(|(m, &filtered)| {
                let mesh = TriangleMesh {
                    positions: &m.positions,
                    indices: &m.indices,
                    filtered,
                };
                let geometry = Geometry::new(vec![mesh], Vec::new());
                let layout = AccelLayout {
                    nodes: NodeLayout::Full,
                    leaves: LeafLayout::choose(storage, geometry.len()),
                };
                Accel::build_geometry(&geometry, Simd::best(), layout)
            })
            .collect();
        let boxes: Vec<Aabb> = instances
            .iter()
            .map(|i| i.transform.bounds(blas[i.mesh as usize].bounds()))
            .collect();
        let tlas = Bvh::build(&boxes);
        Instances {
            meshes,
            blas,
            instances,
            tlas,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.instances.is_empty()
    }

    pub fn bounds(&self) -> Aabb {
        self.tlas.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    /// Triangles stored (each shared mesh once).
    pub fn stored_triangles(&self) -> usize {
        self.meshes.iter().map(|m| m.indices.len()).sum()
    }

    /// Triangles as rendered (each instance's mesh counted per instance).
    pub fn instanced_triangles(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes[i.mesh as usize].indices.len())
            .sum()
    }

    /// The nearest hit within (0, t_max); `filter(instance, tri, hit, object_ray)`
    /// decides hits on meshes flagged as filtered.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: impl Fn(u32, u32, &TriangleHit) -> bool,
    ) -> Option<InstanceHit> {
        let mut best = None;
        self.traverse(ray, t_max, |inst, t_max| {
            let (i, local) = self.local_ray(inst, ray);
            match self.blas[i.mesh as usize].intersect(&local, t_max, |tri, h| filter(inst, tri, h))
            {
                Some(h) => {
                    best = Some(InstanceHit {
                        instance: inst,
                        tri: h.prim,
                        t: h.t,
                        b1: h.b1,
                        b2: h.b2,
                    });
                    (h.t, false)
                }
                None => (t_max, false),
            }
        });
        best
    }

    /// Whether an instance blocks the ray within (0, t_max).
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: impl Fn(u32, u32, &TriangleHit) -> bool,
    ) -> bool {
        let mut found = false;
        self.traverse(ray, t_max, |inst, t_max| {
            let (i, local) = self.local_ray(inst, ray);
            found =
                self.blas[i.mesh as usize].occluded(&local, t_max, |tri, h| filter(inst, tri, h));
            (t_max, found)
        });
        found
    }

    fn local_ray(&self, inst: u32, ray: &Ray) -> (&Instance, Ray) {
        let i = &self.instances[inst as usize];
        let w = &i.transform.to_object;
        (
            i,
            Ray::new(w.transform_point3(ray.o), w.transform_vector3(ray.d)),
        )
    }

    /// Visits the instances whose boxes the ray enters, near child first; `visit(instance,
    /// t_max)` returns the new t_max and whether to stop.
    #[inline]
    fn traverse(&self, ray: &Ray, t_max: f32, visit: impl FnMut(u32, f32) -> (f32, bool)) {
        self.tlas.traverse(ray, visit, t_max);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skewed(mirror: bool) -> Transform {
        let s = Vec3::new(if mirror { -2.0 } else { 2.0 }, 0.5, 1.5);
        Transform::new(Mat4::from_scale_rotation_translation(
            s,
            glam::Quat::from_rotation_y(0.7) * glam::Quat::from_rotation_x(0.3),
            Vec3::new(1.0, -2.0, 3.0),
        ))
    }

    #[test]
    fn normals_stay_perpendicular_and_tangents_keep_their_handedness() {
        for mirror in [false, true] {
            let xf = skewed(mirror);
            // A surface spanned by e1, e2 with normal e1 × e2.
            let (e1, e2) = (Vec3::new(1.0, 0.2, 0.0), Vec3::new(0.1, 1.0, 0.4));
            let n = xf.normal(e1.cross(e2));
            let (w1, w2) = (
                xf.point(e1) - xf.point(Vec3::ZERO),
                xf.point(e2) - xf.point(Vec3::ZERO),
            );
            assert!(n.dot(w1).abs() < 1e-5 && n.dot(w2).abs() < 1e-5, "{n}");
            assert!((n.length() - 1.0).abs() < 1e-6);
            // The winding's normal flips under a mirror; the carried normal does not.
            assert_eq!(w1.cross(w2).dot(n) < 0.0, mirror);
            let t = xf.tangent(e1.normalize().extend(1.0));
            assert!(t.truncate().abs_diff_eq(w1.normalize(), 1e-5));
            assert_eq!(t.w, if mirror { -1.0 } else { 1.0 });
            // The inverse takes world points back.
            let p = Vec3::new(0.3, -0.7, 2.0);
            assert!(xf
                .to_object
                .transform_point3(xf.point(p))
                .abs_diff_eq(p, 1e-5));
        }
    }

    #[test]
    fn world_bounds_hold_every_carried_point() {
        let xf = skewed(true);
        let b = Aabb {
            min: Vec3::new(-1.0, -2.0, 0.5),
            max: Vec3::new(3.0, 1.0, 0.75),
        };
        let w = xf.bounds(b);
        for i in 0..1000u32 {
            let f = |k: u32| ((i.wrapping_mul(2654435761) >> k) & 255) as f32 / 255.0;
            let p = b.min + (b.max - b.min) * Vec3::new(f(0), f(8), f(16));
            let q = xf.point(p);
            assert!(
                q.cmpge(w.min).all() && q.cmple(w.max).all(),
                "{q} outside {w:?}"
            );
        }
        assert!(xf.bounds(Aabb::EMPTY).is_empty());
    }
}
