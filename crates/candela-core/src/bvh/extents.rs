//! The binned SAH build's bookkeeping: primitive boxes, node and bin extents, in SIMD
//! vectors (`Vec3A`), since the build spends its time taking unions of them.

use glam::Vec3A;

use crate::geometry::Aabb;

/// A primitive's box during the build, in SIMD vectors. Centroids are kept doubled
/// (`min + max`), which bins exactly as the centroid does and saves a multiply.
#[derive(Clone, Copy)]
pub(super) struct PrimInfo {
    pub min: Vec3A,
    pub max: Vec3A,
    pub index: u32,
}

impl PrimInfo {
    #[inline(always)]
    pub fn centroid2(&self) -> Vec3A {
        self.min + self.max
    }
}

/// A box in SIMD vectors, for the build's many unions.
#[derive(Clone, Copy)]
pub(super) struct Box3A {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl Box3A {
    pub const EMPTY: Box3A = Box3A {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    #[inline(always)]
    pub fn grow(&mut self, p: Vec3A) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    #[inline(always)]
    pub fn union(&mut self, min: Vec3A, max: Vec3A) {
        self.min = self.min.min(min);
        self.max = self.max.max(max);
    }

    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: self.min.into(),
            max: self.max.into(),
        }
    }
}

/// What every node of the build knows of its primitives: their boxes' bounds and the
/// bounds of their (doubled) centroids, both gathered by the parent's binning pass.
#[derive(Clone, Copy)]
pub(super) struct Extents {
    pub bounds: Box3A,
    pub centroids: Box3A,
}

impl Extents {
    pub fn of(prims: &[PrimInfo]) -> Extents {
        let mut e = Extents {
            bounds: Box3A::EMPTY,
            centroids: Box3A::EMPTY,
        };
        for p in prims {
            e.add(p);
        }
        e
    }

    #[inline(always)]
    pub fn add(&mut self, p: &PrimInfo) {
        self.bounds.union(p.min, p.max);
        self.centroids.grow(p.centroid2());
    }

    pub fn merge(&mut self, o: &Extents) {
        self.bounds.union(o.bounds.min, o.bounds.max);
        self.centroids.union(o.centroids.min, o.centroids.max);
    }
}
