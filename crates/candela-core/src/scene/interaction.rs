//! What a ray found: the hit record ([`SurfaceInteraction`]) and how it is made, for a
//! triangle (every vertex attribute interpolated, instances carried to world space, and a
//! fast path for bare meshes) and for a sphere.

use glam::{Vec2, Vec3, Vec3A};

use super::mesh::{winding_normal, Mesh, Prim, ShadingRecord};
use super::Scene;
use crate::geometry::Ray;
use crate::instance::Instance;
use crate::light::LightId;
use crate::material::MaterialId;
use crate::math::offset_ray_origin_a;

/// What a ray found.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceInteraction {
    pub p: Vec3,
    pub t: f32,
    /// Unit geometric normal (see [`Mesh::geometric_normal`]).
    pub ng: Vec3,
    /// Unit shading normal, on the same side as `ng`.
    pub ns: Vec3,
    pub uv: Vec2,
    /// ∂p/∂u, the direction of increasing u (zero where the uvs are degenerate): the
    /// tangent of normal maps and anisotropic roughness.
    pub dpdu: Vec3,
    /// ±1: the bitangent of a normal map is `bitangent_sign`·(ns × dpdu). −1 where the uvs
    /// are mirrored (∂p/∂v points against ng × ∂p/∂u) or a file's tangent says so.
    pub bitangent_sign: f32,
    /// The interpolated vertex colour multiplying the base colour; one where the mesh has
    /// none (and on spheres).
    pub color: Vec3,
    pub material: MaterialId,
    pub light: Option<LightId>,
}

impl SurfaceInteraction {
    /// A ray leaving this surface towards `d`, its origin moved off the surface.
    #[inline]
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        leaving_ray(self.p, self.ng, d)
    }
}

/// The ray leaving point `p` of a surface of normal `n` towards `d`, its origin moved off
/// the surface to the side `d` leaves by. In SIMD lanes, bit for bit the scalar set-up (see
/// [`super::Scene::unoccluded`]).
#[inline(always)]
pub(super) fn leaving_ray(p: Vec3, n: Vec3, d: Vec3) -> Ray {
    let (pa, na, da) = (Vec3A::from(p), Vec3A::from(n), Vec3A::from(d));
    let o = offset_ray_origin_a(pa, negated_unless_a(na, da.dot(na) >= 0.0));
    Ray::new(o.into(), d)
}

/// `n` where `keep`, else `−n`: as a product with ±1 (exact, so bit for bit the select)
/// rather than a select of vectors, which LLVM built from a broadcast comparison mask, a
/// dozen instructions where this takes a few; it turns a ray's offset normal towards the
/// side it leaves, three times a bounce.
#[inline(always)]
pub(super) fn negated_unless(n: Vec3, keep: bool) -> Vec3 {
    n * if keep { 1.0 } else { -1.0 }
}

/// [`negated_unless`] in SIMD lanes.
#[inline(always)]
pub(super) fn negated_unless_a(n: Vec3A, keep: bool) -> Vec3A {
    n * if keep { 1.0 } else { -1.0 }
}

/// The hit records come back as `Option`s, `Some` always, the type the ray query returns:
/// the out-of-line ones are then written straight where the caller keeps the query's
/// answer. Returned bare, each was written to a slot of the call and copied into the
/// `Option` after it (22 instructions a hit).
impl Scene {
    /// The hit record of `prim` at distance `t` along `ray`, barycentrics `bary` on a
    /// triangle: every attribute ([`ShadingRecord::Full`] or [`ShadingRecord::Bare`]), or
    /// where `shading`, what the mesh's shading reads ([`Mesh::shading_record`]).
    #[inline(always)]
    pub(super) fn interaction(
        &self,
        ray: &Ray,
        prim: Prim,
        t: f32,
        bary: Vec2,
        shading: bool,
    ) -> Option<SurfaceInteraction> {
        match prim {
            Prim::Triangle { mesh, tri } => {
                let m = &self.meshes[mesh as usize];
                let record = match shading {
                    true => m.shading_record,
                    false if m.is_bare() => ShadingRecord::Bare,
                    false => ShadingRecord::Full,
                };
                match record {
                    ShadingRecord::Bare => Some(bare_triangle_interaction(m, tri, t, bary)),
                    ShadingRecord::Normals => Some(normals_triangle_interaction(m, tri, t, bary)),
                    ShadingRecord::Full => world_triangle_interaction(m, tri, t, bary),
                }
            }
            Prim::Sphere(i) => self.sphere_interaction(ray, i, t, shading),
        }
    }

