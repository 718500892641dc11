//! `[materials.NAME]` entries of the TOML format: the BSDF types and their textures
//! (documented in `docs/scene-format.md`).

use std::fmt;
use std::path::Path;
use std::sync::Arc;

use candela_core::desc::{
    metal_preset, BsdfDesc, ImageTextureDesc, MicrofacetDesc, TextureDesc, WrapMode, METAL_PRESETS,
};
use glam::{Affine2, Vec3};
use serde::de::{self, IgnoredAny, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};
use toml::Spanned;

use crate::image_texture::{load_image, Encoding};
use crate::toml::values::{Num, Splat3, V2};
use crate::toml::{deserialize, Item};
use crate::{LoadError, Source};

/// The material types, for `type = "..."`.
pub(crate) const MATERIAL_TYPES: &[&str] = &[
    "diffuse",
    "conductor",
    "dielectric",
    "plastic",
    "metal_rough",
    "mix",
    "null",
];

/// A texturable value: one number, `[r, g, b]`, or a texture table.
#[derive(Debug)]
pub(crate) enum TexValue {
    Value(Vec3),
    Table(TexTable),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TexTable {
    #[serde(rename = "type")]
    kind: TexKind,
    file: Option<Spanned<String>>,
    /// `"srgb"` or a power γ (1 = linear); the default depends on the slot.
    gamma: Option<GammaValue>,
    wrap: Option<Wrap>,
    uv_scale: Option<V2>,
    uv_offset: Option<V2>,
    uv_rotation: Option<Num>,
    scale: Option<Splat3>,
    channel: Option<u8>,
    a: Option<Splat3>,
    b: Option<Splat3>,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
enum TexKind {
    Image,
    Checker,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum Wrap {
    Repeat,
    Clamp,
    Mirror,
}

/// `distribution = "ggx" | "beckmann"` of a rough conductor or dielectric.
#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum Distribution {
    Ggx,
    Beckmann,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(untagged)]
enum GammaValue {
    Power(f32),
    Named(GammaName),
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum GammaName {
    Srgb,
}

struct TexVisitor;

impl<'de> Visitor<'de> for TexVisitor {
    type Value = TexValue;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number, an array of 3 numbers or a texture table")
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<TexValue, E> {
        Splat3::deserialize(de::value::I64Deserializer::new(v)).map(|c| TexValue::Value(c.0))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<TexValue, E> {
        Splat3::deserialize(de::value::U64Deserializer::new(v)).map(|c| TexValue::Value(c.0))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<TexValue, E> {
        Splat3::deserialize(de::value::F64Deserializer::new(v)).map(|c| TexValue::Value(c.0))
    }
    fn visit_seq<A: de::SeqAccess<'de>>(self, seq: A) -> Result<TexValue, A::Error> {
        Splat3::deserialize(de::value::SeqAccessDeserializer::new(seq))
            .map(|c| TexValue::Value(c.0))
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<TexValue, A::Error> {
        TexTable::deserialize(de::value::MapAccessDeserializer::new(map)).map(TexValue::Table)
    }
}

impl<'de> Deserialize<'de> for TexValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TexVisitor)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialEntry {
    #[serde(rename = "type")]
    _kind: IgnoredAny,
    albedo: Option<Spanned<TexValue>>,
    base_color: Option<Spanned<TexValue>>,
    metallic: Option<Spanned<TexValue>>,
    roughness: Option<Spanned<TexValue>>,
    normal_map: Option<Spanned<TexValue>>,
    preset: Option<Spanned<String>>,
    eta: Option<Spanned<Splat3>>,
    k: Option<Splat3>,
    alpha: Option<Num>,
    alpha_u: Option<Num>,
    alpha_v: Option<Num>,
    distribution: Option<Distribution>,
    thin: Option<bool>,
    two_sided: Option<bool>,
    specular: Option<Splat3>,
    materials: Option<Spanned<Vec<Spanned<String>>>>,
    weight: Option<Spanned<TexValue>>,
}

/// Whether a texture slot holds colour (sRGB-decoded by default) or data (linear).
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Slot {
    Color,
    Data,
}

/// Albedo of a diffuse material without one (Mitsuba's default).
const DEFAULT_ALBEDO: f32 = 0.5;

/// Keys each type accepts besides `type`, `two_sided` and `normal_map`.
fn allowed_keys(kind: &str) -> &'static [&'static str] {
    match kind {
        "diffuse" => &["albedo"],
        "conductor" => &[
            "preset",
            "eta",
            "k",
            "alpha",
            "alpha_u",
            "alpha_v",
            "distribution",
        ],
        "dielectric" => &["eta", "alpha", "alpha_u", "alpha_v", "distribution", "thin"],
        "plastic" => &["albedo", "eta", "alpha", "distribution", "specular"],
        "metal_rough" => &["base_color", "metallic", "roughness"],
        "mix" => &["materials", "weight"],
        _ => &[],
    }
}

/// Parses one material of the given (already checked) type; `mixed` gives the BSDF of a
/// material a mix names.
pub(crate) fn parse_material(
    src: &Source,
    base: &Path,
    kind: &str,
    item: Item,
    mixed: &mut dyn FnMut(&Spanned<String>) -> Result<BsdfDesc, LoadError>,
) -> Result<BsdfDesc, LoadError> {
    // Reject keys of other types first, so the error names the key.
    if let Some(table) = item.get_ref().as_table() {
        let allowed = allowed_keys(kind);
        for (key, _) in table.iter() {
            let k = key.get_ref().as_ref();
            if !allowed.contains(&k) && !["type", "two_sided", "normal_map"].contains(&k) {
                return Err(src.error(
                    key.span().start,
                    format!("unknown key `{k}` for a {kind} material; expected one of {allowed:?}, `two_sided`, `normal_map`"),
                ));
            }
        }
    }
    let at = item.span().start;
    let m: MaterialEntry = deserialize(src, item)?;
    let tex = |v: Option<Spanned<TexValue>>, default: Vec3, slot| match v {
        None => Ok(TextureDesc::Constant(default)),
        Some(v) => texture(src, base, v, slot),
    };
    let alpha = |m: &MaterialEntry| {
        let a = m.alpha.map_or(0.0, |n| n.0);
        (m.alpha_u.map_or(a, |n| n.0), m.alpha_v.map_or(a, |n| n.0))
    };
    let distribution = match m.distribution {
        None | Some(Distribution::Ggx) => MicrofacetDesc::Ggx,
        Some(Distribution::Beckmann) => MicrofacetDesc::Beckmann,
    };
    let bsdf = match kind {
        "diffuse" => BsdfDesc::Diffuse {
            albedo: tex(m.albedo, Vec3::splat(DEFAULT_ALBEDO), Slot::Color)?,
        },
        "null" => BsdfDesc::Null,
        "conductor" => {
            let (alpha_u, alpha_v) = alpha(&m);
            let (eta, k) = match (m.preset, m.eta, m.k) {
                (Some(p), None, None) => metal_preset(p.get_ref()).ok_or_else(|| {
                    src.error(
                        p.span().start,
                        format!(
                            "unknown metal preset \"{}\"; known: {METAL_PRESETS:?}",
                            p.get_ref()
                        ),
                    )
                })?,
                (None, Some(eta), Some(k)) => (eta.get_ref().0, k.0),
                (None, None, None) => metal_preset("Al").expect("Al is a preset"),
                _ => {
                    return Err(src.error(
                        at,
                        "a conductor takes either `preset` or both `eta` and `k`",
                    ))
                }
            };
            BsdfDesc::Conductor {
                eta,
                k,
                specular: Vec3::ONE,
                alpha_u,
                alpha_v,
                distribution,
            }
        }
        "dielectric" => {
            let (alpha_u, alpha_v) = alpha(&m);
            BsdfDesc::Dielectric {
                eta: scalar_eta(src, m.eta)?,
                alpha_u,
                alpha_v,
                distribution,
                thin: m.thin.unwrap_or(false),
                tint: TextureDesc::Constant(Vec3::ONE),
            }
        }
        "plastic" => BsdfDesc::Plastic {
            albedo: tex(m.albedo, Vec3::splat(DEFAULT_ALBEDO), Slot::Color)?,
            eta: scalar_eta(src, m.eta)?,
            alpha: m.alpha.map_or(0.0, |n| n.0),
            distribution,
            linear: false,
            specular: m.specular.map_or(Vec3::ONE, |c| c.0),
        },
        "metal_rough" => BsdfDesc::MetalRough {
            base_color: tex(m.base_color, Vec3::ONE, Slot::Color)?,
            metallic: tex(m.metallic, Vec3::ONE, Slot::Data)?,
            roughness: tex(m.roughness, Vec3::ONE, Slot::Data)?,
        },
        "mix" => {
            let Some(names) = m.materials else {
                return Err(src.error(at, "a mix needs `materials = [\"A\", \"B\"]`"));
            };
            let [a, b] = names.get_ref().as_slice() else {
                return Err(src.error(
                    names.span().start,
                    format!("a mix takes 2 materials, not {}", names.get_ref().len()),
                ));
            };
            let Some(weight) = m.weight else {
                return Err(src.error(
                    at,
                    "a mix needs a `weight` (0 gives the first material, 1 the second)",
                ));
            };
            BsdfDesc::Mix {
                weight: texture(src, base, weight, Slot::Data)?,
                a: Box::new(mixed(a)?),
                b: Box::new(mixed(b)?),
            }
        }
        other => unreachable!("type {other} was checked"),
    };
    let bsdf = match m.normal_map {
        Some(map) => BsdfDesc::NormalMap {
            map: texture(src, base, map, Slot::Data)?,
            inner: Box::new(bsdf),
        },
        None => bsdf,
    };
    Ok(if m.two_sided == Some(true) {
        BsdfDesc::TwoSided(Box::new(bsdf))
    } else {
        bsdf
    })
}

/// A dielectric index: one number (default 1.5, glass).
fn scalar_eta(src: &Source, eta: Option<Spanned<Splat3>>) -> Result<f32, LoadError> {
    let Some(eta) = eta else { return Ok(1.5) };
    let v = eta.get_ref().0;
    if v.x != v.y || v.y != v.z {
        return Err(src.error(eta.span().start, "a dielectric's `eta` is one number"));
    }
    if v.x <= 0.0 {
        return Err(src.error(eta.span().start, format!("`eta` {} must be positive", v.x)));
    }
    Ok(v.x)
}

pub(crate) fn texture(
    src: &Source,
    base: &Path,
    v: Spanned<TexValue>,
    slot: Slot,
) -> Result<TextureDesc, LoadError> {
    let at = v.span().start;
    let t = match v.into_inner() {
        TexValue::Value(c) => return Ok(TextureDesc::Constant(c)),
        TexValue::Table(t) => t,
    };
    let deg = t.uv_rotation.map_or(0.0, |n| n.0).to_radians();
    // uv' = R(rotation)·(S·uv) + offset: scale first, then rotate, then move.
    let uv_transform =
        Affine2::from_translation(t.uv_offset.map_or(glam::Vec2::ZERO, |o| o.vec2()))
            * Affine2::from_angle(deg)
            * Affine2::from_scale(t.uv_scale.map_or(glam::Vec2::ONE, |s| s.vec2()));
    let misplaced = |what: &str| {
        src.error(
            at,
            format!("`{what}` does not belong to a {:?} texture", t.kind),
        )
    };
    match t.kind {
        TexKind::Checker => {
            if t.file.is_some() {
                return Err(misplaced("file"));
            }
            Ok(TextureDesc::Checker {
                a: t.a.map_or(Vec3::splat(0.8), |c| c.0),
                b: t.b.map_or(Vec3::splat(0.2), |c| c.0),
                uv_transform,
            })
        }
        TexKind::Image => {
            if t.a.is_some() || t.b.is_some() {
                return Err(misplaced("a`/`b"));
            }
            let Some(file) = t.file else {
                return Err(src.error(at, "an image texture needs `file`"));
            };
            let encoding = match (t.gamma, slot) {
                (Some(GammaValue::Named(GammaName::Srgb)), _) | (None, Slot::Color) => {
                    Encoding::Srgb
                }
                (None, Slot::Data) => Encoding::Gamma(1.0),
                (Some(GammaValue::Power(g)), _) if g.is_finite() && g > 0.0 => Encoding::Gamma(g),
                (Some(GammaValue::Power(g)), _) => {
                    return Err(src.error(at, format!("gamma {g} must be positive")))
                }
            };
            if t.channel.is_some_and(|c| c > 2) {
                return Err(src.error(at, "`channel` must be 0 (R), 1 (G) or 2 (B)"));
            }
            let path = base.join(file.get_ref());
            let image = load_image(&path, encoding).map_err(|e| src.error(file.span().start, e))?;
            Ok(TextureDesc::Image(ImageTextureDesc {
                image: Arc::new(image),
                wrap: match t.wrap.unwrap_or(Wrap::Repeat) {
                    Wrap::Repeat => WrapMode::Repeat,
                    Wrap::Clamp => WrapMode::Clamp,
                    Wrap::Mirror => WrapMode::Mirror,
                },
                uv_transform,
                scale: t.scale.map_or(Vec3::ONE, |s| s.0),
                channel: t.channel,
            }))
        }
    }
}
