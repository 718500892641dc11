//! The ray-tracing acceleration structure: a [`WideBvh`] over the scene's primitives,
//! with the primitives copied into the BVH's leaf order so that a leaf's triangles sit
//! side by side in memory, vertices inline (no index → mesh → position chase).
//!
//! Triangles keep the watertight test (Woop et al. 2013) on the same vertex values as
//! the meshes, so a hit's distance is the same bits as the mesh's own test. Each record
//! carries flag bits: a sphere, or a triangle whose hits must pass a filter (alpha
//! masks). Unflagged triangles never call the filter; a flagged one calls it after its
//! barycentrics are known, and traversal goes on past it when the filter rejects.

use glam::Vec3;

use crate::bvh::{Bvh, WideBvh};
use crate::geometry::{intersect_sphere, Aabb, Ray, TriangleHit, WatertightRay};

/// A primitive handed to [`Accel::build`].
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    Triangle([Vec3; 3]),
    Sphere { center: Vec3, radius: f32 },
}

impl Shape {
    pub fn bounds(&self) -> Aabb {
        match *self {
            Shape::Triangle(v) => Aabb::from_points(&v),
            Shape::Sphere { center, radius } => Aabb {
                min: center - Vec3::splat(radius),
                max: center + Vec3::splat(radius),
            },
        }
    }
}

/// What a ray hit: the primitive's index in the list given to [`Accel::build`], the
/// distance, and for a triangle the barycentrics of its vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub prim: u32,
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

const SPHERE: u32 = 1 << 31;
const FILTERED: u32 = 1 << 30;
const ID_MASK: u32 = FILTERED - 1;

/// A primitive in leaf order: a triangle's three vertices, or a sphere's centre in
/// `v[0]` and radius in `v[1].x`; `id` is the primitive index with the flag bits.
#[derive(Clone, Copy, Debug)]
struct LeafPrim {
    v: [Vec3; 3],
    id: u32,
}

/// Accepts every hit: the filter of scenes without alpha masks.
pub fn accept_all(_: u32, _: &TriangleHit) -> bool {
    true
}

#[derive(Clone, Debug, Default)]
pub struct Accel {
    bvh: WideBvh,
    prims: Vec<LeafPrim>,
}

impl Accel {
    /// Builds over `shapes`; `filtered(i)` says whether hits on triangle `i` must pass
    /// the filter. Primitives with empty or non-finite boxes are left out.
    pub fn build(shapes: &[Shape], filtered: impl Fn(u32) -> bool) -> Accel {
        assert!(
            shapes.len() < ID_MASK as usize,
            "at most 2^30 primitives per scene"
        );
        let boxes: Vec<Aabb> = shapes.iter().map(Shape::bounds).collect();
        let binary = Bvh::build(&boxes);
        let prims = binary
            .prims
            .iter()
            .map(|&i| match shapes[i as usize] {
                Shape::Triangle(v) => LeafPrim {
                    v,
                    id: i | if filtered(i) { FILTERED } else { 0 },
                },
                Shape::Sphere { center, radius } => LeafPrim {
                    v: [center, Vec3::new(radius, 0.0, 0.0), Vec3::ZERO],
                    id: i | SPHERE,
                },
            })
            .collect();
        Accel {
            bvh: WideBvh::collapse(&binary),
            prims,
        }
    }

    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// The nearest hit within (0, t_max); hits on flagged triangles count only where
    /// `filter` accepts them.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<Hit> {
        let wray = WatertightRay::new(ray);
        let mut best: Option<Hit> = None;
        self.bvh.intersect(ray, t_max, |first, count, mut t_max| {
            let first = first as usize;
            for p in &self.prims[first..first + count as usize] {
                if p.id & SPHERE != 0 {
                    if let Some(t) = intersect_sphere(ray, p.v[0], p.v[1].x, t_max) {
                        t_max = t;
                        best = Some(Hit {
                            prim: p.id & ID_MASK,
                            t,
                            b1: 0.0,
                            b2: 0.0,
                        });
                    }
                } else if let Some(h) = wray.intersect(p.v[0], p.v[1], p.v[2], t_max) {
                    if p.id & FILTERED != 0 && !filter(p.id & ID_MASK, &h) {
                        continue;
                    }
                    t_max = h.t;
                    best = Some(Hit {
                        prim: p.id & ID_MASK,
                        t: h.t,
                        b1: h.b1,
                        b2: h.b2,
                    });
                }
            }
            t_max
        });
        best
    }

    /// Whether anything accepted by `filter` lies on the ray within (0, t_max); stops
    /// at the first blocker found.
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: impl Fn(u32, &TriangleHit) -> bool,
    ) -> bool {
        let wray = WatertightRay::new(ray);
        self.bvh.occluded(ray, t_max, |first, count, t_max| {
            let first = first as usize;
            self.prims[first..first + count as usize].iter().any(|p| {
                if p.id & SPHERE != 0 {
                    intersect_sphere(ray, p.v[0], p.v[1].x, t_max).is_some()
                } else {
                    wray.intersect(p.v[0], p.v[1], p.v[2], t_max)
                        .is_some_and(|h| p.id & FILTERED == 0 || filter(p.id & ID_MASK, &h))
                }
            })
        })
    }
}
