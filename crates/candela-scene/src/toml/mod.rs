//! Candela's TOML scene format (documented in `docs/scene-format.md`): `[render]`,
//! `[camera]`, `[materials.NAME]`, `[[shape]]`, `[[light]]`, `[environment]` and
//! `[[include]]` (glTF files), `[media.NAME]`.
//!
//! The document is first parsed into `toml`'s span-keeping tree ([`DeTable`]); each section
//! is then deserialized on its own with `deny_unknown_fields`, so every error (unknown
//! key, wrong type, bad enum value, wrong array length, non-finite number) points at the
//! offending key or value. Items that take a `type` are dispatched on it first, so a key
//! that belongs to another type is reported as unknown.

mod camera;
mod environment;
mod include;
mod light;
mod material;
mod media;
pub(crate) mod shape;
mod values;

use std::path::Path;

use candela_core::desc::{
    AccelStorage, BsdfDesc, EmissionProfileDesc, FilterSampling, IntegratorKind, LampSampling,
    LightSamplerKind, MaterialDesc, MisMode, RenderSettings, SamplerKind, SceneDesc,
    ShapeMediaDesc,
};
use serde::de::DeserializeOwned;
use serde::Deserialize;
use toml::de::{DeTable, DeValue, ValueDeserializer};
use toml::Spanned;

use crate::{LoadError, Source};
use camera::parse_camera;
use environment::parse_environment;
use include::parse_include;
use light::parse_light;
use material::{parse_material, MATERIAL_TYPES};
use media::{parse_media, take_keys};
use shape::parse_shape;

/// One item of the parsed tree: a value and its byte range in the text.
pub(crate) type Item<'i> = Spanned<DeValue<'i>>;

/// Parses a TOML scene. Relative paths inside (mesh files) resolve against `file`'s
/// folder; `file` is also the name errors are reported under.
pub fn parse_toml_scene(text: &str, file: &Path) -> Result<SceneDesc, LoadError> {
    parse_toml_scene_with_warnings(text, file).map(|(desc, _)| desc)
}

