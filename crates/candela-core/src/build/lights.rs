//! Build arms of the lights with units, colours and profiles (points, spots, directional
//! and projector lights): validation and unit conversion.
//!
//! **Units.** A light's RGB scale comes from its colour `c` (linear Rec.709, or a
//! blackbody temperature normalized to luminance 1) and its amount:
//! - W/sr (or W/m² for directional lights): `c` · value;
//! - cd (or lux): `c`/Y(`c`) · value / 683, Y the luminance (683 lm/W at 555 nm);
//! - W: `c` · value / Ω; lm: `c`/Y(`c`) · value / 683 / Ω, where Ω = ∫ shape dω is the
//!   solid angle of the light's relative intensity (4π for a point, the falloff integral
//!   for a spot, ∫ I/I_max dω for a profile, the image integral for a projector), so that
//!   the emitted power is the value;
//! - the profile's own candela: `c`/Y(`c`) · I_max / 683.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::{build_texture, check_color, check_finite, check_image, err, BuildError};
use crate::desc::{
    GeometryDesc, LightAmountDesc, LightColorDesc, LightDesc, LightKindDesc, ProfileDesc,
    ProjectionDesc, SceneDesc, Span,
};
use crate::light::blackbody::blackbody_rgb;
use crate::light::{
    DirectionalLight, EmissionTexture, GoniometricLight, Light, LightId, LightProfile,
    ParallelogramLight, PointLight, ProjectorLight, SpotLight, TriangleLight,
};
use crate::math::luminance;
use crate::scene::Mesh;
use crate::texture::Texture;

/// Lumens per watt at 555 nm, the definition of the candela.
pub const LUMENS_PER_WATT: f32 = 683.0;

/// The light's colour as linear RGB.
fn color_rgb(span: &Span, c: LightColorDesc) -> Result<Vec3, BuildError> {
    match c {
        LightColorDesc::Rgb(rgb) => {
            check_color(span, "color", rgb)?;
            Ok(rgb)
        }
        LightColorDesc::Temperature(k) => blackbody_rgb(k).ok_or_else(|| BuildError {
            span: span.clone(),
            message: format!("temperature {k} K must be positive"),
        }),
    }
}

/// The RGB scale of a light (see the module docs); `omega` is the light's solid angle and
/// `peak` the profile's I_max in cd, where it has a profile.
fn scale(
    span: &Span,
    color: LightColorDesc,
    amount: LightAmountDesc,
    omega: f32,
    peak: Option<f32>,
) -> Result<Vec3, BuildError> {
    let c = color_rgb(span, color)?;
    let value = match amount {
        LightAmountDesc::WattsPerSr(v)
        | LightAmountDesc::Candela(v)
        | LightAmountDesc::Watts(v)
        | LightAmountDesc::Lumens(v) => v,
        LightAmountDesc::ProfileCandela => 1.0,
    };
    check_finite(span, "light amount", &[value])?;
    if value < 0.0 {
        return err(span, format!("light amount {value} must not be negative"));
    }
    let photometric = || {
        let y = luminance(c);
        if y > 0.0 {
            Ok(c / y / LUMENS_PER_WATT)
        } else {
            err(
                span,
                "a photometric amount needs a colour with non-zero luminance",
            )
        }
    };
    let per_sr = |total: f32| {
        if omega > 0.0 {
            Ok(total / omega)
        } else {
            err(
                span,
                "a power needs a light that emits into a non-zero solid angle",
            )
        }
    };
    Ok(match amount {
        LightAmountDesc::WattsPerSr(v) => c * v,
        LightAmountDesc::Candela(v) => photometric()? * v,
        LightAmountDesc::Watts(v) => c * per_sr(v)?,
        LightAmountDesc::Lumens(v) => photometric()? * per_sr(v)?,
        LightAmountDesc::ProfileCandela => match peak {
            Some(peak) => photometric()? * peak,
            None => {
                return err(
                    span,
                    "only a light with an IES profile can take its intensity from it",
                )
            }
        },
    })
}

fn check_angle(span: &Span, what: &str, deg: f32, lo: f32, hi: f32) -> Result<(), BuildError> {
    check_finite(span, what, &[deg])?;
    if !(lo..=hi).contains(&deg) {
        return err(span, format!("{what} {deg}° must lie within {lo}–{hi}°"));
    }
    Ok(())
}

