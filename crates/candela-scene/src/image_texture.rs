//! Image textures: PNG, JPEG, TGA and BMP through `image`, Radiance HDR through `image`
//! (top-down `-Y` files, and bottom-up `+Y` ones turned upright), OpenEXR through `exr`,
//! decoded once to linear RGB ([`ImageDesc`]).
//!
//! Integer images are encoded: a colour texture is decoded with the exact sRGB EOTF
//! (IEC 61966-2-1, [`srgb_decode`]) unless the scene asks for a pure power law
//! (`gamma = 2.2`); data textures (roughness, metallic, normal maps) are linear. Float
//! images (EXR, HDR) are linear already and never decoded. Alpha is dropped.

use std::io::Cursor;
use std::path::Path;

use candela_core::color::srgb_decode;
use candela_core::desc::ImageDesc;
use glam::Vec3;

use crate::limits::{allocation_budget, check_image_size};

/// How an integer image's values map to linear ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Encoding {
    /// The sRGB transfer function (colour textures by default).
    Srgb,
    /// value^γ (γ = 1: linear data).
    Gamma(f32),
}

impl Encoding {
    /// Linear value of an encoded one in [0, 1].
    pub fn decode(self, v: f32) -> f32 {
        match self {
            Encoding::Srgb => srgb_decode(v),
            Encoding::Gamma(1.0) => v,
            Encoding::Gamma(g) => v.max(0.0).powf(g),
        }
    }
}

/// Loads an image file as linear RGB, choosing the decoder by extension. Errors name the
/// file and the reason.
pub fn load_image(path: &Path, encoding: Encoding) -> Result<ImageDesc, String> {
    check_extension(path)?;
    let bytes =
        std::fs::read(path).map_err(|e| format!("{}: cannot read image: {e}", path.display()))?;
    decode_image(&bytes, path, encoding)
}

/// Decodes the bytes of an image file as linear RGB; `path` names the file in errors and
/// its extension chooses the decoder. The dimensions the header declares are checked
/// against the file's size before any pixel is allocated
/// ([`crate::limits::check_image_size`]).
pub fn decode_image(bytes: &[u8], path: &Path, encoding: Encoding) -> Result<ImageDesc, String> {
    // Decoders' messages may end in a newline (JPEG's do): keep the error on one line.
    let fail = |e: &dyn std::fmt::Display| {
        let e = crate::escape_control(e.to_string().trim());
        format!("{}: cannot read image: {e}", path.display())
    };
    match check_extension(path)? {
        None => decode_exr(bytes).map_err(|e| fail(&e)),
        Some(format) => {
            let img = decode_with_image(bytes, format).map_err(|e| fail(&e))?;
            Ok(from_dynamic(&img, encoding))
        }
    }
}

/// The `image` crate's format for the file's extension, `None` for EXR, or an error for
/// an extension Candela does not read.
fn check_extension(path: &Path) -> Result<Option<image::ImageFormat>, String> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "exr" => Ok(None),
        "png" | "jpg" | "jpeg" | "tga" | "bmp" | "hdr" => Ok(Some(
            image::ImageFormat::from_extension(&ext).expect("a known extension"),
        )),
        _ => Err(format!(
            "{}: unsupported image format \".{ext}\"; supported: .png, .jpg, .jpeg, .tga, \
             .bmp, .hdr, .exr",
            path.display()
        )),
    }
}

/// Opens an image as `image` decodes it, keeping its colour type (PNG, JPEG, TGA, BMP,
/// HDR; not EXR), within the file's allocation budget.
pub(crate) fn open_dynamic(path: &Path) -> Result<image::DynamicImage, String> {
    let Some(format) = check_extension(path)? else {
        return Err(format!("{}: EXR is not supported here", path.display()));
    };
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    decode_with_image(&bytes, format)
}

/// Decodes an image whose format is known only from its bytes (a glTF's embedded or
/// `data:` images), within the same allocation budget as a file.
pub(crate) fn decode_guessed(bytes: &[u8]) -> Result<image::DynamicImage, String> {
    let format = image::guess_format(bytes).map_err(|e| e.to_string())?;
    decode_with_image(bytes, format)
}

