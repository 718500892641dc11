//! The thin lens of the course notes (and pbrt-v3 §6.2.3): a ray starts from a random
//! point on the aperture and passes through the point where the pinhole ray through the
//! same film position meets the plane of focus. The plane of focus is the pinhole's image
//! plane scaled to the focus distance, so the field of view does not change with focus.
//!
//! Image-side the model matches a real thin lens of focal length f focused at distance F:
//! a point at depth z blurs into a circle of confusion whose diameter, as a fraction of
//! the image height, is A·|z − F| / (z·F·tan(fov/2)) for aperture radius A — the same as
//! the photographic c = 2A·|z − F|/z · f/(F − f) over the sensor height.

use glam::{Vec2, Vec3, Vec3A};

use super::aperture::Aperture;
use crate::desc::{ApertureSizeDesc, CameraDesc, FocusDesc, LensDesc};

/// Millimetres per scene unit when an f-number sets the aperture: scene units are metres.
const MM_PER_SCENE_UNIT: f32 = 1000.0;

/// A thin lens in the camera's frame: the lens lies in the z = 0 plane, centred on the
/// camera position; the plane of focus is z = −`focus_distance`.
#[derive(Clone, Debug)]
pub struct ThinLens {
    /// Radius of the aperture circle, in scene units.
    pub aperture_radius: f32,
    /// Distance from the lens to the plane of focus along the view axis.
    pub focus_distance: f32,
    pub aperture: Aperture,
}

impl ThinLens {
    /// The lens of a validated camera description.
    pub fn new(camera: &CameraDesc, lens: &LensDesc) -> ThinLens {
        let forward = (camera.look_at - camera.position).normalize();
        let focus_distance = match lens.focus {
            FocusDesc::LookAt => (camera.look_at - camera.position).dot(forward),
            FocusDesc::Distance(d) => d,
            FocusDesc::Point(p) => (p - camera.position).dot(forward),
        };
        let aperture_radius = match lens.size {
            ApertureSizeDesc::Radius(r) => r,
            ApertureSizeDesc::FNumber(n) => {
                camera.focal_length_mm() / (2.0 * n) / MM_PER_SCENE_UNIT
            }
        };
        ThinLens {
            aperture_radius,
            focus_distance,
            aperture: Aperture::new(&lens.aperture),
        }
    }

    /// A point on the lens (camera frame, z = 0) from a uniform `u`.
    pub fn sample_point(&self, u: Vec2) -> Vec2 {
        self.aperture_radius * self.aperture.sample(u)
    }

    /// The ray, in the camera frame, from the lens point of `u` through the point where
    /// the pinhole direction `d_pinhole` (with z = −1) meets the plane of focus.
    pub fn ray(&self, d_pinhole: Vec3, u: Vec2) -> (Vec3, Vec3) {
        let focus = Vec3A::from(d_pinhole) * self.focus_distance;
        let lens = self.sample_point(u).extend(0.0);
        (lens, super::normalize(focus - Vec3A::from(lens)).into())
    }

    /// Where the line from lens point `lens` through `p` (camera frame, in front of the
    /// lens) meets the plane of focus.
    pub fn focus_point(&self, p: Vec3, lens: Vec2) -> Option<Vec3> {
        let depth = -p.z;
        if depth <= 0.0 {
            return None;
        }
        let lens = lens.extend(0.0);
        Some(lens + (p - lens) * (self.focus_distance / depth))
    }
}
