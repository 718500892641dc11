//! Cameras. In its own frame a camera sits at the origin and looks down −z, with +y up
//! and +x to the right of the image. A camera is a pinhole, a pinhole with a
//! [`ThinLens`] for depth of field, or orthographic (parallel rays).

mod aperture;
mod thin_lens;

pub use aperture::{Aperture, ImageAperture, PolygonAperture};
pub use thin_lens::ThinLens;

use glam::{Vec2, Vec3, Vec3A};

use crate::desc::CameraDesc;
use crate::geometry::Ray;

impl CameraDesc {
    /// The vertical field of view in degrees: from the focal length and the sensor height
    /// when a focal length is given, else `fov_y_deg`.
    pub fn vertical_fov_deg(&self) -> f32 {
        match self.focal_length_mm {
            Some(f) => (2.0 * (0.5 * self.sensor_mm.y / f).atan()).to_degrees(),
            None => self.fov_y_deg,
        }
    }

    /// The focal length in millimetres: as given, or the one that gives `fov_y_deg` on
    /// the sensor (36×24 mm full frame by default, so 24 mm high).
    pub fn focal_length_mm(&self) -> f32 {
        match self.focal_length_mm {
            Some(f) => f,
            None => 0.5 * self.sensor_mm.y / (0.5 * self.fov_y_deg.to_radians()).tan(),
        }
    }
}

/// A perspective camera, a pinhole or a thin lens when `lens` is set, or an orthographic
/// one.
#[derive(Clone, Debug)]
pub struct Camera {
    pub position: Vec3,
    /// Camera-to-world rotation: columns are the camera's right, up and backward axes
    /// (each in one SSE register: the rotation is three multiplies and two adds).
    right: Vec3A,
    up: Vec3A,
    back: Vec3A,
    /// tan(fov_y / 2)
    tan_half_fov: f32,
    resolution: Vec2,
    lens: Option<ThinLens>,
    /// Half the view height of an orthographic camera.
    ortho_half_height: Option<f32>,
}

impl Camera {
    /// A camera for a film of `width`×`height` pixels. The description must have been
    /// validated (distinct position and target, up not parallel to the view, a lens with
    /// positive focus distance and a usable aperture). A lens of radius 0 is a pinhole.
    pub fn new(desc: &CameraDesc, width: u32, height: u32) -> Camera {
        let back = (desc.position - desc.look_at).normalize();
        let right = desc.up.cross(back).normalize();
        let up = back.cross(right);
        let lens = desc
            .lens
            .as_ref()
            .map(|l| ThinLens::new(desc, l))
            .filter(|l| l.aperture_radius > 0.0);
        Camera {
            position: desc.position,
            right: right.into(),
            up: up.into(),
            back: back.into(),
            tan_half_fov: (desc.vertical_fov_deg().to_radians() * 0.5).tan(),
            resolution: Vec2::new(width as f32, height as f32),
            lens,
            ortho_half_height: desc.ortho_height.map(|h| 0.5 * h),
        }
    }

    /// The thin lens, if the camera has one.
    pub fn lens(&self) -> Option<&ThinLens> {
        self.lens.as_ref()
    }

    /// Whether [`Self::generate_lens_ray`] uses its lens sample; a pinhole does not, so
    /// the integrator takes no lens dimensions for it.
    pub fn needs_lens_sample(&self) -> bool {
        self.lens.is_some()
    }

    /// The film position as x, y in [−1, 1]², +y up, and the image's aspect ratio.
    #[inline]
    fn screen(&self, film: Vec2) -> (Vec2, f32) {
        let ndc = film / self.resolution;
        let aspect = self.resolution.x / self.resolution.y;
        (Vec2::new(2.0 * ndc.x - 1.0, 1.0 - 2.0 * ndc.y), aspect)
    }

    /// Direction (camera frame, z = −1) of the pinhole ray through film position `film`.
    #[inline]
    fn pinhole_direction(&self, film: Vec2) -> Vec3 {
        let (s, aspect) = self.screen(film);
        Vec3::new(
            s.x * self.tan_half_fov * aspect,
            s.y * self.tan_half_fov,
            -1.0,
        )
    }

    /// A camera-frame vector in the world frame: lane by lane the operations of
    /// `right·x + up·y + back·z` in `Vec3`, so the same bits.
    #[inline]
    fn to_world(&self, v: Vec3) -> Vec3A {
        self.right * v.x + self.up * v.y + self.back * v.z
    }

    /// The ray through film position `film` (in pixels, (0,0) at the top left) from the
    /// centre of the lens: the pinhole ray.
    #[inline]
    pub fn generate_ray(&self, film: Vec2) -> Ray {
        if let Some(h) = self.ortho_half_height {
            return self.orthographic_ray(h, film);
        }
        let d = normalize(self.to_world(self.pinhole_direction(film)));
        Ray::new(self.position, d.into())
    }

    /// The orthographic ray through film position `film`: from the camera's plane, along
    /// the view direction.
    #[inline(never)]
    fn orthographic_ray(&self, half_height: f32, film: Vec2) -> Ray {
        let (s, aspect) = self.screen(film);
        let o = Vec3::new(s.x * half_height * aspect, s.y * half_height, 0.0);
        Ray::new(self.position + Vec3::from(self.to_world(o)), self.forward())
    }

    /// The ray through film position `film` from the lens point of the uniform sample
    /// `lens_u`; a pinhole ignores `lens_u`. Inlined for a pinhole (into each copy of the
    /// render loop, see [`crate::isa`]), a thin lens out of line.
    #[inline]
    pub fn generate_lens_ray(&self, film: Vec2, lens_u: Vec2) -> Ray {
        match &self.lens {
            None => self.generate_ray(film),
            Some(lens) => self.thin_lens_ray(lens, film, lens_u),
        }
    }

