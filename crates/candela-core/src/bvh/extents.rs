//! The binned SAH build's bookkeeping: primitive boxes, node and bin extents, in SIMD
//! vectors (`Vec3A`), since the build spends its time taking unions of them.

use glam::{Vec3A, Vec4};

use crate::geometry::Aabb;

/// A primitive's box during the build, in SIMD vectors, and its index: 32 bytes (the
/// index rides in the unused fourth lane of `max`; a separate field made it 48, which at
/// the build's peak was a third of an 8M-triangle scene's memory).
#[derive(Clone, Copy)]
pub(super) struct PrimInfo {
    pub min: Vec3A,
    /// The box's max in x, y, z; in w the index, as the bits of a finite float ≥ 1 (the
    /// index plus [`PrimInfo::INDEX_BIAS`]), never a denormal or NaN that would slow the
    /// lane's arithmetic, which nothing reads.
    max_index: Vec4,
}

impl PrimInfo {
    /// The bits of 1.0: with an index below 2³⁰ the sum stays at or below `f32::MAX`.
    const INDEX_BIAS: u32 = 0x3f80_0000;

    /// The largest index a record holds.
    pub const MAX_INDEX: u32 = (1 << 30) - 1;

    #[inline(always)]
    pub fn new(min: Vec3A, max: Vec3A, index: u32) -> PrimInfo {
        debug_assert!(index <= PrimInfo::MAX_INDEX);
        PrimInfo {
            min,
            max_index: max.extend(f32::from_bits(PrimInfo::INDEX_BIAS + index)),
        }
    }

    /// The box's max (the fourth lane, which `Vec3A` arithmetic ignores, is the index).
    #[inline(always)]
    pub fn max(&self) -> Vec3A {
        Vec3A::from_vec4(self.max_index)
    }

    #[inline(always)]
    pub fn index(&self) -> u32 {
        self.max_index.w.to_bits() - PrimInfo::INDEX_BIAS
    }

    /// Centroids are kept doubled (`min + max`), which bins exactly as the centroid does
    /// and saves a multiply.
    #[inline(always)]
    pub fn centroid2(&self) -> Vec3A {
        self.min + self.max()
    }
}

const _: () = assert!(size_of::<PrimInfo>() == 32);

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
        self.bounds.union(p.min, p.max());
        self.centroids.grow(p.centroid2());
    }

    pub fn merge(&mut self, o: &Extents) {
        self.bounds.union(o.bounds.min, o.bounds.max);
        self.centroids.union(o.centroids.min, o.centroids.max);
    }
}
