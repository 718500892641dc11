//! The render-time primitives: triangle meshes in world space (or object space, where
//! instanced), spheres, and the id of a primitive in the BVH.

use glam::{Vec2, Vec3, Vec4};

use super::interaction::uv_tangent;

use crate::light::LightId;
use crate::material::MaterialId;

/// A triangle mesh in world space.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    /// Empty, or one unit normal per position.
    pub normals: Vec<Vec3>,
    /// Empty, or one per position.
    pub uvs: Vec<Vec2>,
    /// Empty, or one linear RGB vertex colour per position (see [`crate::desc::MeshDesc`]).
    pub colors: Vec<Vec3>,
    /// Empty, or one tangent per position: xyz along +u, w = ±1 the handedness (see
    /// [`crate::desc::MeshDesc`]).
    pub tangents: Vec<Vec4>,
    pub indices: Vec<[u32; 3]>,
    pub material: MaterialId,
    /// Light of each triangle, if the mesh emits (same length as `indices`).
    pub lights: Vec<LightId>,
    /// Geometric normals point away from the winding's front side when set.
    pub flip_normals: bool,
    /// Empty, or [`Mesh::geometric_normal`] of each triangle, cached by
    /// [`Mesh::cache_face_normals`] once the mesh is final (world space, `flip_normals`
    /// set): a hit then loads its normal instead of a cross product, a square root and a
    /// division on the path's critical chain. Bit for bit what the hit would compute.
    pub face_normals: Vec<Vec3>,
    /// Empty, or each triangle's ∂p/∂u (xyz) and bitangent sign (w) from its uvs, as the
    /// hit record makes them, cached by [`Mesh::cache_uv_tangents`] for a world-space
    /// mesh with uvs and no tangents: a hit then loads them instead of dividing two
    /// vectors by the uv determinant and taking a cross product (about 120 of the ~390
    /// instructions of such a mesh's hit record). Bit for bit what the hit would compute.
    pub face_dpdu: Vec<Vec4>,
    /// Where the surface is cut out or see-through (glTF alpha modes); see [`crate::alpha`].
    pub alpha: Option<crate::alpha::AlphaMask>,
    /// The hit record the integrators' query ([`super::Scene::intersect_for_shading`])
    /// makes on this mesh, set by [`Mesh::cache_shading_record`] once the mesh and what
    /// its shading reads are known; [`ShadingRecord::Full`] (always right) until then.
    pub shading_record: ShadingRecord,
}

/// Which hit record a mesh's shading needs: each kind leaves out work whose fields no one
/// reads, so that the integrators' hits skip it (see [`Mesh::cache_shading_record`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShadingRecord {
    /// Every attribute interpolated ([`super::Scene::intersect`]'s record).
    #[default]
    Full,
    /// Positions only ([`Mesh::is_bare`]): the full record, without attribute branches.
    Bare,
    /// The shading normal from the vertex normals, and nothing else that the mesh has:
    /// no colours, and neither the material nor the emission reads the uvs, ∂p/∂u or the
    /// bitangent sign, which hold the bare record's placeholders (the barycentrics,
    /// p₁ − p₀, +1). Most scenes' constant Lambertian walls loaded with normals and uvs.
    Normals,
}

