//! `<shape>`: Mitsuba's primitives map to Candela's unit primitives, which follow the
//! same conventions (rectangle [-1,1]² and disk of radius 1 in z = 0 facing +z, cube
//! [-1,1]³); `obj` and `ply` go through [`crate::load_mesh`]. A textured `sphere` or
//! `disk` becomes a mesh carrying Mitsuba's uvs (see [`uv_sphere`], [`polar_disk`]).

use std::sync::Arc;

use candela_core::desc::{BsdfDesc, GeometryDesc, MeshDesc, ShapeDesc, TextureDesc};
use candela_core::math::Frame;
use glam::{Mat4, Vec2, Vec3};

use super::parse::Node;
use super::{bsdfs, describe, transform, Ctx};
use crate::LoadError;

/// A top-level `<shape>`: one shape, an `instance` of a `shapegroup`, or (a
/// `shapegroup` itself) nothing until an instance places it.
pub(crate) fn shape(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    match node.kind() {
        "shapegroup" => Ok(()),
        "instance" => instance(ctx, node),
        _ => {
            let index = ctx.desc.shapes.len();
            super::media::shape_media(ctx, node, index)?;
            match shape_desc(ctx, node)? {
                Some(s) => ctx.desc.shapes.push(s),
                // Skipped under --lenient: its media bound nothing.
                None => ctx.desc.media.shapes.retain(|m| m.shape != index),
            }
            Ok(())
        }
    }
}

/// A `<shape type="shapegroup" id="…">`: its shapes, kept under the id for instances.
/// Mitsuba 3 allows no emitters and no nested groups inside a group.
pub(crate) fn shape_group(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    let id = node.req("id")?;
    let mut shapes = Vec::new();
    for c in node.plugins("shape") {
        if matches!(c.kind(), "shapegroup" | "instance") {
            return Err(c.error(format!("a shapegroup cannot hold a {}", describe(c))));
        }
        if let Some(e) = c.children.iter().find(|e| e.tag == "emitter") {
            return Err(e.error(
                "a shape in a shapegroup cannot emit (Mitsuba 3 allows no emitters in groups)",
            ));
        }
        if let Some(s) = shape_desc(ctx, c)? {
            shapes.push(s);
        }
    }
    ctx.check_unused(node)?;
    if ctx.shape_groups.insert(id.to_string(), shapes).is_some() {
        return Err(node.error(format!("id \"{id}\" is used twice")));
    }
    Ok(())
}

/// A `<shape type="instance">`: the group of its `<ref id>`, each shape's transform
/// preceded by the instance's `to_world`. Meshes keep their `Arc`s, so the build stores
/// them once (see `candela_core::instance`).
fn instance(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    let mut refs = node.children.iter().filter(|c| c.tag == "ref");
    let Some(r) = refs.next() else {
        return Err(node.error("an instance needs a <ref id> to a shapegroup"));
    };
    if let Some(extra) = refs.next() {
        return Err(extra.error("an instance refers to exactly one shapegroup"));
    }
    r.used.set(true);
    let id = r.req("id")?;
    let Some(group) = ctx.shape_groups.get(id) else {
        return Err(r.error(format!(
            "no <shape type=\"shapegroup\"> has the id \"{id}\""
        )));
    };
    let to_world = to_world(node)?;
    let placed: Vec<ShapeDesc> = group
        .iter()
        .map(|s| ShapeDesc {
            transform: to_world * s.transform,
            span: node.span.clone(),
            ..s.clone()
        })
        .collect();
    ctx.check_unused(node)?;
    ctx.desc.shapes.extend(placed);
    Ok(())
}

fn to_world(node: &Node) -> Result<Mat4, LoadError> {
    match node.prop("to_world") {
        Some(t) if t.tag == "transform" => transform::transform(t),
        Some(t) => Err(t.error("to_world must be a <transform>")),
        None => Ok(Mat4::IDENTITY),
    }
}

