//! Top-level `<emitter>`s. Area emitters live inside shapes (see `shapes.rs`).

use std::f32::consts::PI;

use std::sync::Arc;

use candela_core::desc::{
    DirectionalLightDesc, EnvironmentDesc, EnvironmentMapDesc, ImageDesc, LightAmountDesc,
    LightColorDesc, LightDesc, LightKindDesc, ProjectionDesc, ProjectorLightDesc, SpotFalloff,
    SpotLightDesc, TextureDesc,
};
use glam::{Affine2, Mat3, Mat4, Vec2, Vec3};

use super::parse::Node;
use super::sensor::{field_of_view, vertical_fov};
use super::{describe, transform, Ctx};
use crate::envmap::load_linear_image;
use crate::LoadError;

pub(crate) fn emitter(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    let kind = match node.kind() {
        "point" => {
            let position = placed(node, "position", Vec3::ZERO)?;
            LightKindDesc::Point {
                position,
                intensity: node.illuminant("intensity")?.unwrap_or(Vec3::ONE),
            }
        }
        "spot" => {
            // Mitsuba's spot shines along its local +z, falling off linearly in angle
            // from `beam_width` to `cutoff_angle` (its `spot.cpp`).
            let to_world = to_world(node)?;
            let outer = node.float("cutoff_angle")?.unwrap_or(20.0);
            let inner = node.float("beam_width")?.unwrap_or(outer * 0.75);
            if !(0.0 < inner && inner <= outer && outer <= 180.0) {
                return Err(node.error(format!(
                    "spot needs 0 < beam_width ≤ cutoff_angle ≤ 180, got {inner} and {outer}"
                )));
            }
            LightKindDesc::Spot(SpotLightDesc {
                position: to_world.transform_point3(Vec3::ZERO),
                direction: to_world.transform_vector3(Vec3::Z),
                inner_angle_deg: inner,
                outer_angle_deg: outer,
                falloff: SpotFalloff::Mitsuba,
                color: LightColorDesc::Rgb(node.illuminant("intensity")?.unwrap_or(Vec3::ONE)),
                amount: LightAmountDesc::WattsPerSr(1.0),
                profile: None,
            })
        }
        "directional" => {
            // `direction` is where the light goes; `to_world` sends it along local +z.
            let direction = match (node.point("direction")?, node.prop("to_world")) {
                (Some(_), Some(_)) => {
                    return Err(node.error("directional: give direction or to_world, not both"))
                }
                (Some(d), None) => d,
                (None, _) => to_world(node)?.transform_vector3(Vec3::Z),
            };
            LightKindDesc::Directional(DirectionalLightDesc {
                direction,
                // An irradiance (W/m²) on a surface facing the light, per channel.
                color: LightColorDesc::Rgb(node.illuminant("irradiance")?.unwrap_or(Vec3::ONE)),
                amount: LightAmountDesc::WattsPerSr(1.0),
            })
        }
        "projector" => match projector(ctx, node)? {
            Some(kind) => kind,
            None => return Ok(()),
        },
        "envmap" | "constant" => return environment(ctx, node),
        "area" => return Err(node.error("an area emitter must sit inside a <shape>")),
        _ => return ctx.unsupported(node, format!("<{}> is not supported", describe(node))),
    };
    ctx.check_unused(node)?;
    ctx.desc.lights.push(LightDesc {
        kind,
        span: node.span.clone(),
    });
    Ok(())
}