/// [`parse_toml_scene`] with the warnings met on the way (from included glTF files).
pub fn parse_toml_scene_with_warnings(
    text: &str,
    file: &Path,
) -> Result<(SceneDesc, Vec<String>), LoadError> {
    let src = Source::new(file, text);
    let mut warnings = Vec::new();
    let mut includes = 0;
    let root = DeTable::parse(text).map_err(|e| src.toml_error(&e))?;
    let base = file.parent().unwrap_or(Path::new(""));
    let mut desc = SceneDesc::default();
    let mut included_materials = Vec::new();
    let mut mesh_files = Default::default();
    for (key, value) in root.into_inner() {
        let key_at = key.span().start;
        match key.get_ref().as_ref() {
            "render" => desc.render = parse_render(&src, value)?,
            "camera" => {
                let mut value = value;
                let [medium] =
                    <[_; 1]>::try_from(take_keys(&src, &mut value, &["medium"])?).expect("one key");
                if let Some((name, at)) = medium {
                    desc.media.camera = Some(name);
                    desc.media.camera_span = src.span(at);
                }
                desc.camera = parse_camera(&src, base, key_at, value)?
            }
            "media" => desc.media.media = parse_media(&src, base, value)?,
            "materials" => desc.materials = parse_materials(&src, base, value)?,
            "shape" => {
                for mut item in array_of_tables(&src, "shape", value)? {
                    let at = item.span().start;
                    let sides = take_keys(&src, &mut item, &["interior", "exterior"])?;
                    let (shapes, profile) = parse_shape(&src, base, item, &mut mesh_files)?;
                    for shape in shapes {
                        if sides.iter().any(Option::is_some) {
                            desc.media.shapes.push(ShapeMediaDesc {
                                shape: desc.shapes.len(),
                                interior: sides[0].as_ref().map(|s| s.0.clone()),
                                exterior: sides[1].as_ref().map(|s| s.0.clone()),
                                span: src.span(at),
                            });
                        }
                        if let Some((table, span)) = &profile {
                            desc.emission_profiles.push(EmissionProfileDesc {
                                shape: desc.shapes.len(),
                                table: table.clone(),
                                span: span.clone(),
                            });
                        }
                        desc.shapes.push(shape);
                    }
                }
            }
            "environment" => desc.environment = Some(parse_environment(&src, base, key_at, value)?),
            "light" => {
                for item in array_of_tables(&src, "light", value)? {
                    desc.lights.push(parse_light(&src, base, item)?);
                }
            }
            "include" => {
                for item in array_of_tables(&src, "include", value)? {
                    let inc = parse_include(&src, base, item, includes)?;
                    includes += 1;
                    desc.shapes.extend(inc.shapes);
                    included_materials.extend(inc.materials);
                    desc.lights.extend(inc.lights);
                    warnings.extend(inc.warnings);
                }
            }
            other => {
                return Err(src.error(
                    key_at,
                    format!(
                        "unknown key `{other}`, expected one of `render`, `camera`, \
                         `materials`, `shape`, `light`, `environment`, `include`, `media`"
                    ),
                ))
            }
        }
    }
    // After the loop: `[materials]` may come after an `[[include]]` and replaces the list.
    desc.materials.extend(included_materials);
    Ok((desc, warnings))
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
#[serde(deny_unknown_fields)]
struct RenderSection {
    resolution: Option<Spanned<[u32; 2]>>,
    spp: Option<u32>,
    max_depth: Option<u32>,
    rr_depth: Option<u32>,
    seed: Option<u64>,
    mis: Option<MisMode>,
    integrator: Option<IntegratorKind>,
    light_sampler: Option<LightSamplerKind>,
    lamp_sampling: Option<LampSampling>,
    ris_candidates: Option<std::num::NonZeroU32>,
    sampler: Option<SamplerKind>,
    aov: Option<Vec<candela_core::aov::AovKind>>,
    filter_sampling: Option<FilterSampling>,
    accel: Option<AccelStorage>,
}

fn parse_render(src: &Source, value: Item) -> Result<RenderSettings, LoadError> {
    let r: RenderSection = deserialize(src, value)?;
    let mut out = RenderSettings::default();
    if let Some(res) = r.resolution {
        let [w, h] = *res.get_ref();
        candela_core::build::check_resolution(w, h).map_err(|m| src.error(res.span().start, m))?;
        (out.width, out.height) = (w, h);
    }
    out.spp = r.spp.unwrap_or(out.spp);
    out.max_depth = r.max_depth.unwrap_or(out.max_depth);
    out.rr_depth = r.rr_depth.unwrap_or(out.rr_depth);
    out.seed = r.seed.unwrap_or(out.seed);
    out.mis = r.mis.unwrap_or(out.mis);
    out.integrator = r.integrator.unwrap_or(out.integrator);
    out.light_sampler = r.light_sampler.unwrap_or(out.light_sampler);
    out.lamp_sampling = r.lamp_sampling.unwrap_or(out.lamp_sampling);
    if let Some(n) = r.ris_candidates {
        out.ris_candidates = n.get();
    }
    out.sampler = r.sampler.unwrap_or(out.sampler);
    out.aovs = r.aov.into_iter().flatten().collect();
    out.filter_sampling = r.filter_sampling.unwrap_or(out.filter_sampling);
    out.accel = r.accel.unwrap_or(out.accel);
    Ok(out)
}

fn parse_materials(src: &Source, base: &Path, value: Item) -> Result<Vec<MaterialDesc>, LoadError> {
    let at = value.span().start;
    let DeValue::Table(table) = value.into_inner() else {
        return Err(src.error(at, "`materials` must be a table of named materials"));
    };
    let mut entries = Vec::new();
    for (name, item) in table {
        let kind = item_type(src, "material", &item, MATERIAL_TYPES)?;
        entries.push(MaterialEntry {
            name: name.get_ref().to_string(),
            at: name.span().start,
            kind,
            item: Some(item),
            bsdf: None,
        });
    }
    for i in 0..entries.len() {
        parse_entry(src, base, &mut entries, i, 0)?;
    }
    Ok(entries
        .into_iter()
        .map(|e| MaterialDesc {
            span: src.span(e.at),
            name: e.name,
            bsdf: e.bsdf.expect("every entry was parsed"),
        })
        .collect())
}

/// A `[materials.NAME]` entry: its item until it is parsed, then its BSDF.
struct MaterialEntry<'i> {
    name: String,
    at: usize,
    kind: &'static str,
    item: Option<Item<'i>>,
    bsdf: Option<BsdfDesc>,
}

/// How deep mixes may nest (each level is a recursion when the scene is read and at every
/// hit on it).
const MAX_MIX_DEPTH: usize = 16;

/// Parses entry `i` (once), and first the materials it mixes, whatever their order in
/// the file, `depth` mixes down; a mix that contains itself is an error at the name
/// closing the loop.
fn parse_entry(
    src: &Source,
    base: &Path,
    entries: &mut [MaterialEntry],
    i: usize,
    depth: usize,
) -> Result<BsdfDesc, LoadError> {
    if let Some(bsdf) = &entries[i].bsdf {
        return Ok(bsdf.clone());
    }
    let Some(item) = entries[i].item.take() else {
        unreachable!("a mix's loop is caught before its entry is parsed again")
    };
    let kind = entries[i].kind;
    let bsdf = parse_material(src, base, kind, item, &mut |name| {
        let Some(j) = entries.iter().position(|e| e.name == *name.get_ref()) else {
            return Err(src.error(
                name.span().start,
                format!("unknown material \"{}\" in a mix", name.get_ref()),
            ));
        };
        if entries[j].bsdf.is_none() && entries[j].item.is_none() {
            return Err(src.error(
                name.span().start,
                format!("material \"{}\" mixes itself", name.get_ref()),
            ));
        }
        if depth == MAX_MIX_DEPTH {
            return Err(src.error(
                name.span().start,
                format!("mixes nest more than {MAX_MIX_DEPTH} deep here"),
            ));
        }
        parse_entry(src, base, entries, j, depth + 1)
    })?;
    entries[i].bsdf = Some(bsdf.clone());
    Ok(bsdf)
}