    /// The hit record of sphere `i` at distance `t` along the ray; where `shading` and
    /// nothing that shades the sphere reads its uvs ([`super::Sphere::reads_uv`]), they
    /// are zero.
    #[inline(never)]
    fn sphere_interaction(
        &self,
        ray: &Ray,
        i: u32,
        t: f32,
        shading: bool,
    ) -> Option<SurfaceInteraction> {
        let s = &self.spheres[i as usize];
        let n_out = (ray.at(t) - s.center).normalize();
        // Project back onto the surface to remove the error of o + t·d.
        let p = s.center + n_out * s.radius;
        let n = if s.flip_normals { -n_out } else { n_out };
        let uv = if shading && !s.reads_uv {
            Vec2::ZERO
        } else {
            let phi = n_out.z.atan2(n_out.x);
            Vec2::new(
                (phi / std::f32::consts::TAU).rem_euclid(1.0),
                n_out.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI,
            )
        };
        Some(SurfaceInteraction {
            p,
            t,
            ng: n,
            ns: n,
            uv,
            // u grows with φ = atan2(z, x): along (−z, 0, x) of the normal.
            dpdu: Vec3::new(-n_out.z, 0.0, n_out.x),
            bitangent_sign: 1.0,
            color: Vec3::ONE,
            material: s.material,
            light: s.light,
        })
    }
}

/// The hit record of triangle `tri` of instance `inst`'s mesh `m` at barycentrics `bary`:
/// its object-space vertex data carried to world space first by the same
/// [`crate::instance::Transform`] that flattens meshes.
#[inline(always)]
pub(super) fn instance_triangle_interaction(
    m: &Mesh,
    inst: &Instance,
    tri: u32,
    t: f32,
    bary: Vec2,
) -> Option<SurfaceInteraction> {
    Some(full_triangle_interaction(m, Some(inst), tri, t, bary))
}

/// [`full_triangle_interaction`] of a world-space mesh: a copy of its own, out of line,
/// in which every test of the instance (its material, flip and transform) folds away.
#[inline(never)]
fn world_triangle_interaction(
    m: &Mesh,
    tri: u32,
    t: f32,
    bary: Vec2,
) -> Option<SurfaceInteraction> {
    Some(full_triangle_interaction(m, None, tri, t, bary))
}

/// The hit record of triangle `tri` of `m` at barycentrics `bary`, every vertex attribute
/// the mesh has interpolated: a world-space mesh's where `inst` is `None`, else an
/// instance's (see [`instance_triangle_interaction`]).
#[inline(always)]
fn full_triangle_interaction(
    m: &Mesh,
    inst: Option<&Instance>,
    tri: u32,
    t: f32,
    bary: Vec2,
) -> SurfaceInteraction {
    let xf = inst.map(|i| &i.transform);
    let flip_normals = inst.map_or(m.flip_normals, |i| i.flip_normals);
    let material = inst.map_or(m.material, |i| i.material);
    let [a, b, c] = m.indices[tri as usize].map(|i| i as usize);
    let [p0, p1, p2] = match xf {
        None => m.vertices(tri),
        Some(x) => m.vertices(tri).map(|p| x.point(p)),
    };
    // An `if`, not `bool::then` with a closure, which LLVM left out of line.
    let normals = if m.normals.is_empty() {
        None
    } else {
        let n = [m.normals[a], m.normals[b], m.normals[c]];
        Some([
            carried_normal(xf, n[0]),
            carried_normal(xf, n[1]),
            carried_normal(xf, n[2]),
        ])
    };
    let b0 = 1.0 - bary.x - bary.y;
    // Barycentric interpolation is more accurate than o + t·d.
    let p = p0 * b0 + p1 * bary.x + p2 * bary.y;
    let ng = match (inst, m.face_normals.get(tri as usize)) {
        (None, Some(&n)) => n,
        _ => winding_normal(
            [p0, p1, p2],
            normals.map(|[na, nb, nc]| na + nb + nc),
            flip_normals,
        ),
    };
    let mut ns = ng;
    if let Some([na, nb, nc]) = normals {
        if let Some(n) = unit(na * b0 + nb * bary.x + nc * bary.y) {
            // A product with ±1, exact (n is finite here), where the select of −n or n
            // was a broadcast mask.
            ns = negated_unless(n, !flip_normals);
        }
    }
    // `Mesh::uv_at`'s sum, from the indices already loaded.
    let uv = if m.uvs.is_empty() {
        bary
    } else {
        m.uvs[a] * b0 + m.uvs[b] * bary.x + m.uvs[c] * bary.y
    };
    let light = m.lights.get(tri as usize).copied();
    let (dpdu, bitangent_sign) = if !m.tangents.is_empty() {
        let tangent = |i: usize| xf.map_or(m.tangents[i], |x| x.tangent(m.tangents[i]));
        let t = tangent(a) * b0 + tangent(b) * bary.x + tangent(c) * bary.y;
        (t.truncate(), if t.w < 0.0 { -1.0 } else { 1.0 })
    } else if m.uvs.is_empty() {
        (p1 - p0, 1.0)
    } else if let (None, Some(&f)) = (inst, m.face_dpdu.get(tri as usize)) {
        (f.truncate(), f.w)
    } else {
        uv_tangent([p0, p1, p2], [m.uvs[a], m.uvs[b], m.uvs[c]], ng)
    };
    let color = if m.colors.is_empty() {
        Vec3::ONE
    } else {
        m.colors[a] * b0 + m.colors[b] * bary.x + m.colors[c] * bary.y
    };
    SurfaceInteraction {
        p,
        t,
        ng,
        ns,
        uv,
        dpdu,
        bitangent_sign,
        color,
        material,
        light,
    }
}

