//! Shapes: spheres and meshes checked and placed in world space, the meshes that are
//! instanced rather than flattened, and the unit primitives (rectangle, disk, cube) as
//! meshes.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::desc::{GeometryDesc, MeshDesc, SceneDesc, ShapeDesc, Span};
use crate::instance::Transform;
use crate::material::MaterialId;
use crate::scene::{Mesh, Sphere};

use super::validate::{check_finite, err, BuildError};

/// The meshes to instance: those that two or more non-emitting shapes hold (the same
/// `Arc`). A mesh placed once gains nothing from a BLAS of its own and would cost every
/// ray a detour through the TLAS, so it is flattened into world space with the rest;
/// emitting shapes stay flattened because each of their triangles is an area light in
/// world space.
pub(super) fn shared_meshes(desc: &SceneDesc) -> std::collections::HashSet<*const MeshDesc> {
    let mut count: HashMap<*const MeshDesc, u32> = HashMap::new();
    for shape in &desc.shapes {
        if let GeometryDesc::Mesh(m) = &shape.geometry {
            if shape.emission.is_none_or(|le| le == Vec3::ZERO) {
                *count.entry(Arc::as_ptr(m)).or_default() += 1;
            }
        }
    }
    count
        .into_iter()
        .filter(|&(_, n)| n >= 2)
        .map(|(m, _)| m)
        .collect()
}

pub(super) fn build_sphere(
    shape: &ShapeDesc,
    center: Vec3,
    radius: f32,
    material: MaterialId,
) -> Result<Sphere, BuildError> {
    check_finite(
        &shape.span,
        "sphere",
        &[center.x, center.y, center.z, radius],
    )?;
    if radius <= 0.0 {
        return err(
            &shape.span,
            format!("sphere radius {radius} must be positive"),
        );
    }
    let m = Mat3::from_mat4(shape.transform);
    let scales = [m.x_axis.length(), m.y_axis.length(), m.z_axis.length()];
    let (lo, hi) = (
        scales.iter().copied().fold(f32::INFINITY, f32::min),
        scales.iter().copied().fold(0.0, f32::max),
    );
    if hi - lo > 1e-4 * hi {
        return err(
            &shape.span,
            "a sphere's transform must scale all axes equally",
        );
    }
    Ok(Sphere {
        center: shape.transform.transform_point3(center),
        radius: radius * hi,
        material,
        light: None,
        flip_normals: shape.flip_normals,
        reads_uv: true,
    })
}

pub(super) fn validate_mesh(m: &MeshDesc, span: &Span) -> Result<(), BuildError> {
    if m.indices.is_empty() || m.positions.is_empty() {
        return err(span, "mesh has no triangles");
    }
    // Each per-vertex attribute is absent or one a position, checked in this order.
    for (what, len) in [
        ("normals", m.normals.len()),
        ("uvs", m.uvs.len()),
        ("colours", m.colors.len()),
        ("tangents", m.tangents.len()),
    ] {
        if len != 0 && len != m.positions.len() {
            return err(
                span,
                format!("mesh has {len} {what} for {} positions", m.positions.len()),
            );
        }
    }
    if let Some(i) = m
        .indices
        .iter()
        .flatten()
        .find(|&&i| i as usize >= m.positions.len())
    {
        return err(
            span,
            format!(
                "mesh index {i} is out of range ({} positions)",
                m.positions.len()
            ),
        );
    }
    if m.positions
        .iter()
        .chain(&m.normals)
        .chain(&m.colors)
        .any(|p| !p.is_finite())
        || m.uvs.iter().any(|uv| !uv.is_finite())
        || m.tangents.iter().any(|t| !t.is_finite())
    {
        return err(span, "mesh has a non-finite vertex attribute");
    }
    Ok(())
}

pub(super) fn to_world(local: MeshDesc, m: Mat4, material: MaterialId) -> Mesh {
    let xf = Transform::new(m);
    Mesh {
        // Through `into_iter`: the vectors are reused, not copied.
        positions: local.positions.into_iter().map(|p| xf.point(p)).collect(),
        normals: local.normals.into_iter().map(|n| xf.normal(n)).collect(),
        uvs: local.uvs,
        colors: local.colors,
        tangents: local.tangents.into_iter().map(|t| xf.tangent(t)).collect(),
        indices: local.indices,
        material,
        lights: Vec::new(),
        flip_normals: false,
        alpha: None,
        face_normals: Vec::new(),
        face_dpdu: Vec::new(),
        shading_record: Default::default(),
    }
}

/// A shared mesh as its instances read it: the description's vertex data untouched
/// (normals and tangents not yet normalised), so that an instance's [`Transform`] makes
/// of it exactly what [`to_world`] makes of the same mesh.
pub(super) fn object_space(local: MeshDesc, material: MaterialId) -> Mesh {
    Mesh {
        positions: local.positions,
        normals: local.normals,
        uvs: local.uvs,
        colors: local.colors,
        tangents: local.tangents,
        indices: local.indices,
        material,
        lights: Vec::new(),
        flip_normals: false,
        alpha: None,
        face_normals: Vec::new(),
        face_dpdu: Vec::new(),
        shading_record: Default::default(),
    }
}

/// The square [-1,1]² at z = 0 facing +z, as two triangles.
pub fn rectangle() -> MeshDesc {
    MeshDesc {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        normals: vec![Vec3::Z; 4],
        uvs: vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        colors: Vec::new(),
        tangents: Vec::new(),
    }
}

/// The unit disk at z = 0 facing +z, as a fan of `segments` triangles. Its area falls
/// short of π by the factor sin(2π/n)·n/(2π) (4·10⁻⁴ at n = 128).
pub fn disk(segments: u32) -> MeshDesc {
    let mut positions = vec![Vec3::ZERO];
    let mut uvs = vec![Vec2::splat(0.5)];
    for i in 0..segments {
        let phi = std::f32::consts::TAU * i as f32 / segments as f32;
        let (s, c) = phi.sin_cos();
        positions.push(Vec3::new(c, s, 0.0));
        uvs.push(Vec2::new(0.5 + 0.5 * c, 0.5 + 0.5 * s));
    }
    let indices = (0..segments)
        .map(|i| [0, 1 + i, 1 + (i + 1) % segments])
        .collect();
    MeshDesc {
        normals: vec![Vec3::Z; positions.len()],
        positions,
        uvs,
        indices,
        colors: Vec::new(),
        tangents: Vec::new(),
    }
}

/// The cube [-1,1]³ with outward faces, four vertices per face so normals stay flat.
pub fn cube() -> MeshDesc {
    let mut mesh = MeshDesc::default();
    let rect = rectangle();
    // Each face is the rectangle rotated so that +z goes to the face's normal.
    let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for n in faces {
        let rot = glam::Quat::from_rotation_arc(Vec3::Z, n);
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(rect.positions.iter().map(|&p| rot * p + n));
        mesh.normals.extend([n; 4]);
        mesh.uvs.extend(&rect.uvs);
        mesh.indices
            .extend(rect.indices.iter().map(|t| t.map(|i| i + base)));
    }
    mesh
}