/// The description of one shape; `None` where `--lenient` skips it.
fn shape_desc(ctx: &mut Ctx, node: &Node) -> Result<Option<ShapeDesc>, LoadError> {
    let geometry = match node.kind() {
        "rectangle" => GeometryDesc::Rectangle,
        "disk" => GeometryDesc::Disk,
        "cube" => GeometryDesc::Cube,
        "sphere" => GeometryDesc::Sphere {
            center: node.point("center")?.unwrap_or(Vec3::ZERO),
            radius: node.float("radius")?.unwrap_or(1.0),
        },
        "cylinder" => GeometryDesc::Mesh(Arc::new(cylinder(node)?)),
        "obj" | "ply" | "serialized" => {
            let file = node
                .string("filename")?
                .ok_or_else(|| node.error(format!("{} needs a filename", describe(node))))?;
            let path = ctx.base.join(file);
            let face_normals = node.boolean("face_normals")?.unwrap_or(false);
            // Mitsuba flips OBJ texture coordinates by default (a serialized mesh has no
            // such option and keeps its uvs).
            let flip_uv = match node.kind() {
                "serialized" => false,
                kind => node.boolean("flip_tex_coords")?.unwrap_or(kind == "obj"),
            };
            let index = match node.kind() {
                "serialized" => match node.integer("shape_index")?.unwrap_or(0) {
                    i @ 0..=0xffff_ffff => i as u32,
                    i => {
                        let p = node.prop("shape_index").expect("read just now");
                        return Err(p.error(format!("shape_index {i} must be 0 or more")));
                    }
                },
                _ => 0,
            };
            // Shapes loading the same file the same way share one mesh, which the build
            // then instances.
            let key = (path, index, face_normals, flip_uv);
            let mesh = match ctx.mesh_files.get(&key) {
                Some(m) => m.clone(),
                None => {
                    let loaded = match node.kind() {
                        "serialized" => crate::mitsuba::serialized::load_serialized(&key.0, index),
                        _ => crate::load_mesh(&key.0),
                    };
                    let mut mesh =
                        loaded.map_err(|e| node.error(format!("cannot load mesh: {e}")))?;
                    // Mitsuba keeps a PLY's colours as an attribute that only a
                    // `mesh_attribute` texture reads; they do not tint the BSDF.
                    mesh.colors.clear();
                    if face_normals {
                        mesh.normals.clear();
                    } else if mesh.normals.is_empty() {
                        // Mitsuba smooths a mesh that comes without normals.
                        mesh.normals = vertex_normals(&mesh);
                    }
                    if flip_uv {
                        mesh.uvs.iter_mut().for_each(|uv| uv.y = 1.0 - uv.y);
                    }
                    let mesh = Arc::new(mesh);
                    ctx.mesh_files.insert(key, mesh.clone());
                    mesh
                }
            };
            GeometryDesc::Mesh(mesh)
        }
        _ => {
            ctx.unsupported(node, format!("<{}> is not supported", describe(node)))?;
            return Ok(None);
        }
    };
    let transform = to_world(node)?;
    let flip_normals = node.boolean("flip_normals")?.unwrap_or(false);
    let material = material(ctx, node)?;

    let mut emission = None;
    let mut emission_texture = None;
    for e in node.plugins("emitter") {
        if e.kind() != "area" {
            ctx.unsupported(
                e,
                format!("<{}> inside a shape (only \"area\" is)", describe(e)),
            )?;
            continue;
        }
        if emission.is_some() {
            return Err(e.error("a shape has at most one area emitter"));
        }
        // A texture (a bitmap or a checkerboard, nested or by `<ref>`) makes a textured
        // area light: Candela's emission texture, read at the shape's uvs.
        if e.is_texture("radiance") {
            emission = Some(Vec3::ONE);
            emission_texture = Some(ctx.texture(e, "radiance", Vec3::ONE)?);
        } else {
            emission = Some(e.illuminant("radiance")?.unwrap_or(Vec3::ONE));
        }
        ctx.check_unused(e)?;
    }
    let textured = reads_uv(ctx, &material) || emission_texture.is_some();
    let geometry = match geometry {
        GeometryDesc::Sphere { center, radius } if textured => {
            GeometryDesc::Mesh(Arc::new(uv_sphere(center, radius)))
        }
        GeometryDesc::Disk if textured => GeometryDesc::Mesh(Arc::new(polar_disk())),
        g => g,
    };
    let geometry = match geometry {
        GeometryDesc::Mesh(m) if normal_mapped(ctx, &material) && m.tangents.is_empty() => {
            GeometryDesc::Mesh(Arc::new(with_tangents(&m)))
        }
        g => g,
    };
    ctx.check_unused(node)?;
    Ok(Some(ShapeDesc {
        geometry,
        material,
        emission,
        emission_texture,
        transform,
        flip_normals,
        span: node.span.clone(),
    }))
}

