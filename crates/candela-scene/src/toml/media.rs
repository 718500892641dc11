//! `[media.NAME]` entries of the TOML format, and the `interior`/`exterior` keys of a
//! `[[shape]]` and `medium` key of `[camera]` that refer to them (documented in
//! `docs/scene-format.md`). The referring keys are taken out of their tables before those
//! are read, so the shape and camera readers need not know them.

use std::path::Path;
use std::sync::Arc;

use candela_core::desc::{MediumDesc, MediumKindDesc, PhaseDesc, VolumeDesc};
use glam::{Mat4, Vec3};
use serde::Deserialize;
use toml::de::DeValue;
use toml::Spanned;

use crate::toml::shape::{compose, TransformOp};
use crate::toml::values::{Num, Splat3};
use crate::toml::{deserialize, Item};
use crate::{LoadError, Source};

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
enum MediumType {
    Homogeneous,
    Grid,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MediumEntry {
    #[serde(rename = "type")]
    kind: MediumType,
    sigma_t: Option<Splat3>,
    albedo: Option<Splat3>,
    sigma_a: Option<Splat3>,
    sigma_s: Option<Splat3>,
    scale: Option<Num>,
    g: Option<Num>,
    file: Option<Spanned<String>>,
    albedo_file: Option<Spanned<String>>,
    transform: Option<Vec<Spanned<TransformOp>>>,
    use_grid_bbox: Option<bool>,
}

/// Mitsuba's defaults: σt 1, albedo 0.75.
const DEFAULT_ALBEDO: f32 = 0.75;

/// Parses the `[media]` table.
pub(crate) fn parse_media(
    src: &Source,
    base: &Path,
    value: Item,
) -> Result<Vec<MediumDesc>, LoadError> {
    let at = value.span().start;
    let DeValue::Table(table) = value.into_inner() else {
        return Err(src.error(at, "`media` must be a table of named media"));
    };
    let mut out = Vec::new();
    for (name, item) in table {
        let at = item.span().start;
        let e: MediumEntry = deserialize(src, item)?;
        let scale = e.scale.map_or(1.0, |s| s.0);
        let phase = match e.g {
            None => PhaseDesc::Isotropic,
            Some(g) => PhaseDesc::HenyeyGreenstein { g: g.0 },
        };
        let kind = match e.kind {
            MediumType::Homogeneous => {
                if let Some(f) = e.file.as_ref().or(e.albedo_file.as_ref()) {
                    return Err(src.error(f.span().start, "a homogeneous medium reads no file"));
                }
                let (sigma_t, albedo) = coefficients(src, at, &e)?;
                MediumKindDesc::Homogeneous {
                    sigma_t: sigma_t * scale,
                    albedo,
                }
            }
            MediumType::Grid => {
                if e.sigma_t.is_some() || e.sigma_a.is_some() || e.sigma_s.is_some() {
                    return Err(src.error(
                        at,
                        "a grid medium's σt is its `file` times `scale`; it takes no \
                         `sigma_t`, `sigma_a` or `sigma_s`",
                    ));
                }
                let Some(file) = &e.file else {
                    return Err(src.error(at, "a grid medium needs a `file` (.vol)"));
                };
                let (grid, box_) = load_grid(src, base, file)?;
                let mut to_world = compose(src, e.transform.unwrap_or_default())?;
                if e.use_grid_bbox.unwrap_or(false) {
                    to_world *= box_;
                }
                let albedo = match (&e.albedo_file, e.albedo) {
                    (Some(f), None) => VolumeDesc::Grid(load_grid(src, base, f)?.0),
                    (Some(f), Some(_)) => {
                        return Err(src.error(
                            f.span().start,
                            "`albedo` and `albedo_file` exclude each other",
                        ))
                    }
                    (None, a) => {
                        VolumeDesc::Constant(a.map_or(Vec3::splat(DEFAULT_ALBEDO), |a| a.0))
                    }
                };
                MediumKindDesc::Grid {
                    sigma_t: grid,
                    albedo,
                    scale,
                    to_world,
                }
            }
        };
        out.push(MediumDesc {
            name: name.get_ref().to_string(),
            kind,
            phase,
            span: src.span(name.span().start),
        });
    }
    Ok(out)
}

/// σt and the albedo of a homogeneous medium: `sigma_t` and `albedo`, or `sigma_a` and
/// `sigma_s`.
fn coefficients(src: &Source, at: usize, e: &MediumEntry) -> Result<(Vec3, Vec3), LoadError> {
    match (e.sigma_a, e.sigma_s) {
        (None, None) => Ok((
            e.sigma_t.map_or(Vec3::ONE, |s| s.0),
            e.albedo.map_or(Vec3::splat(DEFAULT_ALBEDO), |a| a.0),
        )),
        _ if e.sigma_t.is_some() || e.albedo.is_some() => Err(src.error(
            at,
            "give `sigma_t` and `albedo`, or `sigma_a` and `sigma_s`, not both pairs",
        )),
        (a, s) => {
            let (a, s) = (a.map_or(Vec3::ZERO, |v| v.0), s.map_or(Vec3::ZERO, |v| v.0));
            let t = a + s;
            let albedo = Vec3::select(t.cmpgt(Vec3::ZERO), s / t, Vec3::ZERO);
            Ok((t, albedo))
        }
    }
}

/// A `.vol` grid named by a key, and the transform of the unit cube to the box its
/// header declares.
fn load_grid(
    src: &Source,
    base: &Path,
    file: &Spanned<String>,
) -> Result<(Arc<candela_core::desc::GridDesc>, Mat4), LoadError> {
    let path = base.join(file.get_ref());
    let vol = crate::vol::load_vol(&path)
        .map_err(|e| src.error(file.span().start, format!("cannot load grid: {e}")))?;
    let box_ = Mat4::from_translation(vol.bbox_min) * Mat4::from_scale(vol.bbox_max - vol.bbox_min);
    Ok((Arc::new(vol.grid), box_))
}

/// Takes the string keys `keys` out of a table item (before the item is read with
/// `deny_unknown_fields`): each one's value and span.
pub(crate) fn take_keys(
    src: &Source,
    item: &mut Item,
    keys: &[&str],
) -> Result<Vec<Option<(String, usize)>>, LoadError> {
    let DeValue::Table(table) = item.get_mut() else {
        return Ok(vec![None; keys.len()]);
    };
    keys.iter()
        .map(|k| match table.remove(*k) {
            None => Ok(None),
            Some(v) => match v.get_ref().as_str() {
                Some(s) => Ok(Some((s.to_string(), v.span().start))),
                None => Err(src.error(
                    v.span().start,
                    format!(
                        "`{k}` names a medium: a string, found {}",
                        v.get_ref().type_str()
                    ),
                )),
            },
        })
        .collect()
}
