//! Top-level `<emitter>`s. Area emitters live inside shapes (see `shapes.rs`).

use candela_core::desc::{LightDesc, LightKindDesc};
use glam::Vec3;

use super::parse::Node;
use super::{describe, transform, Ctx};
use crate::LoadError;

/// Emitters that Candela will map once the spot, directional and environment work lands.
const PLANNED: &[&str] = &["spot", "directional", "envmap", "constant"];

pub(crate) fn emitter(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    match node.kind() {
        "point" => {
            let from_position = node.point("position")?;
            let from_transform = match node.prop("to_world") {
                Some(t) => Some(transform::transform(t)?.transform_point3(Vec3::ZERO)),
                None => None,
            };
            let position = match (from_position, from_transform) {
                (Some(_), Some(_)) => {
                    return Err(node.error("point emitter: give position or to_world, not both"))
                }
                (p, t) => p.or(t).unwrap_or(Vec3::ZERO),
            };
            let intensity = ctx.color(node, "intensity", Vec3::ONE)?;
            ctx.check_unused(node)?;
            ctx.desc.lights.push(LightDesc {
                kind: LightKindDesc::Point {
                    position,
                    intensity,
                },
                span: node.span.clone(),
            });
            Ok(())
        }
        "area" => Err(node.error("an area emitter must sit inside a <shape>")),
        k if PLANNED.contains(&k) => {
            ctx.unsupported(node, format!("<{}> is not supported yet", describe(node)))
        }
        _ => ctx.unsupported(node, format!("<{}> is not supported", describe(node))),
    }
}