/// The shape's material: an inline `<bsdf>`, a `<ref id>` to one, or Mitsuba's default
/// (grey diffuse; black for an emitter, which then only emits).
fn material(ctx: &mut Ctx, node: &Node) -> Result<String, LoadError> {
    let mut found: Option<String> = None;
    for c in &node.children {
        let name = match c.tag.as_str() {
            "bsdf" => bsdfs::material(ctx, c)?,
            // A medium's reference is the shape's medium, not its BSDF.
            "ref" if !matches!(c.name(), "interior" | "exterior") => {
                let id = c.req("id")?;
                match ctx.bsdf_ids.get(id) {
                    Some(n) => n.clone(),
                    None => return Err(c.error(format!("no <bsdf> has the id \"{id}\""))),
                }
            }
            _ => continue,
        };
        c.used.set(true);
        if found.is_some() {
            return Err(c.error("a shape has at most one BSDF"));
        }
        found = Some(name);
    }
    let emits = node.children.iter().any(|c| c.tag == "emitter");
    Ok(found.unwrap_or_else(|| bsdfs::default_material(ctx, emits)))
}

/// Whether the named material looks anything up by uv (then a sphere's uv convention
/// shows in the image).
fn reads_uv(ctx: &Ctx, material: &str) -> bool {
    fn texture(t: &TextureDesc) -> bool {
        !matches!(t, TextureDesc::Constant(_))
    }
    fn bsdf(b: &BsdfDesc) -> bool {
        match b {
            BsdfDesc::Diffuse { albedo } | BsdfDesc::Plastic { albedo, .. } => texture(albedo),
            BsdfDesc::MetalRough {
                base_color,
                metallic,
                roughness,
            } => texture(base_color) || texture(metallic) || texture(roughness),
            BsdfDesc::NormalMap { .. } | BsdfDesc::Alpha { .. } => true,
            BsdfDesc::TwoSided(inner) | BsdfDesc::OneSided(inner) => bsdf(inner),
            BsdfDesc::Mix { weight, a, b } => texture(weight) || bsdf(a) || bsdf(b),
            BsdfDesc::Conductor { .. } | BsdfDesc::Dielectric { .. } | BsdfDesc::Null => false,
        }
    }
    ctx.desc
        .materials
        .iter()
        .find(|m| m.name == material)
        .is_some_and(|m| bsdf(&m.bsdf))
}

/// Mitsuba's `Mesh::recompute_vertex_normals`, which its `obj` and `ply` shapes apply to
/// a mesh without normals unless `face_normals` is set: each vertex gets the sum of its
/// faces' unit normals weighted by the face's angle at the vertex (Thürmer and Wüthrich
/// 1998), normalized; a vertex with no valid face gets (1, 0, 0), as in Mitsuba.
pub(crate) fn vertex_normals(mesh: &MeshDesc) -> Vec<Vec3> {
    // The angle between unit vectors, accurate near 0 and π (Mitsuba's `unit_angle`).
    fn unit_angle(a: Vec3, b: Vec3) -> f32 {
        if a.dot(b) < 0.0 {
            std::f32::consts::PI - 2.0 * ((a + b).length() * 0.5).min(1.0).asin()
        } else {
            2.0 * ((a - b).length() * 0.5).min(1.0).asin()
        }
    }
    let mut normals = vec![Vec3::ZERO; mesh.positions.len()];
    for &[i0, i1, i2] in &mesh.indices {
        let [p0, p1, p2] = [i0, i1, i2].map(|i| mesh.positions[i as usize]);
        let n = (p1 - p0).cross(p2 - p0);
        if n.length_squared() == 0.0 || !n.is_finite() {
            continue;
        }
        let n = n.normalize();
        let corners = [
            (i0, p1 - p0, p2 - p0),
            (i1, p2 - p1, p0 - p1),
            (i2, p0 - p2, p1 - p2),
        ];
        for (i, a, b) in corners {
            normals[i as usize] += n * unit_angle(a.normalize(), b.normalize());
        }
    }
    for n in &mut normals {
        *n = n.try_normalize().unwrap_or(Vec3::X);
    }
    normals
}

