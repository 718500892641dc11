//! Indexed leaves ([`super::LeafLayout::Indexed`]): each primitive as three indices into
//! one shared vertex array and its id with flags, in leaf order, so that a leaf is a
//! range of these records. A ray that reaches a leaf gathers its vertices into a
//! [`Block`] and runs the same test as the inline layout on the same values, so the hits
//! are the same bits.
//!
//! 16 bytes a primitive and the vertices once (12 bytes each; a closed mesh has about
//! half as many vertices as triangles), against a 320-byte block a leaf inline (about 86
//! bytes a triangle on a height field, whose leaves hold 3.7 on average).

use glam::Vec3;

use super::block::{Block, SPHERE};
use super::geometry::{Geometry, Located};
use super::Shape;

/// The three vertex indices of a primitive and its id with flags. A sphere's "vertices"
/// are its centre, (radius, 0, 0) and zero, as in a block's lanes.
pub type Record = [u32; 4];

#[derive(Clone, Debug, Default)]
pub struct IndexedLeaves {
    /// In leaf order: a wide node's leaf lane names its first record and count.
    records: Vec<Record>,
    points: Vec<Vec3>,
}

impl IndexedLeaves {
    /// The records of `order` (ids in leaf order, with `flags(id)`), over the meshes'
    /// vertices copied into one array and each sphere's three points after them.
    pub fn from_geometry(
        geometry: &Geometry,
        order: &[u32],
        flags: impl Fn(u32) -> u32,
    ) -> IndexedLeaves {
        let vertices = geometry
            .meshes()
            .iter()
            .map(|m| m.positions.len())
            .sum::<usize>();
        let mut points = Vec::with_capacity(vertices + 3 * geometry.spheres().len());
        let mut base = Vec::with_capacity(geometry.meshes().len());
        for m in geometry.meshes() {
            base.push(points.len() as u32);
            points.extend_from_slice(m.positions);
        }
        let spheres = points.len() as u32;
        for &(center, radius) in geometry.spheres() {
            points.extend([center, Vec3::new(radius, 0.0, 0.0), Vec3::ZERO]);
        }
        let records = order
            .iter()
            .map(|&id| {
                let [a, b, c] = match geometry.locate(id) {
                    Located::Triangle { mesh, tri } => {
                        let m = &geometry.meshes()[mesh as usize];
                        m.indices[tri as usize].map(|v| base[mesh as usize] + v)
                    }
                    Located::Sphere(s) => {
                        let at = spheres + 3 * s;
                        [at, at + 1, at + 2]
                    }
                };
                [a, b, c, id | flags(id)]
            })
            .collect();
        IndexedLeaves { records, points }
    }

    /// The records of `order` over primitives given one by one: each gets three points
    /// of its own (nothing is shared; for tests and shape lists).
    pub fn from_shapes(
        order: &[u32],
        shape: impl Fn(u32) -> Shape,
        flags: impl Fn(u32) -> u32,
    ) -> IndexedLeaves {
        let mut points = Vec::with_capacity(3 * order.len());
        let records = order
            .iter()
            .map(|&id| {
                let at = points.len() as u32;
                points.extend(match shape(id) {
                    Shape::Triangle(v) => v,
                    Shape::Sphere { center, radius } => {
                        [center, Vec3::new(radius, 0.0, 0.0), Vec3::ZERO]
                    }
                });
                [at, at + 1, at + 2, id | flags(id)]
            })
            .collect();
        IndexedLeaves { records, points }
    }

    /// The block of the `count` records from `first` on.
    #[inline(always)]
    pub fn block(&self, first: u32, count: u32) -> Block {
        let records = &self.records[first as usize..(first + count) as usize];
        Block::gather(
            records
                .iter()
                .map(|&[a, b, c, id]| ([a, b, c].map(|v| self.points[v as usize]), id)),
        )
    }

    /// The address of record `first`, to prefetch.
    #[inline(always)]
    pub fn record_at(&self, first: u32) -> *const u8 {
        self.records.as_ptr().wrapping_add(first as usize) as *const u8
    }

    /// Whether every primitive is an unfiltered triangle.
    pub fn is_plain(&self) -> bool {
        self.records
            .iter()
            .all(|r| r[3] & (SPHERE | super::block::FILTERED) == 0)
    }

    /// Bytes of the records and the vertices.
    pub fn memory(&self) -> usize {
        size_of_val(&self.records[..]) + size_of_val(&self.points[..])
    }
}
