//! Radiance from the lights at infinity along a ray that leaves the scene, for the
//! volumetric path tracer (which weights it by its own MIS). The surface path tracer
//! (`path.rs`) looks up the radiance and its MIS density together (`Light::le_pdf`).

use glam::Vec3;

use crate::geometry::Ray;
use crate::light::LightId;
use crate::scene::Scene;

/// Each infinite light that sends radiance along `ray`, with that radiance (never zero).
/// A camera ray (`camera`) sees an environment as its camera-visible image (which may
/// differ from the lighting one, see `Light::le_camera`); later bounces see its `le`.
#[inline]
pub(crate) fn escaped<'a>(
    scene: &'a Scene,
    ray: &'a Ray,
    camera: bool,
) -> impl Iterator<Item = (LightId, Vec3)> + 'a {
    scene.infinite_lights.iter().filter_map(move |&id| {
        let light = scene.light(id);
        let le = if camera {
            light.le_camera(ray)
        } else {
            light.le(ray)
        };
        (le != Vec3::ZERO).then_some((id, le))
    })
}
