//! Cameras. In its own frame a camera sits at the origin and looks down −z, with +y up
//! and +x to the right of the image.

use glam::{Vec2, Vec3};

use crate::desc::CameraDesc;
use crate::geometry::Ray;

/// A perspective pinhole camera.
#[derive(Clone, Debug)]
pub struct Camera {
    pub position: Vec3,
    /// Camera-to-world rotation: columns are the camera's right, up and backward axes.
    right: Vec3,
    up: Vec3,
    back: Vec3,
    /// tan(fov_y / 2)
    tan_half_fov: f32,
    resolution: Vec2,
}

impl Camera {
    /// A camera for a film of `width`×`height` pixels. The description must have been
    /// validated (distinct position and target, up not parallel to the view).
    pub fn new(desc: &CameraDesc, width: u32, height: u32) -> Camera {
        let back = (desc.position - desc.look_at).normalize();
        let right = desc.up.cross(back).normalize();
        let up = back.cross(right);
        Camera {
            position: desc.position,
            right,
            up,
            back,
            tan_half_fov: (desc.fov_y_deg.to_radians() * 0.5).tan(),
            resolution: Vec2::new(width as f32, height as f32),
        }
    }

    /// The primary ray through film position `film` (in pixels, (0,0) at the top left).
    pub fn generate_ray(&self, film: Vec2) -> Ray {
        let ndc = film / self.resolution;
        let aspect = self.resolution.x / self.resolution.y;
        let x = (2.0 * ndc.x - 1.0) * self.tan_half_fov * aspect;
        let y = (1.0 - 2.0 * ndc.y) * self.tan_half_fov;
        let d = (self.right * x + self.up * y - self.back).normalize();
        Ray::new(self.position, d)
    }

    /// The camera's viewing direction in world space.
    pub fn forward(&self) -> Vec3 {
        -self.back
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_target_and_corners_span_the_fov() {
        let desc = CameraDesc {
            position: Vec3::new(0.0, 1.0, 5.0),
            look_at: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: 90.0,
            ..Default::default()
        };
        let cam = Camera::new(&desc, 200, 100);
        let c = cam.generate_ray(Vec2::new(100.0, 50.0));
        assert!((c.d - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        // Top edge centre is 45° up; right edge centre is atan(2) to the right (aspect 2).
        let top = cam.generate_ray(Vec2::new(100.0, 0.0));
        assert!((top.d.y - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-5);
        let right = cam.generate_ray(Vec2::new(200.0, 50.0));
        assert!(right.d.x > 0.0 && (right.d.x / -right.d.z - 2.0).abs() < 1e-5);
    }
}