/// A vertex normal carried to world space by the instance transform `xf`, if any.
#[inline(always)]
fn carried_normal(xf: Option<&crate::instance::Transform>, n: Vec3) -> Vec3 {
    match xf {
        None => n,
        Some(x) => x.normal(n),
    }
}

/// [`full_triangle_interaction`] of a world-space mesh with positions only (no normals, uvs,
/// tangents or colours, the Cornell box's walls): the same record, without the branches
/// and interpolations of the attributes it lacks. The uvs are the barycentrics, ∂p/∂u is
/// p₁ − p₀, as in the general case.
#[inline(always)]
fn bare_triangle_interaction(m: &Mesh, tri: u32, t: f32, bary: Vec2) -> SurfaceInteraction {
    let [p0, p1, p2] = m.vertices(tri);
    let b0 = 1.0 - bary.x - bary.y;
    let ng = m.geometric_normal(tri);
    SurfaceInteraction {
        p: p0 * b0 + p1 * bary.x + p2 * bary.y,
        t,
        ng,
        ns: ng,
        uv: bary,
        dpdu: p1 - p0,
        bitangent_sign: 1.0,
        color: Vec3::ONE,
        material: m.material,
        light: m.lights.get(tri as usize).copied(),
    }
}

/// The hit record of a world-space mesh of [`ShadingRecord::Normals`]:
/// the position, the cached geometric normal and the shading normal from the vertex
/// normals, as [`full_triangle_interaction`] makes them; the uvs, ∂p/∂u and bitangent sign,
/// which this mesh's shading does not read, as the bare record's.
#[inline(always)]
fn normals_triangle_interaction(m: &Mesh, tri: u32, t: f32, bary: Vec2) -> SurfaceInteraction {
    let [a, b, c] = m.indices[tri as usize].map(|i| i as usize);
    let [p0, p1, p2] = [m.positions[a], m.positions[b], m.positions[c]];
    let [na, nb, nc] = [m.normals[a], m.normals[b], m.normals[c]];
    let b0 = 1.0 - bary.x - bary.y;
    let ng = m.geometric_normal(tri);
    let ns = match unit(na * b0 + nb * bary.x + nc * bary.y) {
        Some(n) => negated_unless(n, !m.flip_normals),
        None => ng,
    };
    SurfaceInteraction {
        p: p0 * b0 + p1 * bary.x + p2 * bary.y,
        t,
        ng,
        ns,
        uv: bary,
        dpdu: p1 - p0,
        bitangent_sign: 1.0,
        color: Vec3::ONE,
        material: m.material,
        light: m.lights.get(tri as usize).copied(),
    }
}