/// Decodes through `image`, with its own allocation limit set to the file's budget and
/// the declared dimensions checked first (the decoder's limit does not count Candela's
/// conversions).
fn decode_with_image(
    bytes: &[u8],
    format: image::ImageFormat,
) -> Result<image::DynamicImage, String> {
    let bottom_up = match format {
        image::ImageFormat::Hdr => hdr_as_top_down(bytes),
        _ => None,
    };
    let img = decode_top_down(bottom_up.as_deref().unwrap_or(bytes), format)?;
    Ok(if bottom_up.is_some() {
        img.flipv()
    } else {
        img
    })
}

/// A Radiance file that stores its bottom row first (resolution line `+Y h +X w`, which
/// `image` refuses) as the same bytes with `-Y`: decoded, its rows are then upside down.
/// `None` for any other orientation (the usual `-Y h +X w`, or the column-major ones,
/// which `image` reports as unsupported).
fn hdr_as_top_down(bytes: &[u8]) -> Option<Vec<u8>> {
    // The header ends at the first empty line; the resolution line follows.
    let head = &bytes[..bytes.len().min(1 << 16)];
    let end = head.windows(2).position(|w| w == b"\n\n")? + 2;
    let at = end + bytes[end..].iter().take_while(|&&b| b == b' ').count();
    if !bytes[at..].starts_with(b"+Y ") {
        return None;
    }
    let mut fixed = bytes.to_vec();
    fixed[at] = b'-';
    Some(fixed)
}

/// [`decode_with_image`] of an image stored top row first.
fn decode_top_down(
    bytes: &[u8],
    format: image::ImageFormat,
) -> Result<image::DynamicImage, String> {
    let reader = || image::ImageReader::with_format(Cursor::new(bytes), format);
    let (w, h) = reader().into_dimensions().map_err(|e| e.to_string())?;
    check_image_size(w.into(), h.into(), bytes.len())?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(allocation_budget(bytes.len()));
    let mut reader = reader();
    reader.limits(limits);
    reader.decode().map_err(|e| e.to_string())
}

/// Converts a decoded image to linear RGB: float images as they are, integer ones
/// through `encoding`.
pub fn from_dynamic(img: &image::DynamicImage, encoding: Encoding) -> ImageDesc {
    let is_float = matches!(
        img,
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
    );
    let rgb = img.to_rgb32f();
    let decode = |v: f32| if is_float { v } else { encoding.decode(v) };
    ImageDesc {
        width: rgb.width(),
        height: rgb.height(),
        pixels: rgb
            .pixels()
            .map(|p| Vec3::new(decode(p[0]), decode(p[1]), decode(p[2])))
            .collect(),
    }
}

