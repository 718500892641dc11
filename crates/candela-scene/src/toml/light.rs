//! `[[light]]` entries of the TOML scene format: `point`, `spot`, `directional` and
//! `projector`, their units and colours, and the files they name (IES profiles, projector
//! images), which are read here so that the core gets them decoded.

use std::path::Path;
use std::sync::Arc;

use candela_core::desc::{
    DirectionalLightDesc, ImageDesc, LightAmountDesc, LightColorDesc, LightDesc, LightKindDesc,
    ProfileDesc, ProjectorLightDesc, ShapedPointDesc, SpotFalloff, SpotLightDesc,
};
use candela_core::photometry::GoniometricTable;
use glam::Vec3;
use serde::de::IgnoredAny;
use serde::Deserialize;
use toml::Spanned;

use crate::image_texture::{load_image, Encoding};
use crate::toml::values::{Num, Splat3, V3};
use crate::toml::{deserialize, item_type, Item};
use crate::{LoadError, Source};

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
enum Units {
    Radiometric,
    Photometric,
}

#[derive(Deserialize)]
#[serde(rename_all = "snake_case")]
enum FalloffName {
    Smoothstep,
    Mitsuba,
    Gltf,
}

/// Keys of every light type; each type accepts the subset its `type` names (checked in
/// [`parse_light`]), so that a key of another type is an error.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightEntry {
    #[serde(rename = "type")]
    _kind: IgnoredAny,
    position: Option<V3>,
    direction: Option<V3>,
    up: Option<V3>,
    intensity: Option<Spanned<Splat3>>,
    power: Option<Spanned<Num>>,
    irradiance: Option<Spanned<Splat3>>,
    units: Option<Units>,
    color: Option<Spanned<Splat3>>,
    temperature: Option<Spanned<Num>>,
    ies: Option<Spanned<String>>,
    c0: Option<V3>,
    inner_angle: Option<Num>,
    outer_angle: Option<Num>,
    falloff: Option<FalloffName>,
    image: Option<Spanned<String>>,
    fov: Option<Num>,
    fov_x: Option<Num>,
    fov_y: Option<Num>,
}

/// Keys each light type takes besides `type`.
const KEYS: &[(&str, &[&str])] = &[
    (
        "point",
        &[
            "position",
            "intensity",
            "power",
            "units",
            "color",
            "temperature",
            "ies",
            "direction",
            "c0",
        ],
    ),
    (
        "spot",
        &[
            "position",
            "direction",
            "inner_angle",
            "outer_angle",
            "falloff",
            "intensity",
            "power",
            "units",
            "color",
            "temperature",
            "ies",
            "c0",
        ],
    ),
    (
        "directional",
        &["direction", "irradiance", "units", "color", "temperature"],
    ),
    (
        "projector",
        &[
            "position",
            "direction",
            "up",
            "image",
            "fov",
            "fov_x",
            "fov_y",
            "intensity",
            "power",
            "units",
            "color",
            "temperature",
        ],
    ),
];

/// Rejects keys that belong to another light type, at the key.
fn check_keys(src: &Source, item: &Item, kind: &str) -> Result<(), LoadError> {
    let allowed = KEYS
        .iter()
        .find(|(k, _)| *k == kind)
        .map_or(&[][..], |k| k.1);
    let Some(table) = item.get_ref().as_table() else {
        return Ok(());
    };
    for (key, _) in table.iter() {
        let name = key.get_ref().as_ref();
        let known = KEYS.iter().any(|(_, keys)| keys.contains(&name));
        if name != "type" && known && !allowed.contains(&name) {
            return Err(src.error(
                key.span().start,
                format!("a {kind} light has no key `{name}`"),
            ));
        }
    }
    Ok(())
}

