//! glTF cameras, and the automatic camera of models that have none.
//!
//! A glTF camera looks down its node's −z with +y up (the same convention as Candela's).
//! Perspective cameras keep `yfov`; `aspectRatio`, when given, sets the image height
//! from the width. Candela has no orthographic camera, so those are skipped (warned) and
//! the automatic camera is used.

use candela_core::desc::{CameraDesc, GeometryDesc, ShapeDesc};
use candela_core::geometry::Aabb;
use glam::{Mat4, Vec3};

use super::Ctx;

/// A node's camera and the aspect ratio it asks for; `None` for orthographic cameras.
pub(crate) fn camera(
    ctx: &mut Ctx,
    c: &gltf::Camera,
    world: Mat4,
) -> Option<(CameraDesc, Option<f32>)> {
    match c.projection() {
        gltf::camera::Projection::Perspective(p) => {
            let position = world.transform_point3(Vec3::ZERO);
            let forward = world.transform_vector3(-Vec3::Z).normalize_or_zero();
            let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
            Some((
                CameraDesc {
                    position,
                    look_at: position + forward,
                    up,
                    fov_y_deg: p.yfov().to_degrees(),
                    span: ctx.span(),
                    ..CameraDesc::default()
                },
                p.aspect_ratio(),
            ))
        }
        gltf::camera::Projection::Orthographic(_) => {
            ctx.warn(format!(
                "cameras[{}]: orthographic cameras are not supported; skipped",
                c.index()
            ));
            None
        }
    }
}

/// The world-space bounds of the mesh shapes.
pub fn shape_bounds(shapes: &[ShapeDesc]) -> Aabb {
    let mut b = Aabb::EMPTY;
    for s in shapes {
        if let GeometryDesc::Mesh(m) = &s.geometry {
            for &p in &m.positions {
                b = b.grow(s.transform.transform_point3(p));
            }
        }
    }
    b
}

/// A camera framing the shapes' bounding sphere from a three-quarter view: from the front
/// right and above (azimuth 35° from +z towards +x, elevation 25°), far enough that the
/// sphere fills the vertical field of view `fov_y_deg` with a 10% margin.
pub fn framing_camera(shapes: &[ShapeDesc], fov_y_deg: f32) -> CameraDesc {
    let b = shape_bounds(shapes);
    let (center, radius) = if b.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        (b.center(), (0.5 * b.extent().length()).max(1e-3))
    };
    let (az, el) = (35f32.to_radians(), 25f32.to_radians());
    let dir = Vec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos());
    let dist = 1.1 * radius / (0.5 * fov_y_deg.to_radians()).sin();
    CameraDesc {
        position: center + dir * dist,
        look_at: center,
        up: Vec3::Y,
        fov_y_deg,
        ..CameraDesc::default()
    }
}