/// Whether the named material bends its normals by a map.
fn normal_mapped(ctx: &Ctx, material: &str) -> bool {
    fn bsdf(b: &BsdfDesc) -> bool {
        match b {
            BsdfDesc::NormalMap { .. } => true,
            BsdfDesc::TwoSided(inner) | BsdfDesc::OneSided(inner) => bsdf(inner),
            BsdfDesc::Alpha { inner, .. } => bsdf(inner),
            BsdfDesc::Mix { a, b, .. } => bsdf(a) || bsdf(b),
            _ => false,
        }
    }
    ctx.desc
        .materials
        .iter()
        .find(|m| m.name == material)
        .is_some_and(|m| bsdf(&m.bsdf))
}

/// The mesh with per-vertex tangents ∂p/∂u (the sum over its faces, normalized) and
/// handedness +1. Mitsuba's `normalmap` takes its bitangent as n × ∂p/∂u whatever the
/// uvs' orientation, where Candela without tangents flips it on mirrored uvs (glTF's
/// rule), which an OBJ's flipped v makes every face.
fn with_tangents(mesh: &MeshDesc) -> MeshDesc {
    let mut tangents = vec![Vec3::ZERO; mesh.positions.len()];
    if mesh.uvs.len() == mesh.positions.len() {
        for &[i0, i1, i2] in &mesh.indices {
            let [p0, p1, p2] = [i0, i1, i2].map(|i| mesh.positions[i as usize]);
            let [t0, t1, t2] = [i0, i1, i2].map(|i| mesh.uvs[i as usize]);
            let (d1, d2) = (t1 - t0, t2 - t0);
            let det = d1.x * d2.y - d1.y * d2.x;
            if det == 0.0 || !det.is_finite() {
                continue;
            }
            let dpdu = ((p1 - p0) * d2.y - (p2 - p0) * d1.y) / det;
            for i in [i0, i1, i2] {
                tangents[i as usize] += dpdu;
            }
        }
    }
    MeshDesc {
        tangents: tangents
            .into_iter()
            .map(|t| t.try_normalize().unwrap_or(Vec3::ZERO).extend(1.0))
            .collect(),
        ..mesh.clone()
    }
}

/// Segments around a `cylinder`: the flat sides lie within r·(1 − cos(π/128)) ≈ 3·10⁻⁴ r
/// of the tube and its area is short by 10⁻⁴.
const CYLINDER_SEGMENTS: u32 = 128;

/// Mitsuba's `cylinder`: an open tube (no caps) of `radius` (1) from `p0` (origin) to `p1`
/// (0, 0, 1), normals outwards, as a smooth-shaded mesh in the shape's object space (its
/// `to_world` then applies). Mitsuba's tube is the unit one, z in [0, 1], placed by the
/// frame of p1 − p0 (`coordinate_system`, i.e. [`Frame::from_z`]); its uv is
/// (atan2(y, x)/2π, z) in that unit frame.
fn cylinder(node: &Node) -> Result<MeshDesc, LoadError> {
    let p0 = node.point("p0")?.unwrap_or(Vec3::ZERO);
    let p1 = node.point("p1")?.unwrap_or(Vec3::Z);
    let radius = node.float("radius")?.unwrap_or(1.0);
    let axis = p1 - p0;
    if axis.length_squared() == 0.0 || radius <= 0.0 {
        return Err(node.error("a cylinder needs p0 ≠ p1 and a positive radius"));
    }
    let f = Frame::from_z(axis.normalize());
    let mut mesh = MeshDesc::default();
    for j in 0..=CYLINDER_SEGMENTS {
        let u = j as f32 / CYLINDER_SEGMENTS as f32;
        let (sin, cos) = (u * std::f32::consts::TAU).sin_cos();
        let radial = f.s * cos + f.t * sin;
        for v in [0.0, 1.0] {
            mesh.positions.push(p0 + radial * radius + axis * v);
            mesh.normals.push(radial);
            mesh.uvs.push(Vec2::new(u, v));
        }
    }
    for j in 0..CYLINDER_SEGMENTS {
        let (a, b, c, d) = (2 * j, 2 * j + 2, 2 * j + 3, 2 * j + 1);
        // Counter-clockwise seen from outside: (s, t, z) is right-handed.
        mesh.indices.push([a, b, c]);
        mesh.indices.push([a, c, d]);
    }
    Ok(mesh)
}

