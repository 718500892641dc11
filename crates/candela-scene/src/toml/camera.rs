//! The `[camera]` table: a pinhole, a thin lens with a disc, polygon or image aperture, or
//! an orthographic camera. The types take different keys, so a lens key on a pinhole is
//! an unknown key.

use std::path::Path;

use candela_core::color::srgb_decode;
use candela_core::desc::{ApertureDesc, ApertureSizeDesc, CameraDesc, FocusDesc, LensDesc};
use serde::Deserialize;
use toml::Spanned;

use crate::toml::values::{Num, V2, V3};
use crate::toml::{deserialize, item_type, Item};
use crate::{LoadError, Source};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PinholeSection {
    #[serde(rename = "type")]
    _kind: Option<String>,
    position: Option<V3>,
    look_at: Option<V3>,
    up: Option<V3>,
    fov: Option<Num>,
    focal_length: Option<Spanned<Num>>,
    sensor: Option<V2>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OrthographicSection {
    #[serde(rename = "type")]
    _kind: String,
    position: Option<V3>,
    look_at: Option<V3>,
    up: Option<V3>,
    height: Option<Num>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ThinLensSection {
    #[serde(rename = "type")]
    _kind: String,
    position: Option<V3>,
    look_at: Option<V3>,
    up: Option<V3>,
    fov: Option<Num>,
    focal_length: Option<Spanned<Num>>,
    sensor: Option<V2>,
    focus_distance: Option<Num>,
    focus_on: Option<Spanned<V3>>,
    f_number: Option<Num>,
    aperture_radius: Option<Spanned<Num>>,
    aperture: Option<Spanned<toml::Value>>,
}

/// Parses `[camera]`; relative aperture image paths resolve against `base`.
pub(crate) fn parse_camera(
    src: &Source,
    base: &Path,
    key_at: usize,
    value: Item,
) -> Result<CameraDesc, LoadError> {
    let has_type = value
        .get_ref()
        .as_table()
        .is_some_and(|t| t.contains_key("type"));
    let kind = if has_type {
        item_type(
            src,
            "camera",
            &value,
            &["pinhole", "thin_lens", "orthographic"],
        )?
    } else {
        "pinhole"
    };
    let d = CameraDesc {
        span: src.span(key_at),
        ..CameraDesc::default()
    };
    if kind == "pinhole" {
        let c: PinholeSection = deserialize(src, value)?;
        return frame(
            src,
            d,
            c.position,
            c.look_at,
            c.up,
            c.fov,
            c.focal_length,
            c.sensor,
        );
    }
    if kind == "orthographic" {
        let c: OrthographicSection = deserialize(src, value)?;
        let Some(Num(height)) = c.height else {
            return Err(src.error(
                key_at,
                "an orthographic camera needs `height`, its view's height in scene units",
            ));
        };
        let d = frame(src, d, c.position, c.look_at, c.up, None, None, None)?;
        return Ok(CameraDesc {
            ortho_height: Some(height),
            ..d
        });
    }
    let c: ThinLensSection = deserialize(src, value)?;
    let mut d = frame(
        src,
        d,
        c.position,
        c.look_at,
        c.up,
        c.fov,
        c.focal_length,
        c.sensor,
    )?;
    let focus = match (c.focus_distance, c.focus_on) {
        (Some(_), Some(p)) => {
            return Err(src.error(
                p.span().start,
                "give `focus_distance` or `focus_on`, not both",
            ))
        }
        (Some(Num(f)), None) => FocusDesc::Distance(f),
        (None, Some(p)) => FocusDesc::Point(p.into_inner().vec3()),
        (None, None) => FocusDesc::LookAt,
    };
    let size = match (c.f_number, c.aperture_radius) {
        (Some(_), Some(r)) => {
            return Err(src.error(
                r.span().start,
                "give `f_number` or `aperture_radius`, not both",
            ))
        }
        (Some(Num(n)), None) => ApertureSizeDesc::FNumber(n),
        (None, Some(r)) => ApertureSizeDesc::Radius(r.into_inner().0),
        (None, None) => {
            return Err(src.error(
                key_at,
                "a thin_lens camera needs `f_number` or `aperture_radius`",
            ))
        }
    };
    let aperture = match c.aperture {
        Some(a) => parse_aperture(src, base, a)?,
        None => ApertureDesc::Disc,
    };
    d.lens = Some(LensDesc {
        focus,
        size,
        aperture,
    });
    Ok(d)
}

/// The keys both camera types share.
#[allow(clippy::too_many_arguments)]
fn frame(
    src: &Source,
    d: CameraDesc,
    position: Option<V3>,
    look_at: Option<V3>,
    up: Option<V3>,
    fov: Option<Num>,
    focal_length: Option<Spanned<Num>>,
    sensor: Option<V2>,
) -> Result<CameraDesc, LoadError> {
    if let (Some(_), Some(f)) = (fov, &focal_length) {
        return Err(src.error(f.span().start, "give `fov` or `focal_length`, not both"));
    }
    Ok(CameraDesc {
        position: position.map_or(d.position, V3::vec3),
        look_at: look_at.map_or(d.look_at, V3::vec3),
        up: up.map_or(d.up, V3::vec3),
        fov_y_deg: fov.map_or(d.fov_y_deg, |n| n.0),
        focal_length_mm: focal_length.map(|f| f.into_inner().0),
        sensor_mm: sensor.map_or(d.sensor_mm, V2::vec2),
        ..d
    })
}

const APERTURE_FORMS: &str =
    "`aperture` must be \"disc\", { blades = N, rotation = DEGREES } or { image = \"FILE\" }";

fn parse_aperture(
    src: &Source,
    base: &Path,
    value: Spanned<toml::Value>,
) -> Result<ApertureDesc, LoadError> {
    let at = value.span().start;
    let bad = |what: &str| src.error(at, format!("{what}; {APERTURE_FORMS}"));
    match value.into_inner() {
        toml::Value::String(s) if s == "disc" => Ok(ApertureDesc::Disc),
        toml::Value::String(s) => Err(bad(&format!("unknown aperture \"{s}\""))),
        toml::Value::Table(t) => {
            if let Some(img) = t.get("image") {
                if t.len() > 1 {
                    return Err(bad("an image aperture takes only `image`"));
                }
                let Some(file) = img.as_str() else {
                    return Err(bad("`image` must be a file name"));
                };
                return load_aperture_image(src, at, &base.join(file), file);
            }
            if let Some(k) = t
                .keys()
                .find(|k| !["blades", "rotation"].contains(&k.as_str()))
            {
                return Err(bad(&format!("unknown aperture key `{k}`")));
            }
            let blades = match t.get("blades").and_then(toml::Value::as_integer) {
                Some(n) if (3..=64).contains(&n) => n as u32,
                _ => return Err(bad("`blades` must be an integer from 3 to 64")),
            };
            let rotation_deg = match t.get("rotation") {
                None => 0.0,
                Some(v) => match v.as_float().or(v.as_integer().map(|i| i as f64)) {
                    Some(r) if r.is_finite() => r as f32,
                    _ => return Err(bad("`rotation` must be a finite number of degrees")),
                },
            };
            Ok(ApertureDesc::Polygon {
                blades,
                rotation_deg,
            })
        }
        other => Err(bad(&format!("found {}", other.type_str()))),
    }
}

/// Decodes an aperture mask to linear luminance (Rec.709 weights). 8- and 16-bit images
/// are taken as sRGB-encoded, float images (.hdr) as linear; alpha multiplies the
/// luminance, so a transparent pixel passes no light.
fn load_aperture_image(
    src: &Source,
    at: usize,
    path: &Path,
    name: &str,
) -> Result<ApertureDesc, LoadError> {
    let img = crate::image_texture::open_dynamic(path)
        .map_err(|e| src.error(at, format!("cannot read aperture image `{name}`: {e}")))?;
    let linear = matches!(
        img.color(),
        image::ColorType::Rgb32F | image::ColorType::Rgba32F
    );
    let rgba = img.to_rgba32f();
    let luminance: Vec<f32> = rgba
        .pixels()
        .map(|p| {
            let [r, g, b, a] = p.0;
            let [r, g, b] = if linear {
                [r, g, b]
            } else {
                [srgb_decode(r), srgb_decode(g), srgb_decode(b)]
            };
            (0.2126 * r + 0.7152 * g + 0.0722 * b) * a
        })
        .collect();
    if !luminance.iter().any(|&v| v > 0.0) {
        return Err(src.error(
            at,
            format!("aperture image `{name}` is black: no light would pass"),
        ));
    }
    Ok(ApertureDesc::Image {
        width: rgba.width(),
        height: rgba.height(),
        luminance,
    })
}
