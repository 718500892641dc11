//! KHR_lights_punctual: point and spot lights in candela (lm/sr), directional lights in
//! lux (lm/m²), colours linear. The build converts at 683 lm/W with the colour normalized
//! to unit luminance, so 1 cd of white light is 1/683 W/sr per channel. Lights sit at the
//! node's origin and shine down its −z. `range` is ignored (with a warning): physical
//! lights fall off as 1/d² without a cut-off.

use candela_core::desc::{
    DirectionalLightDesc, LightAmountDesc, LightColorDesc, LightDesc, LightKindDesc,
    ShapedPointDesc, SpotFalloff, SpotLightDesc,
};
use glam::{Mat4, Vec3};
use gltf::khr_lights_punctual::Kind;

use super::Ctx;
use crate::LoadError;

/// The light of a node with world transform `world`.
pub(crate) fn light(
    ctx: &mut Ctx,
    l: &gltf::khr_lights_punctual::Light,
    world: Mat4,
) -> Result<LightDesc, LoadError> {
    let path = format!("KHR_lights_punctual.lights[{}]", l.index());
    if l.range().is_some() {
        ctx.warn(format!(
            "{path}: range is ignored (lights fall off as 1/d²)"
        ));
    }
    let color = LightColorDesc::Rgb(Vec3::from(l.color()));
    let amount = LightAmountDesc::Candela(l.intensity());
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(-Vec3::Z).normalize_or_zero();
    if direction == Vec3::ZERO && !matches!(l.kind(), Kind::Point) {
        return Err(ctx.error(
            &path,
            "the node's transform collapses the light's direction",
        ));
    }
    let kind = match l.kind() {
        Kind::Point => LightKindDesc::ShapedPoint(ShapedPointDesc {
            position,
            color,
            amount,
            profile: None,
        }),
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => LightKindDesc::Spot(SpotLightDesc {
            position,
            direction,
            inner_angle_deg: inner_cone_angle.to_degrees(),
            outer_angle_deg: outer_cone_angle.to_degrees(),
            falloff: SpotFalloff::Gltf,
            color,
            amount,
            profile: None,
        }),
        Kind::Directional => LightKindDesc::Directional(DirectionalLightDesc {
            direction,
            color,
            amount,
        }),
    };
    Ok(LightDesc {
        kind,
        span: ctx.span(),
    })
}
