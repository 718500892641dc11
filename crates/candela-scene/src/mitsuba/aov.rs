//! Mitsuba's `aov` integrator: its `aovs` list (`name:type`, comma-separated) becomes
//! Candela's passes, and the integrator nested in it renders the beauty.
//!
//! Types: `albedo` is Candela's albedo pass; `sh_normal` its normal pass (world-space
//! shading normals, as Mitsuba's); `geo_normal` also maps to it, with a warning; `depth`
//! to its depth pass, with a warning, since Mitsuba's is the distance along the ray (0
//! where nothing is hit) and Candela's along the viewing axis (+∞ where nothing is hit).
//! Candela names the EXR layers itself (`albedo`, `normal`, `depth`), whatever the names
//! in the list. Other types (`uv`, `position`, `prim_index`, …) are refused, or skipped
//! with `--lenient`.

use candela_core::aov::{AovKind, AovSet};

use super::parse::Node;
use super::{sensor, Ctx};
use crate::LoadError;

pub(crate) fn aov_integrator(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    let Some(list) = node.string("aovs")? else {
        return Err(node.error("the aov integrator needs an `aovs` list of NAME:TYPE"));
    };
    let mut set = AovSet::NONE;
    if let Some(prop) = node.prop("aovs") {
        for entry in list.split(',').map(str::trim).filter(|e| !e.is_empty()) {
            let Some((_, kind)) = entry.split_once(':') else {
                return Err(prop.error(format!(
                    "aovs entry \"{entry}\" is not NAME:TYPE (e.g. dd.y:depth)"
                )));
            };
            match kind.trim() {
                "albedo" => set = set.with(AovKind::Albedo),
                "sh_normal" => set = set.with(AovKind::Normal),
                "geo_normal" => {
                    ctx.warn(prop, "geo_normal is written as Candela's shading normals");
                    set = set.with(AovKind::Normal);
                }
                "depth" => {
                    ctx.warn(
                        prop,
                        "depth is written as Candela's: the distance along the viewing \
                         axis, not along the ray",
                    );
                    set = set.with(AovKind::Depth);
                }
                other => ctx.unsupported(
                    prop,
                    format!("AOV type \"{other}\" is not supported (albedo, sh_normal, geo_normal and depth are)"),
                )?,
            }
        }
    }
    ctx.desc.render.aovs = set;
    let nested: Vec<&Node> = node.plugins("integrator").collect();
    match nested.as_slice() {
        // Mitsuba then renders the passes alone; Candela still renders its path tracer.
        [] => {}
        [inner] => sensor::integrator(ctx, inner)?,
        [_, extra, ..] => ctx.unsupported(
            extra,
            "an aov integrator nests one integrator in Candela".into(),
        )?,
    }
    ctx.check_unused(node)
}