impl Mesh {
    #[inline]
    pub fn vertices(&self, tri: u32) -> [Vec3; 3] {
        let [a, b, c] = self.indices[tri as usize];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Texture coordinates at barycentrics (b1, b2) of a triangle (the barycentrics
    /// themselves where the mesh has no uvs, as [`super::Scene::intersect`] reports them).
    #[inline]
    pub fn uv_at(&self, tri: u32, bary: Vec2) -> Vec2 {
        if self.uvs.is_empty() {
            return bary;
        }
        let [a, b, c] = self.indices[tri as usize].map(|i| i as usize);
        self.uvs[a] * (1.0 - bary.x - bary.y) + self.uvs[b] * bary.x + self.uvs[c] * bary.y
    }

    /// Whether the mesh has positions only: no normals, uvs, tangents or colours.
    #[inline]
    pub fn is_bare(&self) -> bool {
        self.normals.is_empty()
            && self.uvs.is_empty()
            && self.tangents.is_empty()
            && self.colors.is_empty()
    }

    /// Unit geometric normal of a triangle: from the winding, turned towards the shading
    /// normals where the mesh has them, and flipped by `flip_normals`. Zero for a
    /// degenerate triangle.
    #[inline]
    pub fn geometric_normal(&self, tri: u32) -> Vec3 {
        if let Some(&n) = self.face_normals.get(tri as usize) {
            return n;
        }
        self.winding_normal_of(tri)
    }

    /// Fills [`Mesh::face_normals`]; to be called after the last change to the positions,
    /// normals, indices or `flip_normals` of a world-space mesh (as
    /// [`crate::build::build`] does).
    pub fn cache_face_normals(&mut self) {
        self.face_normals = (0..self.indices.len() as u32)
            .map(|tri| self.winding_normal_of(tri))
            .collect();
    }

    /// Fills [`Mesh::face_dpdu`] for a mesh with uvs and no tangents (else leaves it
    /// empty), after [`Mesh::cache_face_normals`] and the last change to the uvs or
    /// tangents. It costs 16 bytes a triangle, so [`crate::build::build`] caches it only
    /// below [`crate::accel::INDEXED_FROM`] primitives, where a scene is not yet big
    /// enough for its memory to be saved first.
    pub fn cache_uv_tangents(&mut self) {
        self.face_dpdu = if self.uvs.is_empty() || !self.tangents.is_empty() {
            Vec::new()
        } else {
            (0..self.indices.len())
                .map(|tri| {
                    let [a, b, c] = self.indices[tri].map(|i| i as usize);
                    let uv = [self.uvs[a], self.uvs[b], self.uvs[c]];
                    let p = self.vertices(tri as u32);
                    let (dpdu, sign) = uv_tangent(p, uv, self.geometric_normal(tri as u32));
                    dpdu.extend(sign)
                })
                .collect()
        };
    }

    /// Sets [`Mesh::shading_record`] for a world-space mesh whose shading reads the uvs
    /// where `reads_uv` (textures, normal maps, mix weights, textured emission) and ∂p/∂u
    /// with the bitangent sign where `reads_dpdu` (every frame but a Lambertian one), after
    /// the last change to its attributes.
    pub fn cache_shading_record(&mut self, reads_uv: bool, reads_dpdu: bool) {
        self.shading_record = if self.is_bare() {
            ShadingRecord::Bare
        } else if !self.normals.is_empty() && self.colors.is_empty() && !reads_uv && !reads_dpdu {
            ShadingRecord::Normals
        } else {
            ShadingRecord::Full
        };
    }

    /// [`Self::geometric_normal`] from the vertices, not the cache.
    fn winding_normal_of(&self, tri: u32) -> Vec3 {
        let [a, b, c] = self.indices[tri as usize].map(|i| i as usize);
        let normals =
            (!self.normals.is_empty()).then(|| self.normals[a] + self.normals[b] + self.normals[c]);
        winding_normal(self.vertices(tri), normals, self.flip_normals)
    }
}

/// The unit normal of the winding of `p`, turned towards `normals` (the sum of the
/// vertices' shading normals) where given, and flipped by `flip`.
#[inline]
pub(super) fn winding_normal(p: [Vec3; 3], normals: Option<Vec3>, flip: bool) -> Vec3 {
    let [p0, p1, p2] = p;
    let mut n = (p1 - p0).cross(p2 - p0).normalize_or_zero();
    if let Some(ns) = normals {
        if n.dot(ns) < 0.0 {
            n = -n;
        }
    }
    if flip {
        -n
    } else {
        n
    }
}

#[derive(Clone, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub material: MaterialId,
    pub light: Option<LightId>,
    /// Normals point inwards.
    pub flip_normals: bool,
    /// Whether shading a hit reads its uvs: its material's [`Material::reads_uv`] (a sphere
    /// light's emission is uniform). Where not, [`super::Scene::intersect_for_shading`]
    /// leaves them zero and skips their two inverse trigonometric functions. Set by the
    /// scene's build; `true` reads them always.
    ///
    /// [`Material::reads_uv`]: crate::material::Material::reads_uv
    pub reads_uv: bool,
}

/// A primitive in the BVH.
#[derive(Clone, Copy, Debug)]
pub enum Prim {
    Triangle { mesh: u32, tri: u32 },
    Sphere(u32),
}
