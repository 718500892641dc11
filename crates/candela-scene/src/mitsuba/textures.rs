//! `<texture>`: `bitmap` and `checkerboard`, nested in a BSDF or defined at the top level
//! with an `id` and used through `<ref>`.
//!
//! Mesh uvs are read exactly as Mitsuba reads them (OBJ v flipped by default), so the
//! numbers agree; what differs is the lookup: Mitsuba's v = 0 is an image's top row,
//! Candela's its bottom row. A bitmap therefore gets v ↦ 1 − v after its `to_uv`.

use std::sync::Arc;

use candela_core::desc::{ImageTextureDesc, TextureDesc, WrapMode};
use glam::{Affine2, Vec2, Vec3};

use super::parse::Node;
use super::{describe, transform, Ctx};
use crate::image_texture::{load_image, Encoding};
use crate::LoadError;

/// Builds the texture a `<texture>` element describes.
pub(crate) fn texture(ctx: &mut Ctx, node: &Node) -> Result<TextureDesc, LoadError> {
    let to_uv = match node.prop("to_uv") {
        Some(t) if t.tag == "transform" => {
            let m = transform::transform(t)?;
            Affine2::from_cols(
                m.x_axis.truncate().truncate(),
                m.y_axis.truncate().truncate(),
                m.w_axis.truncate().truncate(),
            )
        }
        Some(t) => return Err(t.error("to_uv must be a <transform>")),
        None => Affine2::IDENTITY,
    };
    let tex = match node.kind() {
        "bitmap" => bitmap(ctx, node, to_uv)?,
        // Mitsuba's squares are half a unit of uv: colour0 where u and v are both in the
        // lower or both in the upper half of their unit, i.e. where ⌊2u⌋ + ⌊2v⌋ is even,
        // which is Candela's `a` on the doubled uv.
        "checkerboard" => TextureDesc::Checker {
            a: node.color("color0")?.unwrap_or(Vec3::splat(0.4)),
            b: node.color("color1")?.unwrap_or(Vec3::splat(0.2)),
            uv_transform: Affine2::from_scale(Vec2::splat(2.0)) * to_uv,
        },
        _ => {
            ctx.unsupported(node, format!("<{}> is not supported", describe(node)))?;
            return Ok(TextureDesc::Constant(Vec3::splat(0.5)));
        }
    };
    ctx.check_unused(node)?;
    Ok(tex)
}

fn bitmap(ctx: &mut Ctx, node: &Node, to_uv: Affine2) -> Result<TextureDesc, LoadError> {
    let file = node
        .string("filename")?
        .ok_or_else(|| node.error("a bitmap needs a filename"))?;
    let file_node = node.prop("filename").expect("read just now");
    // `raw` keeps 8-bit data as stored; otherwise it is sRGB-decoded. HDR formats are
    // linear either way.
    let encoding = if node.boolean("raw")?.unwrap_or(false) {
        Encoding::Gamma(1.0)
    } else {
        Encoding::Srgb
    };
    let image = load_image(&ctx.base.join(file), encoding)
        .map_err(|e| file_node.error(format!("cannot load \"{file}\": {e}")))?;
    if image.width == 0 || image.height == 0 {
        return Err(file_node.error(format!("\"{file}\" is empty")));
    }
    let wrap = match node.string("wrap_mode")?.unwrap_or("repeat") {
        "repeat" => WrapMode::Repeat,
        "mirror" => WrapMode::Mirror,
        "clamp" => WrapMode::Clamp,
        w => {
            let p = node.prop("wrap_mode").expect("read just now");
            return Err(p.error(format!(
                "unknown wrap_mode \"{w}\" (repeat, mirror or clamp)"
            )));
        }
    };
    match node.string("filter_type")? {
        None | Some("bilinear") => {}
        Some("nearest") => ctx.warn(node, "filter_type nearest: Candela filters bilinearly"),
        Some(f) => {
            let p = node.prop("filter_type").expect("read just now");
            return Err(p.error(format!("unknown filter_type \"{f}\" (bilinear or nearest)")));
        }
    }
    let flip_v = Affine2::from_cols(Vec2::X, Vec2::NEG_Y, Vec2::Y);
    Ok(TextureDesc::Image(ImageTextureDesc {
        wrap,
        uv_transform: flip_v * to_uv,
        ..ImageTextureDesc::new(Arc::new(image))
    }))
}
