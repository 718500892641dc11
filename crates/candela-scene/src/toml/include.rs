//! `[[include]]` entries of the TOML scene format: a glTF file's shapes, materials and
//! punctual lights placed in the scene by a `transform` (its camera is not used).
//!
//! ```toml
//! [[include]]
//! gltf = "lamp.glb"                  # .gltf or .glb, relative to the scene file
//! scene = 0                          # which glTF scene (default: the file's default)
//! lights = true                      # bring the file's punctual lights (default true)
//! transform = [{ scale = 0.5 }, { translate = [0, 1, 0] }]
//! ```
//!
//! Material names get the prefix `include N:` (N counts the entries from 0), so two
//! includes of one file, or a file and the scene, cannot clash.

use std::path::Path;

use candela_core::desc::{LightDesc, LightKindDesc, MaterialDesc, ShapeDesc};
use glam::Mat4;
use serde::Deserialize;
use toml::Spanned;

use crate::gltf::parse_gltf_scene;
use crate::toml::shape::{check_transform_steps, compose, TransformOp};
use crate::toml::{deserialize, Item};
use crate::{LoadError, LoadOptions, Source};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IncludeEntry {
    gltf: Spanned<String>,
    scene: Option<usize>,
    lights: Option<bool>,
    transform: Option<Vec<Spanned<TransformOp>>>,
}

/// What one include adds to the scene.
pub(crate) struct Included {
    pub shapes: Vec<ShapeDesc>,
    pub materials: Vec<MaterialDesc>,
    pub lights: Vec<LightDesc>,
    pub warnings: Vec<String>,
}

/// Parses the `index`-th `[[include]]` entry and imports its file.
pub(crate) fn parse_include(
    src: &Source,
    base: &Path,
    item: Item,
    index: usize,
) -> Result<Included, LoadError> {
    check_transform_steps(src, &item)?;
    let e: IncludeEntry = deserialize(src, item)?;
    let at = e.gltf.span().start;
    let transform = compose(src, e.transform.unwrap_or_default())?;
    let path = base.join(e.gltf.get_ref());
    let bytes = std::fs::read(&path).map_err(|err| {
        src.error(
            at,
            format!("cannot read glTF file {}: {err}", path.display()),
        )
    })?;
    let options = LoadOptions {
        scene: e.scene,
        ..LoadOptions::default()
    };
    let g = parse_gltf_scene(
        bytes.into(),
        &path,
        Some(path.parent().unwrap_or(Path::new(""))),
        &options,
        &format!("include {index}:"),
    )?;
    let mut shapes = g.shapes;
    for s in &mut shapes {
        s.transform = transform * s.transform;
        s.span = src.span(at);
    }
    let lights = if e.lights.unwrap_or(true) {
        g.lights
            .into_iter()
            .map(|l| place_light(l, transform))
            .collect()
    } else {
        Vec::new()
    };
    Ok(Included {
        shapes,
        materials: g.materials,
        lights,
        warnings: g.warnings,
    })
}

/// A light moved by `m` (positions as points, directions as vectors, renormalized).
fn place_light(mut l: LightDesc, m: Mat4) -> LightDesc {
    let dir = |d: glam::Vec3| m.transform_vector3(d).normalize_or_zero();
    match &mut l.kind {
        LightKindDesc::Point { position, .. } => *position = m.transform_point3(*position),
        LightKindDesc::ShapedPoint(p) => p.position = m.transform_point3(p.position),
        LightKindDesc::Spot(s) => {
            s.position = m.transform_point3(s.position);
            s.direction = dir(s.direction);
        }
        LightKindDesc::Directional(d) => d.direction = dir(d.direction),
        LightKindDesc::Projector(p) => {
            p.position = m.transform_point3(p.position);
            p.direction = dir(p.direction);
            p.up = dir(p.up);
        }
    }
    l
}
