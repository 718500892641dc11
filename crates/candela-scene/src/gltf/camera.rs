//! glTF cameras, and the automatic camera of models that have none.
//!
//! A glTF camera looks down its node's −z with +y up (the same convention as Candela's).
//! Perspective cameras keep `yfov`; `aspectRatio`, when given, sets the image height
//! from the width. Orthographic cameras view 2·`ymag` high, and `xmag`/`ymag` is the
//! aspect they ask for. The clip planes (`znear`, `zfar`) are not applied.

use candela_core::desc::{CameraDesc, GeometryDesc, ShapeDesc};
use candela_core::geometry::Aabb;
use glam::{Mat4, Vec3};

use super::Ctx;

/// A node's camera and the aspect ratio it asks for.
pub(crate) fn camera(ctx: &Ctx, c: &gltf::Camera, world: Mat4) -> (CameraDesc, Option<f32>) {
    let position = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(-Vec3::Z).normalize_or_zero();
    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
    let desc = CameraDesc {
        position,
        look_at: position + forward,
        up,
        span: ctx.span(),
        ..CameraDesc::default()
    };
    match c.projection() {
        gltf::camera::Projection::Perspective(p) => (
            CameraDesc {
                fov_y_deg: p.yfov().to_degrees(),
                ..desc
            },
            p.aspect_ratio(),
        ),
        gltf::camera::Projection::Orthographic(o) => (
            CameraDesc {
                ortho_height: Some(2.0 * o.ymag()),
                ..desc
            },
            Some(o.xmag() / o.ymag()),
        ),
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
