//! Candela's TOML scene format (documented in `docs/scene-format.md`): `[render]`,
//! `[camera]`, `[materials.NAME]`, `[[shape]]` and `[[light]]`.
//!
//! The document is first parsed into `toml`'s span-keeping tree ([`DeTable`]); each section
//! is then deserialized on its own with `deny_unknown_fields`, so every error (unknown
//! key, wrong type, bad enum value, wrong array length, non-finite number) points at the
//! offending key or value. Items that take a `type` are dispatched on it first, so a key
//! that belongs to another type is reported as unknown.

use std::path::Path;

use candela_core::desc::{
    BsdfDesc, LightDesc, LightKindDesc, LightSamplerKind, MaterialDesc, MisMode, RenderSettings,
    SceneDesc, TextureDesc,
};
use glam::Vec3;
use serde::de::{DeserializeOwned, IgnoredAny};
use serde::Deserialize;
use toml::de::{DeTable, DeValue, ValueDeserializer};
use toml::Spanned;

use crate::toml_camera::parse_camera;
use crate::toml_shape::parse_shape;
use crate::toml_values::{Splat3, V3};
use crate::{LoadError, Source};

/// One item of the parsed tree: a value and its byte range in the text.
pub(crate) type Item<'i> = Spanned<DeValue<'i>>;

/// Parses a TOML scene. Relative paths inside (mesh files) resolve against `file`'s
/// folder; `file` is also the name errors are reported under.
pub fn parse_toml_scene(text: &str, file: &Path) -> Result<SceneDesc, LoadError> {
    let src = Source::new(file, text);
    let root = DeTable::parse(text).map_err(|e| src.toml_error(&e))?;
    let base = file.parent().unwrap_or(Path::new(""));
    let mut desc = SceneDesc::default();
    for (key, value) in root.into_inner() {
        let key_at = key.span().start;
        match key.get_ref().as_ref() {
            "render" => desc.render = parse_render(&src, value)?,
            "camera" => desc.camera = parse_camera(&src, base, key_at, value)?,
            "materials" => desc.materials = parse_materials(&src, value)?,
            "shape" => {
                for item in array_of_tables(&src, "shape", value)? {
                    desc.shapes.push(parse_shape(&src, base, item)?);
                }
            }
            "light" => {
                for item in array_of_tables(&src, "light", value)? {
                    desc.lights.push(parse_light(&src, item)?);
                }
            }
            other => {
                return Err(src.error(
                    key_at,
                    format!(
                        "unknown key `{other}`, expected one of `render`, `camera`, \
                         `materials`, `shape`, `light`"
                    ),
                ))
            }
        }
    }
    Ok(desc)
}

/// Deserializes one item, keeping `toml`'s error location.
pub(crate) fn deserialize<T: DeserializeOwned>(src: &Source, item: Item) -> Result<T, LoadError> {
    T::deserialize(ValueDeserializer::from(item)).map_err(|e| src.toml_error(&e))
}

/// The items of `[[name]]`.
fn array_of_tables<'i>(
    src: &Source,
    name: &str,
    value: Item<'i>,
) -> Result<Vec<Item<'i>>, LoadError> {
    let at = value.span().start;
    match value.into_inner() {
        DeValue::Array(items) => Ok(items.into_iter().collect()),
        other => Err(src.error(
            at,
            format!(
                "`{name}` must be an array of tables (`[[{name}]]`), found {}",
                other.type_str()
            ),
        )),
    }
}

/// The `type` of a table item, checked against the names it may take.
pub(crate) fn item_type(
    src: &Source,
    what: &str,
    item: &Item,
    expected: &[&'static str],
) -> Result<&'static str, LoadError> {
    let one_of = expected
        .iter()
        .map(|t| format!("`{t}`"))
        .collect::<Vec<_>>()
        .join(", ");
    let Some(table) = item.get_ref().as_table() else {
        return Err(src.error(
            item.span().start,
            format!(
                "a {what} must be a table, found {}",
                item.get_ref().type_str()
            ),
        ));
    };
    let Some(value) = table.get("type") else {
        return Err(src.error(
            item.span().start,
            format!("{what} has no `type`; expected one of {one_of}"),
        ));
    };
    match value.get_ref().as_str() {
        Some(t) => expected.iter().copied().find(|&e| e == t).ok_or_else(|| {
            src.error(
                value.span().start,
                format!("unknown {what} type `{t}`, expected one of {one_of}"),
            )
        }),
        None => Err(src.error(
            value.span().start,
            format!(
                "{what} `type` must be a string, found {}",
                value.get_ref().type_str()
            ),
        )),
    }
}