fn check_direction(span: &Span, what: &str, d: Vec3) -> Result<Vec3, BuildError> {
    check_finite(span, what, &d.to_array())?;
    let n = d.normalize_or_zero();
    if n == Vec3::ZERO {
        return err(span, format!("{what} must not be zero"));
    }
    Ok(n)
}

fn build_profile(p: &ProfileDesc) -> Result<LightProfile, BuildError> {
    let nadir = check_direction(&p.span, "profile direction", p.nadir)?;
    check_finite(&p.span, "profile C0 direction", &p.c0.to_array())?;
    LightProfile::new(p.table.clone(), nadir, p.c0)
        .map_or_else(|| err(&p.span, "the IES profile is dark everywhere"), Ok)
}

/// Builds one light of the description. Directional lights get a scene radius of 1 here;
/// the caller sets the real one once the scene's bounds are known.
pub(super) fn build_light(l: &LightDesc) -> Result<Light, BuildError> {
    let span = &l.span;
    Ok(match &l.kind {
        LightKindDesc::Point {
            position,
            intensity,
        } => {
            check_finite(span, "position", &position.to_array())?;
            check_color(span, "intensity", *intensity)?;
            Light::Point(PointLight {
                position: *position,
                intensity: *intensity,
            })
        }
        LightKindDesc::ShapedPoint(p) => {
            check_finite(span, "position", &p.position.to_array())?;
            match &p.profile {
                None => Light::Point(PointLight {
                    position: p.position,
                    intensity: scale(span, p.color, p.amount, 4.0 * PI, None)?,
                }),
                Some(pd) => {
                    let profile = build_profile(pd)?;
                    let intensity = scale(
                        span,
                        p.color,
                        p.amount,
                        profile.solid_angle(),
                        Some(profile.max_intensity()),
                    )?;
                    Light::Goniometric(GoniometricLight {
                        position: p.position,
                        intensity,
                        profile,
                    })
                }
            }
        }
        LightKindDesc::Spot(s) => {
            check_finite(span, "position", &s.position.to_array())?;
            let direction = check_direction(span, "direction", s.direction)?;
            check_angle(span, "outer_angle", s.outer_angle_deg, 0.0, 180.0)?;
            check_angle(
                span,
                "inner_angle",
                s.inner_angle_deg,
                0.0,
                s.outer_angle_deg,
            )?;
            if s.outer_angle_deg == 0.0 {
                return err(span, "outer_angle must be positive");
            }
            let profile = match &s.profile {
                Some(pd) => Some(build_profile(&ProfileDesc {
                    nadir: direction,
                    ..pd.clone()
                })?),
                None => None,
            };
            let peak = profile.as_ref().map(LightProfile::max_intensity);
            let spot = SpotLight::new(
                s.position,
                direction,
                s.inner_angle_deg.to_radians(),
                s.outer_angle_deg.to_radians(),
                s.falloff,
                Vec3::ONE,
                profile,
            );
            let mut spot = spot;
            spot.intensity = scale(span, s.color, s.amount, spot.solid_angle(), peak)?;
            Light::Spot(spot)
        }
        LightKindDesc::Directional(d) => {
            let direction = check_direction(span, "direction", d.direction)?;
            if matches!(
                d.amount,
                LightAmountDesc::Watts(_)
                    | LightAmountDesc::Lumens(_)
                    | LightAmountDesc::ProfileCandela
            ) {
                return err(
                    span,
                    "a directional light takes an irradiance (W/m²) or an illuminance (lux)",
                );
            }
            Light::Directional(DirectionalLight {
                direction,
                irradiance: scale(span, d.color, d.amount, 1.0, None)?,
                scene_radius: 1.0,
            })
        }
        LightKindDesc::Projector(p) => {
            check_finite(span, "position", &p.position.to_array())?;
            let direction = check_direction(span, "direction", p.direction)?;
            let up = check_direction(span, "up", p.up)?;
            if direction.cross(up).length_squared() < 1e-10 {
                return err(span, "projector `up` is parallel to its direction");
            }
            for (what, fov) in [("fov_x", p.fov_x_deg), ("fov_y", p.fov_y_deg)] {
                check_finite(span, what, &[fov])?;
                if !(fov > 0.0 && fov < 180.0) {
                    return err(
                        span,
                        format!("{what} {fov} must lie strictly between 0 and 180 degrees"),
                    );
                }
            }
            let img = &p.image;
            check_image(span, "projector image", img)?;
            let mut proj = ProjectorLight::new(
                p.position,
                direction,
                up,
                p.fov_x_deg.to_radians(),
                p.fov_y_deg.to_radians(),
                img.clone(),
                Vec3::ONE,
            );
            if let ProjectionDesc::PlaneIrradiance(t) = &p.projection {
                proj = proj.with_plane_irradiance(build_texture(t, span, "projector irradiance")?);
            }
            let omega = luminance(proj.image_integral());
            proj.scale = scale(span, p.color, p.amount, omega, None)?;
            Light::Projector(proj)
        }
    })
}

