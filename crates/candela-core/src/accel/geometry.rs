//! The primitives an [`super::Accel`] is built over, by reference to the meshes' own
//! arrays, so that the build copies nothing it does not keep: the inline layout reads
//! each leaf's vertices from them, the indexed one keeps their vertex indices.

use glam::Vec3;

use super::Shape;

/// One mesh's triangles: `indices` into `positions`. `filtered`: hits on it must pass
/// the traversal's filter (alpha masks).
#[derive(Clone, Copy, Debug)]
pub struct TriangleMesh<'a> {
    pub positions: &'a [Vec3],
    pub indices: &'a [[u32; 3]],
    pub filtered: bool,
}

/// A scene's primitives: the triangles of each mesh in turn, then the spheres (centre,
/// radius). Their ids, which hits report, count in that order.
#[derive(Clone, Debug, Default)]
pub struct Geometry<'a> {
    meshes: Vec<TriangleMesh<'a>>,
    spheres: Vec<(Vec3, f32)>,
    /// The id of each mesh's first triangle, and after the last mesh the first sphere's.
    first: Vec<u32>,
}

/// Where primitive `id` is: a mesh's triangle, or a sphere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Located {
    Triangle { mesh: u32, tri: u32 },
    Sphere(u32),
}

impl<'a> Geometry<'a> {
    /// # Panics
    /// With 2³⁰ primitives or more (the ids' flag bits), or 2³² vertices or more.
    pub fn new(meshes: Vec<TriangleMesh<'a>>, spheres: Vec<(Vec3, f32)>) -> Geometry<'a> {
        let mut first = Vec::with_capacity(meshes.len() + 1);
        let mut count = 0usize;
        for m in &meshes {
            first.push(count as u32);
            count += m.indices.len();
        }
        first.push(count as u32);
        count += spheres.len();
        assert!(
            count < super::block::ID_MASK as usize,
            "at most 2^30 primitives per scene"
        );
        let points = meshes.iter().map(|m| m.positions.len()).sum::<usize>() + 3 * spheres.len();
        assert!(
            points <= u32::MAX as usize,
            "at most 2^32 vertices per scene"
        );
        Geometry {
            meshes,
            spheres,
            first,
        }
    }

    /// Primitives in all.
    pub fn len(&self) -> usize {
        *self.first.last().unwrap_or(&0) as usize + self.spheres.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn meshes(&self) -> &[TriangleMesh<'a>] {
        &self.meshes
    }

    pub fn spheres(&self) -> &[(Vec3, f32)] {
        &self.spheres
    }

    /// Where primitive `id` is (`id` < [`Geometry::len`]).
    #[inline]
    pub fn locate(&self, id: u32) -> Located {
        let spheres_from = *self.first.last().unwrap_or(&0);
        if id >= spheres_from {
            return Located::Sphere(id - spheres_from);
        }
        // The last mesh whose first triangle is at or before `id` (meshes without
        // triangles share their successor's first id and are skipped).
        let mesh = self.first.partition_point(|&f| f <= id) - 1;
        Located::Triangle {
            mesh: mesh as u32,
            tri: id - self.first[mesh],
        }
    }

    /// Primitive `id`'s vertices or sphere.
    #[inline]
    pub fn shape(&self, id: u32) -> Shape {
        match self.locate(id) {
            Located::Triangle { mesh, tri } => {
                let m = &self.meshes[mesh as usize];
                Shape::Triangle(m.indices[tri as usize].map(|v| m.positions[v as usize]))
            }
            Located::Sphere(s) => {
                let (center, radius) = self.spheres[s as usize];
                Shape::Sphere { center, radius }
            }
        }
    }

    /// Whether hits on primitive `id` must pass the filter.
    #[inline]
    pub fn filtered(&self, id: u32) -> bool {
        match self.locate(id) {
            Located::Triangle { mesh, .. } => self.meshes[mesh as usize].filtered,
            Located::Sphere(_) => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_count_meshes_in_turn_then_spheres() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let two = [[0, 1, 2], [1, 2, 3]];
        let mesh = |indices, filtered| TriangleMesh {
            positions: &p,
            indices,
            filtered,
        };
        let g = Geometry::new(
            vec![mesh(&two, false), mesh(&[], true), mesh(&two[1..], true)],
            vec![(Vec3::ONE, 0.5)],
        );
        assert_eq!(g.len(), 4);
        let located: Vec<_> = (0..4).map(|i| g.locate(i)).collect();
        assert_eq!(
            located,
            [
                Located::Triangle { mesh: 0, tri: 0 },
                Located::Triangle { mesh: 0, tri: 1 },
                Located::Triangle { mesh: 2, tri: 0 },
                Located::Sphere(0),
            ]
        );
        assert!(!g.filtered(1) && g.filtered(2) && !g.filtered(3));
        assert!(matches!(g.shape(2), Shape::Triangle(v) if v == [p[1], p[2], p[3]]));
        assert!(Geometry::new(vec![], vec![]).is_empty());
    }
}
