//! glTF images: where their bytes are (a buffer view, a `data:` URI, a file beside the
//! glTF) and how they are decoded for each use — base colour sRGB, data linear, alpha
//! from the fourth channel, normal maps with their `scale` baked in.

use std::path::Path;

use candela_core::desc::ImageDesc;
use glam::{Vec2, Vec3};

use super::Ctx;
use crate::image_texture::{decode_guessed, from_dynamic, Encoding};
use crate::LoadError;

/// How an image's pixels are decoded for one use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Use {
    Color,
    Data,
    Alpha,
    /// A normal map with the scale's bits.
    Normal(u32),
}

/// Decodes `texture`'s image for `use_` (`path` locates errors).
pub(crate) fn decode(
    ctx: &mut Ctx,
    path: &str,
    texture: &gltf::Texture,
    use_: Use,
) -> Result<ImageDesc, LoadError> {
    let source = texture.source();
    let where_ = format!("{path}: images[{}]", source.index());
    let bytes = image_bytes(ctx, &source).map_err(|e| ctx.error(&where_, e))?;
    let dynamic = decode_guessed(&bytes).map_err(|e| {
        let e = crate::escape_control(e.trim());
        ctx.error(&where_, format!("cannot decode image: {e}"))
    })?;
    let img = match use_ {
        Use::Color => from_dynamic(&dynamic, Encoding::Srgb),
        Use::Data => from_dynamic(&dynamic, Encoding::Gamma(1.0)),
        Use::Alpha => {
            let rgba = dynamic.to_rgba32f();
            ImageDesc {
                width: rgba.width(),
                height: rgba.height(),
                pixels: rgba.pixels().map(|p| Vec3::splat(p[3])).collect(),
            }
        }
        Use::Normal(bits) => {
            let s = f32::from_bits(bits);
            let mut img = from_dynamic(&dynamic, Encoding::Gamma(1.0));
            if s > 1.0 {
                ctx.warn(format!(
                    "{path}: normal scale {s} > 1 clamps tilted texels to the unit square"
                ));
            }
            if s != 1.0 {
                for p in &mut img.pixels {
                    let xy = ((Vec2::new(p.x, p.y) * 2.0 - Vec2::ONE) * s)
                        .clamp(Vec2::NEG_ONE, Vec2::ONE);
                    (p.x, p.y) = ((xy.x + 1.0) * 0.5, (xy.y + 1.0) * 0.5);
                }
            }
            img
        }
    };
    Ok(img)
}

/// An image's encoded bytes: from a buffer view, a `data:` URI or a file beside the glTF.
fn image_bytes(ctx: &Ctx, image: &gltf::Image) -> Result<Vec<u8>, String> {
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buffer = ctx
                .buffers
                .get(view.buffer().index())
                .ok_or_else(|| format!("buffer {} is missing", view.buffer().index()))?;
            buffer
                .0
                .get(view.offset()..view.offset() + view.length())
                .map(<[u8]>::to_vec)
                .ok_or_else(|| {
                    format!(
                        "buffer view {} reads past the end of buffer {}",
                        view.index(),
                        view.buffer().index()
                    )
                })
        }
        gltf::image::Source::Uri { uri, .. } => {
            if let Some(rest) = uri.strip_prefix("data:") {
                let (_, data) = rest
                    .split_once(";base64,")
                    .ok_or("a data URI image must be base64")?;
                base64::decode(data).map_err(|e| format!("bad base64 image data: {e}"))
            } else {
                let Some(base) = ctx.base else {
                    return Err(format!(
                        "image \"{uri}\" is an external file, which bytes in memory cannot resolve"
                    ));
                };
                let file = base.join(Path::new(&percent_decode(uri)));
                std::fs::read(&file).map_err(|e| format!("cannot read {}: {e}", file.display()))
            }
        }
    }
}

/// Undoes %XX escapes of a relative URI (glTF URIs are RFC 3986).
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_escapes_decode() {
        assert_eq!(percent_decode("a%20b.png"), "a b.png");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("x%2"), "x%2");
    }
}