    /// [`Self::generate_lens_ray`] through a thin lens.
    #[inline(never)]
    fn thin_lens_ray(&self, lens: &ThinLens, film: Vec2, lens_u: Vec2) -> Ray {
        let (o, d) = lens.ray(self.pinhole_direction(film), lens_u);
        Ray::new(
            self.position + Vec3::from(self.to_world(o)),
            normalize(self.to_world(d)).into(),
        )
    }

    /// The film position (pixels) whose ray from lens sample `lens_u` passes through the
    /// world point `p`; `None` when `p` is not in front of the lens. The inverse of
    /// [`Self::generate_lens_ray`], for tests and for tracing from lights.
    pub fn project(&self, p: Vec3, lens_u: Vec2) -> Option<Vec2> {
        let v = p - self.position;
        let axis = |a: Vec3A| v.dot(a.into());
        let pc = Vec3::new(axis(self.right), axis(self.up), axis(self.back));
        // The point on the plane at distance 1 (perspective) or on the camera's plane
        // (orthographic), and that plane's half height.
        let (x, y, half_height) = if let Some(h) = self.ortho_half_height {
            if pc.z >= 0.0 {
                return None;
            }
            (pc.x, pc.y, h)
        } else {
            let on_focus = match &self.lens {
                Some(lens) => lens.focus_point(pc, lens.sample_point(lens_u))?,
                None if pc.z < 0.0 => pc / -pc.z,
                None => return None,
            };
            let z = -on_focus.z;
            (on_focus.x / z, on_focus.y / z, self.tan_half_fov)
        };
        let aspect = self.resolution.x / self.resolution.y;
        let ndc = Vec2::new(
            0.5 * (x / (half_height * aspect) + 1.0),
            0.5 * (1.0 - y / half_height),
        );
        Some(ndc * self.resolution)
    }

    /// The camera's viewing direction in world space.
    pub fn forward(&self) -> Vec3 {
        -Vec3::from(self.back)
    }
}

/// `Vec3::normalize` in one SSE register: v · (1 / √(v·v)), the same operations in the
/// same order (x² + y², then + z²), so the same bits.
#[inline]
pub(crate) fn normalize(v: Vec3A) -> Vec3A {
    v * (1.0 / v.dot(v).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::desc::{ApertureSizeDesc, FocusDesc, LensDesc};

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

    #[test]
    fn orthographic_rays_are_parallel_and_span_the_view() {
        let desc = CameraDesc {
            position: Vec3::new(1.0, 2.0, 3.0),
            look_at: Vec3::new(1.0, 2.0, -7.0),
            up: Vec3::Y,
            ortho_height: Some(4.0),
            ..Default::default()
        };
        let cam = Camera::new(&desc, 200, 100);
        for (film, origin) in [
            (Vec2::new(100.0, 50.0), Vec3::new(1.0, 2.0, 3.0)),
            // Top edge: 2 up; right edge: 4 right (aspect 2); the top-left corner.
            (Vec2::new(100.0, 0.0), Vec3::new(1.0, 4.0, 3.0)),
            (Vec2::new(200.0, 50.0), Vec3::new(5.0, 2.0, 3.0)),
            (Vec2::new(0.0, 0.0), Vec3::new(-3.0, 4.0, 3.0)),
        ] {
            let r = cam.generate_lens_ray(film, Vec2::new(0.3, 0.7));
            assert!((r.o - origin).length() < 1e-5, "{film}: {}", r.o);
            assert!((r.d - Vec3::NEG_Z).length() < 1e-6, "{film}: {}", r.d);
            // Projecting any point of the ray lands on the same film position.
            let p = cam.project(r.o + 3.5 * r.d, Vec2::ZERO).unwrap();
            assert!((p - film).length() < 1e-3, "{film}: {p}");
        }
        assert!(!cam.needs_lens_sample());
        assert_eq!(cam.project(Vec3::new(1.0, 2.0, 4.0), Vec2::ZERO), None);
    }

    #[test]
    fn focal_length_and_fov_agree_on_a_full_frame_sensor() {
        // A 50 mm lens on a 24 mm high sensor: fov = 2·atan(12/50) = 26.99°.
        let desc = CameraDesc {
            focal_length_mm: Some(50.0),
            ..Default::default()
        };
        assert!((desc.vertical_fov_deg() - 26.9915).abs() < 1e-3);
        let back = CameraDesc {
            fov_y_deg: desc.vertical_fov_deg(),
            ..Default::default()
        };
        assert!((back.focal_length_mm() - 50.0).abs() < 1e-3);
    }

    #[test]
    fn f_number_sets_radius_and_focus_point_sets_distance() {
        let desc = CameraDesc {
            position: Vec3::ZERO,
            look_at: Vec3::new(0.0, 0.0, -1.0),
            focal_length_mm: Some(50.0),
            lens: Some(LensDesc {
                focus: FocusDesc::Point(Vec3::new(3.0, 1.0, -4.0)),
                size: ApertureSizeDesc::FNumber(2.0),
                ..Default::default()
            }),
            ..Default::default()
        };
        let cam = Camera::new(&desc, 64, 64);
        let lens = cam.lens().unwrap();
        assert!((lens.aperture_radius - 0.0125).abs() < 1e-7); // 50 mm / (2·2) in metres
        assert!((lens.focus_distance - 4.0).abs() < 1e-6); // along the view axis only
    }
}
