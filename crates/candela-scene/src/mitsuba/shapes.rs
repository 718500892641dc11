//! `<shape>`: Mitsuba's primitives map to Candela's unit primitives, which follow the
//! same conventions (rectangle [-1,1]² and disk of radius 1 in z = 0 facing +z, cube
//! [-1,1]³); `obj` and `ply` go through [`crate::load_mesh`].

use candela_core::desc::{GeometryDesc, ShapeDesc};
use glam::{Mat4, Vec3};

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
            GeometryDesc::Mesh(mesh)
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