/// Decodes the first RGB(A) layer of an EXR file at its largest resolution level, or a
/// luminance (`Y`) file as grey. Every layer's declared size is checked against the
/// file's budget before its pixels are allocated.
fn decode_exr(bytes: &[u8]) -> Result<ImageDesc, String> {
    use exr::prelude::*;
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| e.to_string())?;
    for header in meta.headers.iter() {
        let size = header.layer_size;
        check_image_size(size.width() as u64, size.height() as u64, bytes.len())?;
    }
    // A luminance-only file (one `Y` channel, no R, G, B in any layer) is grey.
    let has = |h: &exr::meta::header::Header, name: &str| {
        h.channels
            .list
            .iter()
            .any(|c| c.name.eq_case_insensitive(name))
    };
    let rgb = meta
        .headers
        .iter()
        .any(|h| ["R", "G", "B"].iter().all(|c| has(h, c)));
    if !rgb && meta.headers.iter().any(|h| has(h, "Y")) {
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .specific_channels()
            .required("Y")
            .collect_pixels(
                |res, _| ImageDesc {
                    width: res.width() as u32,
                    height: res.height() as u32,
                    pixels: vec![Vec3::ZERO; res.width() * res.height()],
                },
                |img: &mut ImageDesc, pos, (y,): (f32,)| {
                    let w = img.width as usize;
                    img.pixels[pos.y() * w + pos.x()] = Vec3::splat(y);
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(Cursor::new(bytes))
            .map_err(|e| e.to_string())?;
        return Ok(image.layer_data.channel_data.pixels);
    }
    if !rgb {
        let names: Vec<String> = meta
            .headers
            .iter()
            .flat_map(|h| h.channels.list.iter().map(|c| c.name.to_string()))
            .collect();
        return Err(format!(
            "no layer has R, G and B channels (nor a luminance Y); channels: {}",
            names.join(", ")
        ));
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |res, _| ImageDesc {
                width: res.width() as u32,
                height: res.height() as u32,
                pixels: vec![Vec3::ZERO; res.width() * res.height()],
            },
            |img: &mut ImageDesc, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                let w = img.width as usize;
                img.pixels[pos.y() * w + pos.x()] = Vec3::new(r, g, b);
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| e.to_string())?;
    Ok(image.layer_data.channel_data.pixels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use candela_core::color::{srgb_encode, to_u8};

    #[test]
    fn srgb_128_loads_as_0_2158_and_gamma_2_2_differs() {
        let img = image::DynamicImage::ImageRgb8(image::RgbImage::from_pixel(
            1,
            1,
            image::Rgb([128, 0, 255]),
        ));
        let lin = from_dynamic(&img, Encoding::Srgb).pixels[0];
        assert!((lin.x - 0.2158).abs() < 1e-4, "{lin}");
        assert_eq!((lin.y, lin.z), (0.0, 1.0));
        let g = from_dynamic(&img, Encoding::Gamma(2.2)).pixels[0].x;
        assert!((g - (128.0f32 / 255.0).powf(2.2)).abs() < 1e-6 && (g - 0.2158).abs() > 1e-3);
        assert!(
            (from_dynamic(&img, Encoding::Gamma(1.0)).pixels[0].x - 128.0 / 255.0).abs() < 1e-7
        );
    }

    #[test]
    fn all_256_values_round_trip_through_load_and_write() {
        let row = image::RgbImage::from_fn(256, 1, |x, _| image::Rgb([x as u8; 3]));
        let lin = from_dynamic(&image::DynamicImage::ImageRgb8(row), Encoding::Srgb);
        for (v, p) in lin.pixels.iter().enumerate() {
            assert_eq!(to_u8(srgb_encode(p.x)) as usize, v);
        }
    }

    #[test]
    fn files_of_every_format_load() {
        let dir = tempfile::tempdir().unwrap();
        let rgb = image::RgbImage::from_fn(3, 2, |x, y| {
            image::Rgb([(x * 100) as u8, (y * 200) as u8, 64])
        });
        for ext in ["png", "tga", "bmp"] {
            let p = dir.path().join(format!("t.{ext}"));
            rgb.save(&p).unwrap();
            let img = load_image(&p, Encoding::Gamma(1.0)).unwrap();
            assert_eq!((img.width, img.height), (3, 2), "{ext}");
            assert!(
                (img.pixels[2].x - 200.0 / 255.0).abs() < 1e-6,
                "{ext}: row-major from the top"
            );
            assert!((img.pixels[3].y - 200.0 / 255.0).abs() < 1e-6, "{ext}");
        }
        // Float formats stay linear whatever the encoding asks.
        let hdr =
            image::Rgb32FImage::from_fn(2, 1, |x, _| image::Rgb([x as f32 * 4.0 + 0.5, 0.25, 1.0]));
        let p = dir.path().join("t.hdr");
        image::DynamicImage::ImageRgb32F(hdr).save(&p).unwrap();
        let img = load_image(&p, Encoding::Srgb).unwrap();
        assert!((img.pixels[1].x - 4.5).abs() < 0.05, "{:?}", img.pixels);
        let p = dir.path().join("t.exr");
        exr::prelude::write_rgb_file(&p, 2, 1, |x, _| (x as f32 * 3.0 + 0.5, 0.25f32, 2.0f32))
            .unwrap();
        let img = load_image(&p, Encoding::Srgb).unwrap();
        assert_eq!(img.pixels[1], Vec3::new(3.5, 0.25, 2.0));
        // Errors name the file.
        let e = load_image(&dir.path().join("nope.png"), Encoding::Srgb).unwrap_err();
        assert!(e.contains("nope.png"), "{e}");
        assert!(load_image(&dir.path().join("a.gif"), Encoding::Srgb)
            .unwrap_err()
            .contains("unsupported"));
        std::fs::write(dir.path().join("bad.png"), b"not a png").unwrap();
        assert!(load_image(&dir.path().join("bad.png"), Encoding::Srgb).is_err());
    }
}