#[derive(Deserialize)]
#[serde(rename_all = "snake_case")]
enum MisName {
    Balance,
    Power,
    None,
    Bsdf,
}

#[derive(Deserialize)]
#[serde(rename_all = "kebab-case")]
enum LightSamplerName {
    Uniform,
    Power,
    Array,
    Ris,
    Bvh,
    RisBvh,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderSection {
    resolution: Option<[u32; 2]>,
    spp: Option<u32>,
    max_depth: Option<u32>,
    seed: Option<u64>,
    mis: Option<MisName>,
    light_sampler: Option<LightSamplerName>,
    ris_candidates: Option<std::num::NonZeroU32>,
}

fn parse_render(src: &Source, value: Item) -> Result<RenderSettings, LoadError> {
    let r: RenderSection = deserialize(src, value)?;
    let mut out = RenderSettings::default();
    if let Some([w, h]) = r.resolution {
        (out.width, out.height) = (w, h);
    }
    out.spp = r.spp.unwrap_or(out.spp);
    out.max_depth = r.max_depth.unwrap_or(out.max_depth);
    out.seed = r.seed.unwrap_or(out.seed);
    if let Some(mis) = r.mis {
        out.mis = match mis {
            MisName::Balance => MisMode::Balance,
            MisName::Power => MisMode::Power,
            MisName::None => MisMode::NeeOnly,
            MisName::Bsdf => MisMode::BsdfOnly,
        };
    }
    if let Some(ls) = r.light_sampler {
        out.light_sampler = match ls {
            LightSamplerName::Uniform => LightSamplerKind::Uniform,
            LightSamplerName::Power => LightSamplerKind::Power,
            LightSamplerName::Array => LightSamplerKind::Array,
            LightSamplerName::Ris => LightSamplerKind::Ris,
            LightSamplerName::Bvh => LightSamplerKind::Bvh,
            LightSamplerName::RisBvh => LightSamplerKind::RisBvh,
        };
    }
    if let Some(n) = r.ris_candidates {
        out.ris_candidates = n.get();
    }
    Ok(out)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DiffuseEntry {
    #[serde(rename = "type")]
    _kind: IgnoredAny,
    albedo: Option<Splat3>,
}

/// Albedo of a diffuse material without one (Mitsuba's default).
const DEFAULT_ALBEDO: f32 = 0.5;

fn parse_materials(src: &Source, value: Item) -> Result<Vec<MaterialDesc>, LoadError> {
    let at = value.span().start;
    let DeValue::Table(table) = value.into_inner() else {
        return Err(src.error(at, "`materials` must be a table of named materials"));
    };
    let mut out = Vec::new();
    for (name, item) in table {
        let span = src.span(name.span().start);
        let bsdf = match item_type(src, "material", &item, &["diffuse"])? {
            "diffuse" => {
                let m: DiffuseEntry = deserialize(src, item)?;
                let albedo = m.albedo.map_or(Vec3::splat(DEFAULT_ALBEDO), |c| c.0);
                BsdfDesc::Diffuse {
                    albedo: TextureDesc::Constant(albedo),
                }
            }
            _ => unreachable!("item_type checked the type"),
        };
        out.push(MaterialDesc {
            name: name.into_inner().into_owned(),
            bsdf,
            span,
        });
    }
    Ok(out)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointLightEntry {
    #[serde(rename = "type")]
    _kind: IgnoredAny,
    position: V3,
    intensity: Splat3,
}

fn parse_light(src: &Source, item: Item) -> Result<LightDesc, LoadError> {
    let span = src.span(item.span().start);
    let kind = match item_type(src, "light", &item, &["point"])? {
        "point" => {
            let l: PointLightEntry = deserialize(src, item)?;
            LightKindDesc::Point {
                position: l.position.vec3(),
                intensity: l.intensity.0,
            }
        }
        _ => unreachable!("item_type checked the type"),
    };
    Ok(LightDesc { kind, span })
}
