//! `<shape>`: Mitsuba's primitives map to Candela's unit primitives, which follow the
//! same conventions (rectangle [-1,1]² and disk of radius 1 in z = 0 facing +z, cube
//! [-1,1]³); `obj` and `ply` go through [`crate::load_mesh`]. A textured `sphere`
//! becomes a mesh carrying Mitsuba's sphere uvs (see [`uv_sphere`]).

use std::sync::Arc;

use candela_core::desc::{BsdfDesc, GeometryDesc, MeshDesc, ShapeDesc, TextureDesc};
use glam::{Mat4, Vec2, Vec3};

use super::parse::Node;
use super::{bsdfs, describe, transform, Ctx};
use crate::LoadError;

pub(crate) fn shape(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    let geometry = match node.kind() {
        "rectangle" => GeometryDesc::Rectangle,
        "disk" => GeometryDesc::Disk,
        "cube" => GeometryDesc::Cube,
        "sphere" => GeometryDesc::Sphere {
            center: node.point("center")?.unwrap_or(Vec3::ZERO),
            radius: node.float("radius")?.unwrap_or(1.0),
        },
        "obj" | "ply" => {
            let file = node
                .string("filename")?
                .ok_or_else(|| node.error(format!("{} needs a filename", describe(node))))?;
            let mut mesh = crate::load_mesh(&ctx.base.join(file))
                .map_err(|e| node.error(format!("cannot load mesh: {e}")))?;
            if node.boolean("face_normals")?.unwrap_or(false) {
                mesh.normals.clear();
            }
            // Mitsuba flips OBJ texture coordinates by default; no Candela texture reads
            // them yet, so the flag is read and only honoured on the uvs.
            if node
                .boolean("flip_tex_coords")?
                .unwrap_or(node.kind() == "obj")
            {
                mesh.uvs.iter_mut().for_each(|uv| uv.y = 1.0 - uv.y);
            }
            GeometryDesc::Mesh(Arc::new(mesh))
        }
        _ => {
            return ctx.unsupported(node, format!("<{}> is not supported", describe(node)));
        }
    };
    let transform = match node.prop("to_world") {
        Some(t) if t.tag == "transform" => transform::transform(t)?,
        Some(t) => return Err(t.error("to_world must be a <transform>")),
        None => Mat4::IDENTITY,
    };
    let flip_normals = node.boolean("flip_normals")?.unwrap_or(false);
    let material = material(ctx, node)?;
    let geometry = match geometry {
        GeometryDesc::Sphere { center, radius } if reads_uv(ctx, &material) => {
            GeometryDesc::Mesh(Arc::new(uv_sphere(center, radius)))
        }
        g => g,
    };

    let mut emission = None;
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
        emission = Some(e.color("radiance")?.unwrap_or(Vec3::ONE));
        ctx.check_unused(e)?;
    }
    ctx.check_unused(node)?;
    ctx.desc.shapes.push(ShapeDesc {
        geometry,
        material,
        emission,
        transform,
        flip_normals,
        span: node.span.clone(),
    });
    Ok(())
}

/// The shape's material: an inline `<bsdf>`, a `<ref id>` to one, or Mitsuba's default
/// (grey diffuse; black for an emitter, which then only emits).
fn material(ctx: &mut Ctx, node: &Node) -> Result<String, LoadError> {
    let mut found: Option<String> = None;
    for c in &node.children {
        let name = match c.tag.as_str() {
            "bsdf" => bsdfs::material(ctx, c)?,
            "ref" => {
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
            BsdfDesc::Conductor { .. } | BsdfDesc::Dielectric { .. } => false,
        }
    }
    ctx.desc
        .materials
        .iter()
        .find(|m| m.name == material)
        .is_some_and(|m| bsdf(&m.bsdf))
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