/// Triangles of [`polar_disk`], as Candela's own disk.
const DISK_SEGMENTS: u32 = 128;

/// The unit disk in z = 0 facing +z with Mitsuba's polar uvs: `disk.cpp` gives a point at
/// radius r and angle φ = atan2(y, x) the uv (r, φ/2π), φ in [0, 2π). Candela's disk
/// primitive maps uvs flat, so a textured disk is this fan instead. Each triangle has its
/// own centre vertex at u = 0 with its rim's v, so v runs from 0 to 1 around without a
/// seam across the fan. Linear interpolation over a triangle reads r to 3·10⁻⁴ (relative)
/// and v to within half a triangle's share (1/256) near the centre.
pub(crate) fn polar_disk() -> MeshDesc {
    let mut mesh = MeshDesc::default();
    let n = DISK_SEGMENTS;
    let rim = |v: f32| {
        let phi = v * std::f32::consts::TAU;
        Vec3::new(phi.cos(), phi.sin(), 0.0)
    };
    for j in 0..n {
        let (v0, v1) = (j as f32 / n as f32, (j + 1) as f32 / n as f32);
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([Vec3::ZERO, rim(v0), rim(v1)]);
        mesh.uvs.extend([
            Vec2::new(0.0, 0.5 * (v0 + v1)),
            Vec2::new(1.0, v0),
            Vec2::new(1.0, v1),
        ]);
        mesh.normals.extend([Vec3::Z; 3]);
        mesh.indices.push([base, base + 1, base + 2]);
    }
    mesh
}

/// Rings from pole to pole and segments around the axis of [`uv_sphere`]: the flat
/// triangles lie within r·(1 − cos(π/128)) ≈ 3·10⁻⁴ r of the sphere.
const SPHERE_RINGS: u32 = 64;
const SPHERE_SEGMENTS: u32 = 128;

/// A sphere as a smooth-shaded mesh with Mitsuba's uvs. Candela's sphere primitive puts
/// its pole on the world y axis and ignores rotations; Mitsuba's `sphere.cpp` takes the
/// uv of a point from its direction d in the shape's own frame (before `to_world`):
/// u = atan2(d.y, d.x)/2π in [0, 1), v = acos(d.z)/π. The vertices are placed in that
/// frame and the shape's transform moves them, so a texture lands as in Mitsuba. The
/// seam (u = 0 and 1) has its own vertices; the poles one per segment.
pub(crate) fn uv_sphere(center: Vec3, radius: f32) -> MeshDesc {
    let (rings, segments) = (SPHERE_RINGS, SPHERE_SEGMENTS);
    let mut mesh = MeshDesc::default();
    for i in 0..=rings {
        let v = i as f32 / rings as f32;
        let theta = v * std::f32::consts::PI;
        for j in 0..=segments {
            let u = j as f32 / segments as f32;
            let phi = u * std::f32::consts::TAU;
            let d = Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            mesh.positions.push(center + radius * d);
            mesh.normals.push(d);
            mesh.uvs.push(Vec2::new(u, v));
        }
    }
    let index = |i: u32, j: u32| i * (segments + 1) + j;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b) = (index(i, j), index(i + 1, j));
            let (c, d) = (index(i + 1, j + 1), index(i, j + 1));
            // Counter-clockwise seen from outside; the pole rows' quads are triangles.
            if i + 1 < rings {
                mesh.indices.push([a, b, c]);
            }
            if i > 0 {
                mesh.indices.push([a, c, d]);
            }
        }
    }
    mesh
}