/// `projector`: Candela's projector in Mitsuba's projection (see
/// [`ProjectionDesc::PlaneIrradiance`]). It looks along its local +z with +y up and the
/// image's right along −x, as Mitsuba's cameras do, and so as Candela's frame (right =
/// forward × up) puts it; `fov` (default a 50 mm lens) spans `fov_axis` of the
/// irradiance texture's aspect. Measured with Mitsuba 3.9.1's `sample_direction`:
/// I(ω) = π · scale · E(uv) / cos³θ, E looked up as its bitmap is (bilinear, `wrap_mode`).
/// `None` where `--lenient` skips it.
fn projector(ctx: &mut Ctx, node: &Node) -> Result<Option<LightKindDesc>, LoadError> {
    let textured = node.is_texture("irradiance");
    let (texture, image) = if textured {
        match ctx.texture(node, "irradiance", Vec3::ONE)? {
            TextureDesc::Image(mut t) => {
                // The importer reads a bitmap at Mitsuba's uvs (v = 0 the top row); the
                // projector reads it with v up, so v is flipped back first.
                let v_up = Affine2::from_cols(Vec2::X, Vec2::NEG_Y, Vec2::Y);
                t.uv_transform *= v_up;
                let image = t.image.clone();
                (TextureDesc::Image(t), image)
            }
            _ => {
                ctx.unsupported(
                    node,
                    "a projector's irradiance must be a bitmap or a colour".into(),
                )?;
                return Ok(None);
            }
        }
    } else {
        let c = node.illuminant("irradiance")?.unwrap_or(Vec3::ONE);
        let image = ImageDesc {
            width: 1,
            height: 1,
            pixels: vec![c],
        };
        (TextureDesc::Constant(c), Arc::new(image))
    };
    let aspect = image.width as f32 / image.height as f32;
    let (fov, axis) = field_of_view(node)?;
    let fov_y = vertical_fov(fov, axis, aspect).ok_or_else(|| {
        node.error(format!(
            "fov_axis \"{axis}\" is not one of x, y, diagonal, smaller, larger"
        ))
    })?;
    let fov_x = 2.0
        * ((0.5 * fov_y).to_radians().tan() * aspect)
            .atan()
            .to_degrees();
    let to_world = to_world(node)?;
    if Mat3::from_mat4(to_world).determinant() < 0.0 {
        return Err(node.error("a projector's to_world must not mirror"));
    }
    Ok(Some(LightKindDesc::Projector(ProjectorLightDesc {
        position: to_world.transform_point3(Vec3::ZERO),
        direction: to_world.transform_vector3(Vec3::Z),
        up: to_world.transform_vector3(Vec3::Y),
        fov_x_deg: fov_x,
        fov_y_deg: fov_y,
        image,
        color: LightColorDesc::Rgb(Vec3::ONE),
        amount: LightAmountDesc::WattsPerSr(node.float("scale")?.unwrap_or(1.0)),
        projection: ProjectionDesc::PlaneIrradiance(texture),
    })))
}

/// `envmap` and `constant`: Candela's environment.
fn environment(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    if ctx.desc.environment.is_some() {
        return Err(node.error("a scene has at most one envmap or constant emitter"));
    }
    let env = if node.kind() == "constant" {
        EnvironmentDesc {
            map: EnvironmentMapDesc::Constant(node.illuminant("radiance")?.unwrap_or(Vec3::ONE)),
            span: node.span.clone(),
            ..EnvironmentDesc::default()
        }
    } else {
        let file = node
            .string("filename")?
            .ok_or_else(|| node.error("an envmap needs a filename"))?;
        let file_node = node.prop("filename").expect("read just now");
        let image = load_linear_image(&ctx.base.join(file))
            .map_err(|e| file_node.error(format!("cannot load \"{file}\": {e}")))?;
        let to_world = Mat3::from_mat4(to_world(node)?);
        if (to_world.determinant() - 1.0).abs() > 1e-3 {
            return Err(node.error("an envmap's to_world must be a rotation"));
        }
        EnvironmentDesc {
            map: EnvironmentMapDesc::Equirect(image),
            strength: node.float("scale")?.unwrap_or(1.0),
            rotation: to_world * mitsuba_envmap_frame(),
            span: node.span.clone(),
            ..EnvironmentDesc::default()
        }
    };
    ctx.check_unused(node)?;
    ctx.desc.environment = Some(env);
    Ok(())
}

/// Candela's equirect map frame as seen from Mitsuba's. Both put the image's v along
/// acos(y); Mitsuba's u is atan2(x, −z)/2π, so −z is the image's left edge, while
/// Candela's u is (1 + atan2(x, −z)/π)/2, with −z at the centre. The image turned by half
/// a turn about y lands where Mitsuba puts it.
pub(crate) fn mitsuba_envmap_frame() -> Mat3 {
    Mat3::from_rotation_y(PI)
}

/// A plugin's `to_world` transform (identity when absent).
fn to_world(node: &Node) -> Result<Mat4, LoadError> {
    match node.prop("to_world") {
        Some(t) if t.tag == "transform" => transform::transform(t),
        Some(t) => Err(t.error("to_world must be a <transform>")),
        None => Ok(Mat4::IDENTITY),
    }
}

/// A position given as the point property `name` or as `to_world`'s origin.
fn placed(node: &Node, name: &str, default: Vec3) -> Result<Vec3, LoadError> {
    match (node.point(name)?, node.prop("to_world")) {
        (Some(_), Some(_)) => Err(node.error(format!("give {name} or to_world, not both"))),
        (Some(p), None) => Ok(p),
        (None, Some(_)) => Ok(to_world(node)?.transform_point3(Vec3::ZERO)),
        (None, None) => Ok(default),
    }
}