/// Checks that every IES profile of the description is attached to an emitting shape
/// that is not a sphere.
pub(super) fn check_emission_profiles(desc: &SceneDesc) -> Result<(), BuildError> {
    for p in &desc.emission_profiles {
        let Some(shape) = desc.shapes.get(p.shape) else {
            return err(
                &p.span,
                format!(
                    "IES profile refers to shape {} of {}",
                    p.shape,
                    desc.shapes.len()
                ),
            );
        };
        if shape.emission.is_none() {
            return err(
                &p.span,
                "an IES profile needs an emitting shape (`emission`)",
            );
        }
        if matches!(shape.geometry, GeometryDesc::Sphere { .. }) {
            return err(&p.span, "IES profiles are not supported on spheres");
        }
    }
    Ok(())
}

/// One light per triangle of the world-space `mesh` of shape `shape_index` (one per
/// quad where two consecutive unshaped, untextured triangles tile a parallelogram),
/// emitting `le` times `texture` at the mesh's uvs, shaped by the shape's IES profile if
/// it has one (nadir along each triangle's normal, C0 along the shape's transformed
/// local +x).
pub(super) fn triangle_lights(
    desc: &SceneDesc,
    shape_index: usize,
    mesh: &mut Mesh,
    le: Vec3,
    texture: Option<&Arc<Texture>>,
    lights: &mut Vec<Light>,
) {
    let floor = texture.map(|t| t.mean());
    let table = desc
        .emission_profiles
        .iter()
        .find(|p| p.shape == shape_index)
        .map(|p| p.table.clone());
    let c0 = desc.shapes[shape_index]
        .transform
        .transform_vector3(Vec3::X);
    // (normal, profile, projected solid angle) of the last triangle: flat shapes repeat
    // them, and the projected solid angle is a quadrature worth reusing.
    let mut last: Option<(Vec3, LightProfile, f32)> = None;
    let count = mesh.indices.len() as u32;
    let mut tri = 0;
    while tri < count {
        let n = mesh.geometric_normal(tri);
        let mut light = TriangleLight::new(mesh.vertices(tri), n, le);
        // A quad's two triangles (consecutive, as loaders triangulate quads) become one
        // parallelogram light, whose 2D samples are stratified over the whole quad.
        if let (Some(t), Some(floor)) = (texture, floor) {
            // The corners' uvs as `Mesh::uv_at` interpolates them (barycentrics where the
            // mesh has none).
            let uv = [Vec2::ZERO, Vec2::X, Vec2::Y].map(|b| mesh.uv_at(tri, b));
            light = light.with_texture(EmissionTexture::new(t.clone(), uv, le, floor));
        }
        if table.is_none() && texture.is_none() && tri + 1 < count {
            let next =
                TriangleLight::new(mesh.vertices(tri + 1), mesh.geometric_normal(tri + 1), le);
            if let Some(quad) = ParallelogramLight::from_triangles(&light, &next) {
                let id = LightId(lights.len() as u32);
                mesh.lights.extend([id, id]);
                lights.push(Light::Parallelogram(quad));
                tri += 2;
                continue;
            }
        }
        mesh.lights.push(LightId(lights.len() as u32));
        if let Some(table) = &table {
            if last.as_ref().is_none_or(|(ln, _, _)| *ln != n) {
                last = LightProfile::new(table.clone(), n, c0).map(|p| {
                    let projected = p.projected_solid_angle();
                    (n, p, projected)
                });
            }
            if let Some((_, p, projected)) = &last {
                light = light.with_profile(p.clone(), *projected);
            }
        }
        lights.push(Light::Triangle(light));
        tri += 1;
    }
}