/// Reads an IES file named in a scene into its goniometric table.
pub(crate) fn load_ies_table(
    src: &Source,
    base: &Path,
    file: &Spanned<String>,
) -> Result<Arc<GoniometricTable>, LoadError> {
    let path = base.join(file.get_ref());
    if !path.is_file() {
        return Err(src.error(
            file.span().start,
            format!("IES file {} does not exist", path.display()),
        ));
    }
    let ies = crate::ies::load_ies(&path)?;
    Ok(Arc::new(ies.table()?))
}

/// Reads an image through [`load_image`]: 8- and 16-bit images are sRGB-decoded to
/// linear, float images (HDR, EXR) are taken as linear already.
pub(crate) fn load_linear_image(
    src: &Source,
    base: &Path,
    file: &Spanned<String>,
) -> Result<ImageDesc, LoadError> {
    let at = file.span().start;
    let path = base.join(file.get_ref());
    if !path.is_file() {
        return Err(src.error(at, format!("image file {} does not exist", path.display())));
    }
    load_image(&path, Encoding::Srgb).map_err(|e| src.error(at, e))
}

/// Colour and amount from `color`/`temperature`, `intensity`/`power` (or `irradiance`)
/// and `units`. An RGB `intensity` folds into the colour (radiometric only).
fn color_and_amount(
    src: &Source,
    at: usize,
    e: &LightEntry,
    has_profile: bool,
) -> Result<(LightColorDesc, LightAmountDesc), LoadError> {
    let photometric = e.units == Some(Units::Photometric);
    let mut color = match (&e.color, &e.temperature) {
        (Some(_), Some(t)) => {
            return Err(src.error(
                t.span().start,
                "`color` and `temperature` exclude each other",
            ))
        }
        (Some(c), None) => LightColorDesc::Rgb(c.get_ref().0),
        (None, Some(t)) => LightColorDesc::Temperature(t.get_ref().0),
        (None, None) => LightColorDesc::Rgb(Vec3::ONE),
    };
    let intensity = e.intensity.as_ref().or(e.irradiance.as_ref());
    let amount = match (intensity, &e.power) {
        (Some(_), Some(p)) => {
            return Err(src.error(
                p.span().start,
                "give either an intensity or `power`, not both",
            ))
        }
        (Some(i), None) => {
            let v = i.get_ref().0;
            let scalar = if v.x == v.y && v.y == v.z {
                v.x
            } else if photometric {
                return Err(src.error(
                    i.span().start,
                    "a photometric amount is one number; give the colour in `color`",
                ));
            } else {
                color = match color {
                    LightColorDesc::Rgb(c) => LightColorDesc::Rgb(c * v),
                    LightColorDesc::Temperature(_) => {
                        return Err(src.error(
                            i.span().start,
                            "with `temperature` the intensity is one number",
                        ))
                    }
                };
                1.0
            };
            if photometric {
                LightAmountDesc::Candela(scalar)
            } else {
                LightAmountDesc::WattsPerSr(scalar)
            }
        }
        (None, Some(p)) => {
            if photometric {
                LightAmountDesc::Lumens(p.get_ref().0)
            } else {
                LightAmountDesc::Watts(p.get_ref().0)
            }
        }
        (None, None) if has_profile => LightAmountDesc::ProfileCandela,
        (None, None) => {
            return Err(src.error(at, "the light needs an intensity or a `power`"));
        }
    };
    Ok((color, amount))
}

fn required(
    src: &Source,
    at: usize,
    kind: &str,
    key: &str,
    v: Option<V3>,
) -> Result<Vec3, LoadError> {
    v.map(V3::vec3)
        .ok_or_else(|| src.error(at, format!("a {kind} light needs `{key}`")))
}