/// `v` scaled to unit length, `None` where that is not a finite, non-zero vector: glam's
/// `normalize_or_zero` bit for bit (`None` for its zero), with the reciprocal's range
/// checked by two compares where `is_finite` was a dozen integer instructions on its bits.
#[inline(always)]
fn unit(v: Vec3) -> Option<Vec3> {
    let rcp = 1.0 / v.length();
    // An `if`, not `bool::then` with a closure (see `full_triangle_interaction`).
    if rcp > 0.0 && rcp < f32::INFINITY {
        Some(v * rcp)
    } else {
        None
    }
}

/// ∂p/∂u of a triangle from its positions `p` and uvs, and the bitangent sign against its
/// geometric normal `ng`: −1 where the uvs are mirrored (+v lies against ng × ∂p/∂u).
#[inline]
pub(super) fn uv_tangent(p: [Vec3; 3], uv: [Vec2; 3], ng: Vec3) -> (Vec3, f32) {
    let (dpdu, dpdv) = triangle_dpdu_dpdv(p, uv);
    let sign = if ng.cross(dpdu).dot(dpdv) < 0.0 {
        -1.0
    } else {
        1.0
    };
    (dpdu, sign)
}

/// ∂p/∂u and ∂p/∂v of a triangle from its positions and uvs (pbrt-v4 §6.5.3); zero when
/// the uvs are degenerate.
fn triangle_dpdu_dpdv(p: [Vec3; 3], uv: [Vec2; 3]) -> (Vec3, Vec3) {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if det.abs() < 1e-12 {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    let dpdu = (duv12.y * dp02 - duv02.y * dp12) / det;
    let dpdv = (duv02.x * dp12 - duv12.x * dp02) / det;
    if dpdu.is_finite() && dpdv.is_finite() {
        (dpdu, dpdv)
    } else {
        (Vec3::ZERO, Vec3::ZERO)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A world-space mesh of material 3 with no attributes but `normals`.
    fn mesh(positions: Vec<Vec3>, normals: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Mesh {
        Mesh {
            positions,
            normals,
            uvs: vec![],
            colors: vec![],
            tangents: vec![],
            indices,
            material: MaterialId(3),
            lights: vec![],
            flip_normals: false,
            alpha: None,
            face_normals: vec![],
            face_dpdu: vec![],
            shading_record: Default::default(),
        }
    }

    #[test]
    fn a_bare_mesh_s_fast_hit_record_is_the_full_one() {
        let positions = vec![
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::new(1.7, -0.4, 0.2),
            Vec3::new(0.3, 1.1, -0.9),
            Vec3::new(-0.5, 0.6, 2.0),
        ];
        let mut m = mesh(positions, vec![], vec![[0, 1, 2], [2, 1, 3]]);
        m.lights = vec![LightId(4), LightId(7)];
        for flip in [false, true] {
            m.flip_normals = flip;
            m.face_normals.clear();
            let records = |m: &Mesh| {
                let mut r = Vec::new();
                for tri in 0..2 {
                    for bary in [Vec2::new(0.2, 0.3), Vec2::new(0.7, 0.1), Vec2::ZERO] {
                        let fast = bare_triangle_interaction(m, tri, 1.5, bary);
                        let full = full_triangle_interaction(m, None, tri, 1.5, bary);
                        assert_eq!(format!("{fast:?}"), format!("{full:?}"));
                        r.push(format!("{fast:?}"));
                    }
                }
                r
            };
            let computed = records(&m);
            // The cached normals give the same records, bit for bit.
            m.cache_face_normals();
            assert_eq!(m.face_normals.len(), 2);
            assert_eq!(records(&m), computed);
        }
        m.lights.clear();
        let si = bare_triangle_interaction(&m, 1, 1.0, Vec2::splat(0.25));
        assert!(si.light.is_none());
    }

    /// The [`ShadingRecord::Normals`] record is the full one but for the fields its
    /// mesh's shading does not read (uvs, ∂p/∂u, bitangent sign: the bare placeholders),
    /// bit for bit, with and without `flip_normals`, cached normals and a light; and
    /// `cache_shading_record` picks it only where nothing reads those fields.
    #[test]
    fn the_normals_record_is_the_full_one_where_shading_reads() {
        let mut m = mesh(
            vec![
                Vec3::new(0.1, 0.2, 0.3),
                Vec3::new(1.7, -0.4, 0.2),
                Vec3::new(0.3, 1.1, -0.9),
                Vec3::new(-0.5, 0.6, 2.0),
            ],
            vec![
                Vec3::new(0.2, 0.9, 0.1).normalize(),
                Vec3::new(-0.3, 0.8, 0.2).normalize(),
                Vec3::new(0.1, 0.7, -0.6).normalize(),
                // Opposite to vertex 1's: triangle 1's normals sum to zero at (0, ½, ½).
                -Vec3::new(-0.3, 0.8, 0.2).normalize(),
            ],
            vec![[0, 1, 2], [2, 1, 3], [1, 2, 1]],
        );
        m.uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
        m.lights = vec![LightId(1), LightId(2), LightId(3)];
        let shaded = |si: &SurfaceInteraction| {
            let SurfaceInteraction {
                p,
                t,
                ng,
                ns,
                color,
                material,
                light,
                ..
            } = *si;
            format!("{:?}", (p, t, ng, ns, color, material, light))
        };
        for (flip, cached) in [(false, false), (true, false), (false, true), (true, true)] {
            m.flip_normals = flip;
            m.face_normals.clear();
            if cached {
                m.cache_face_normals();
            }
            for tri in 0..3 {
                for bary in [Vec2::new(0.2, 0.3), Vec2::new(0.5, 0.5), Vec2::ZERO] {
                    let full = full_triangle_interaction(&m, None, tri, 1.5, bary);
                    let lean = normals_triangle_interaction(&m, tri, 1.5, bary);
                    assert_eq!(shaded(&lean), shaded(&full), "tri {tri} at {bary}");
                    let [p0, p1, _] = m.vertices(tri);
                    assert_eq!(
                        (lean.uv, lean.dpdu, lean.bitangent_sign),
                        (bary, p1 - p0, 1.0)
                    );
                }
            }
        }
        // Only a mesh with normals, no colours, whose shading reads no uvs or ∂p/∂u.
        m.cache_shading_record(false, false);
        assert_eq!(m.shading_record, ShadingRecord::Normals);
        for (reads_uv, reads_dpdu) in [(true, false), (false, true), (true, true)] {
            m.cache_shading_record(reads_uv, reads_dpdu);
            assert_eq!(m.shading_record, ShadingRecord::Full);
        }
        m.colors = vec![Vec3::ONE; 4];
        m.cache_shading_record(false, false);
        assert_eq!(m.shading_record, ShadingRecord::Full);
        let mut bare = mesh(m.positions.clone(), vec![], m.indices.clone());
        bare.cache_shading_record(true, true);
        assert_eq!(bare.shading_record, ShadingRecord::Bare);
    }

    /// A sphere's record for shading is the full one, bit for bit, but for the uvs where
    /// its material reads none (zero there, the inverse trigonometry skipped): a constant
    /// Lambertian sphere's and a rough conductor's are left out, a checkerboard's kept;
    /// the build sets [`super::super::Sphere::reads_uv`] from the material.
    #[test]
    fn a_sphere_s_shading_record_skips_only_the_uvs_nothing_reads() {
        use crate::desc::{
            BsdfDesc, GeometryDesc, MaterialDesc, MicrofacetDesc, SceneDesc, ShapeDesc, TextureDesc,
        };
        let checker = TextureDesc::Checker {
            a: Vec3::splat(0.2),
            b: Vec3::splat(0.8),
            uv_transform: glam::Affine2::IDENTITY,
        };
        let metal = BsdfDesc::Conductor {
            eta: Vec3::splat(0.2),
            k: Vec3::splat(3.0),
            specular: Vec3::ONE,
            alpha_u: 0.3,
            alpha_v: 0.1,
            distribution: MicrofacetDesc::default(),
        };
        let materials = vec![
            MaterialDesc::diffuse("plain", Vec3::splat(0.5)),
            MaterialDesc::new("checker", BsdfDesc::Diffuse { albedo: checker }),
            MaterialDesc::new("metal", metal),
        ];
        let shapes = ["plain", "checker", "metal"]
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let center = Vec3::new(3.0 * i as f32, 0.0, 0.0);
                ShapeDesc::new(
                    GeometryDesc::Sphere {
                        center,
                        radius: 1.0,
                    },
                    *name,
                )
            })
            .collect();
        let desc = SceneDesc {
            materials,
            shapes,
            ..Default::default()
        };
        let scene = crate::build::build(&desc).expect("scene builds");
        let reads: Vec<_> = scene.spheres.iter().map(|s| s.reads_uv).collect();
        assert_eq!(reads, [false, true, false]);
        let mut compared = 0;
        for (i, &reads_uv) in reads.iter().enumerate() {
            for (dx, dy) in [(0.1, 0.2), (-0.5, 0.3), (0.6, -0.4), (0.0, 0.0)] {
                let o = Vec3::new(3.0 * i as f32 + dx, dy, 5.0);
                let ray = Ray::new(o, Vec3::new(0.01, -0.02, -1.0).normalize());
                let full = scene.intersect(&ray, f32::INFINITY).expect("hits");
                let lean = scene
                    .intersect_for_shading(&ray, f32::INFINITY)
                    .expect("hits");
                let uv = if reads_uv { full.uv } else { Vec2::ZERO };
                assert_ne!(full.uv, Vec2::ZERO);
                let expected = SurfaceInteraction { uv, ..full };
                assert_eq!(format!("{lean:?}"), format!("{expected:?}"), "sphere {i}");
                compared += 1;
            }
        }
        assert_eq!(compared, 12);
    }

    #[test]
    fn cached_face_normals_are_the_computed_ones() {
        // Shading normals that disagree with the winding of the second triangle turn its
        // geometric normal; the cache must keep that and `flip_normals`.
        let mut m = mesh(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.2)],
            vec![Vec3::Z; 4],
            vec![[0, 1, 2], [1, 2, 3], [0, 0, 1]],
        );
        for flip in [false, true] {
            m.flip_normals = flip;
            m.face_normals.clear();
            let bary = Vec2::new(0.3, 0.3);
            let computed: Vec<_> = (0..3)
                .map(|t| format!("{:?}", full_triangle_interaction(&m, None, t, 1.0, bary)))
                .collect();
            let normals: Vec<_> = (0..3).map(|t| m.geometric_normal(t)).collect();
            m.cache_face_normals();
            assert_eq!(m.face_normals, normals);
            assert_eq!(normals[2], Vec3::ZERO, "degenerate");
            assert!(
                normals[0].z * normals[1].z > 0.0,
                "turned towards the normals"
            );
            let cached: Vec<_> = (0..3)
                .map(|t| format!("{:?}", full_triangle_interaction(&m, None, t, 1.0, bary)))
                .collect();
            assert_eq!(cached, computed);
        }
    }

    /// A mesh with uvs: the cached ∂p/∂u and bitangent signs give the records the uvs
    /// give, bit for bit, on a plain, a mirrored and a degenerate uv triangle, with and
    /// without `flip_normals`; a mesh with tangents caches none (its tangents rule).
    #[test]
    fn cached_uv_tangents_give_the_computed_records() {
        let mut m = mesh(
            vec![
                Vec3::new(0.1, 0.2, 0.3),
                Vec3::new(1.7, -0.4, 0.2),
                Vec3::new(0.3, 1.1, -0.9),
                Vec3::new(-0.5, 0.6, 2.0),
            ],
            vec![Vec3::new(0.2, 0.9, 0.1).normalize(); 4],
            vec![[0, 1, 2], [2, 1, 3], [0, 3, 1]],
        );
        // Triangle 1 mirrors triangle 0's uv winding; triangle 2's uvs are collinear.
        m.uvs = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(2.0, 0.0),
        ];
        let mut signs = Vec::new();
        for flip in [false, true] {
            m.flip_normals = flip;
            m.face_normals.clear();
            m.face_dpdu.clear();
            let records = |m: &Mesh| {
                let mut r = Vec::new();
                for tri in 0..3 {
                    for bary in [Vec2::new(0.2, 0.3), Vec2::ZERO] {
                        r.push(format!(
                            "{:?}",
                            full_triangle_interaction(m, None, tri, 1.5, bary)
                        ));
                    }
                }
                r
            };
            let computed = records(&m);
            m.cache_face_normals();
            m.cache_uv_tangents();
            assert_eq!(m.face_dpdu.len(), 3);
            assert_eq!(records(&m), computed);
            signs.extend(m.face_dpdu.iter().map(|f| f.w));
        }
        assert!(signs.contains(&1.0) && signs.contains(&-1.0), "{signs:?}");
        m.tangents = vec![glam::Vec4::new(1.0, 0.0, 0.0, 1.0); 4];
        m.cache_uv_tangents();
        assert!(m.face_dpdu.is_empty());
    }
}