/// Parses one `[[light]]`; files resolve against `base`.
pub(crate) fn parse_light(src: &Source, base: &Path, item: Item) -> Result<LightDesc, LoadError> {
    let at = item.span().start;
    let span = src.span(at);
    let kind = item_type(
        src,
        "light",
        &item,
        &["point", "spot", "directional", "projector"],
    )?;
    check_keys(src, &item, kind)?;
    let e: LightEntry = deserialize(src, item)?;
    let profile = |nadir: Vec3| -> Result<Option<ProfileDesc>, LoadError> {
        e.ies
            .as_ref()
            .map(|f| {
                Ok(ProfileDesc {
                    table: load_ies_table(src, base, f)?,
                    nadir,
                    c0: e.c0.map_or(Vec3::X, V3::vec3),
                    span: src.span(f.span().start),
                })
            })
            .transpose()
    };
    let kind = match kind {
        "point" => {
            let position = required(src, at, kind, "position", e.position)?;
            let profile = profile(e.direction.map_or(-Vec3::Y, V3::vec3))?;
            let plain = profile.is_none()
                && e.units.is_none()
                && e.power.is_none()
                && e.color.is_none()
                && e.temperature.is_none();
            match (&e.intensity, plain) {
                // The original form: an RGB intensity in W/sr.
                (Some(i), true) => LightKindDesc::Point {
                    position,
                    intensity: i.get_ref().0,
                },
                _ => {
                    let (color, amount) = color_and_amount(src, at, &e, profile.is_some())?;
                    LightKindDesc::ShapedPoint(ShapedPointDesc {
                        position,
                        color,
                        amount,
                        profile,
                    })
                }
            }
        }
        "spot" => {
            let position = required(src, at, kind, "position", e.position)?;
            let direction = e.direction.map_or(-Vec3::Y, V3::vec3);
            let profile = profile(direction)?;
            let (color, amount) = color_and_amount(src, at, &e, profile.is_some())?;
            let outer = e.outer_angle.map_or(45.0, |n| n.0);
            LightKindDesc::Spot(SpotLightDesc {
                position,
                direction,
                inner_angle_deg: e.inner_angle.map_or(outer.min(30.0), |n| n.0),
                outer_angle_deg: outer,
                falloff: match e.falloff {
                    None | Some(FalloffName::Smoothstep) => SpotFalloff::Smoothstep,
                    Some(FalloffName::Mitsuba) => SpotFalloff::Mitsuba,
                    Some(FalloffName::Gltf) => SpotFalloff::Gltf,
                },
                color,
                amount,
                profile,
            })
        }
        "directional" => {
            let direction = required(src, at, kind, "direction", e.direction)?;
            if e.irradiance.is_none() {
                return Err(src.error(at, "a directional light needs `irradiance`"));
            }
            let (color, amount) = color_and_amount(src, at, &e, false)?;
            LightKindDesc::Directional(DirectionalLightDesc {
                direction,
                color,
                amount,
            })
        }
        _ => {
            let position = required(src, at, kind, "position", e.position)?;
            let direction = e.direction.map_or(-Vec3::Z, V3::vec3);
            let Some(file) = &e.image else {
                return Err(src.error(at, "a projector needs an `image`"));
            };
            let image = load_linear_image(src, base, file)?;
            let (fov_x, fov_y) = match (e.fov, e.fov_x, e.fov_y) {
                (Some(f), None, None) => {
                    // `fov` is vertical; the horizontal one follows the image's aspect.
                    let aspect = image.width as f32 / image.height as f32;
                    let half = (0.5 * f.0.to_radians()).tan() * aspect;
                    (2.0 * half.atan().to_degrees(), f.0)
                }
                (None, Some(x), Some(y)) => (x.0, y.0),
                _ => {
                    return Err(src.error(
                        at,
                        "a projector needs either `fov` (vertical) or both `fov_x` and `fov_y`",
                    ))
                }
            };
            let (color, amount) = color_and_amount(src, at, &e, false)?;
            LightKindDesc::Projector(ProjectorLightDesc {
                position,
                direction,
                up: e.up.map_or(Vec3::Y, V3::vec3),
                fov_x_deg: fov_x,
                fov_y_deg: fov_y,
                image: Arc::new(image),
                color,
                amount,
                projection: Default::default(),
            })
        }
    };
    Ok(LightDesc { kind, span })
}
