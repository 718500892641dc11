//! A projector: a point light that casts an image through a rectangular frustum.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::{positional, LightBounds, LightFlags, LightSample, LightSource, ShadingCtx};
use crate::desc::ImageDesc;
use crate::geometry::Aabb;
use crate::math::luminance;
use crate::texture::Texture;

/// A point light at `position` whose intensity towards ω is `scale` times the linear
/// value of the image pixel ω passes through, the image spanning the frustum
/// `tan_x` × `tan_y` (tangents of the half fields of view) around `forward`, its top edge
/// towards `up` and its right edge towards `right`. Pixels are looked up nearest (a
/// projector shows its pixels as squares); outside the frustum the intensity is 0.
#[derive(Clone, Debug)]
pub struct ProjectorLight {
    pub position: Vec3,
    pub forward: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    pub tan_x: f32,
    pub tan_y: f32,
    pub image: Arc<ImageDesc>,
    pub scale: Vec3,
    /// Mitsuba's projection (see [`ProjectorLight::with_plane_irradiance`]); `None` for
    /// intensity per pixel.
    pub plane_irradiance: Option<Texture>,
    /// ∫ image(ω) dω per channel (sr).
    image_integral: Vec3,
}

/// Solid angle of the rectangle [0, x] × [0, y] of the plane at distance 1 seen from the
/// origin: atan(xy / √(1 + x² + y²)) (a signed corner term; differences give any
/// rectangle).
fn corner(x: f64, y: f64) -> f64 {
    (x * y / (1.0 + x * x + y * y).sqrt()).atan()
}

impl ProjectorLight {
    /// A projector aimed along `direction`; `up` need only not be parallel to it.
    pub fn new(
        position: Vec3,
        direction: Vec3,
        up: Vec3,
        fov_x_rad: f32,
        fov_y_rad: f32,
        image: Arc<ImageDesc>,
        scale: Vec3,
    ) -> ProjectorLight {
        let forward = direction.normalize();
        let right = forward.cross(up).normalize();
        let mut p = ProjectorLight {
            position,
            forward,
            right,
            up: right.cross(forward),
            tan_x: (0.5 * fov_x_rad).tan(),
            tan_y: (0.5 * fov_y_rad).tan(),
            image,
            scale,
            plane_irradiance: None,
            image_integral: Vec3::ZERO,
        };
        let sum = p
            .pixel_solid_angles()
            .fold(glam::DVec3::ZERO, |acc, (i, o)| {
                acc + p.image.pixels[i].as_dvec3() * o
            });
        p.image_integral = sum.as_vec3();
        p
    }

    /// (pixel index, solid angle of the pixel) for every pixel, exactly.
    fn pixel_solid_angles(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        let (w, h) = (self.image.width as usize, self.image.height as usize);
        let (tx, ty) = (self.tan_x as f64, self.tan_y as f64);
        (0..w * h).map(move |i| {
            let (col, row) = (i % w, i / w);
            let x0 = tx * (2.0 * col as f64 / w as f64 - 1.0);
            let x1 = tx * (2.0 * (col + 1) as f64 / w as f64 - 1.0);
            let y1 = ty * (1.0 - 2.0 * row as f64 / h as f64);
            let y0 = ty * (1.0 - 2.0 * (row + 1) as f64 / h as f64);
            let omega = corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0);
            (i, omega)
        })
    }

    /// The light with Mitsuba's projection: `texture`, read at uv ((x + 1)/2, (y + 1)/2)
    /// for x, y in [−1, 1] across the frustum (right and up), is the irradiance E on the
    /// plane at distance 1, so that I(ω) = π · scale · E / cos³θ; `image` gives only the
    /// power estimate, π · scale × the plane window's area × the mean pixel (exact for a
    /// constant, close for a bilinear texture).
    pub fn with_plane_irradiance(self, texture: Texture) -> ProjectorLight {
        let n = self.image.pixels.len().max(1) as f64;
        let mean = self
            .image
            .pixels
            .iter()
            .fold(glam::DVec3::ZERO, |acc, p| acc + p.as_dvec3())
            / n;
        let area = 4.0 * self.tan_x as f64 * self.tan_y as f64;
        ProjectorLight {
            plane_irradiance: Some(texture),
            image_integral: (mean * area * std::f64::consts::PI).as_vec3(),
            ..self
        }
    }

    /// ∫ image(ω) dω per channel: what turns `scale` into a power per channel.
    pub fn image_integral(&self) -> Vec3 {
        self.image_integral
    }

    /// Where the unit direction `w` leaving the light crosses the frustum: x and y in
    /// [−1, 1] (right and up), and the cosine to the axis; `None` outside it.
    fn frustum_point(&self, w: Vec3) -> Option<(f32, f32, f32)> {
        let z = w.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let x = w.dot(self.right) / (z * self.tan_x);
        let y = w.dot(self.up) / (z * self.tan_y);
        if !(-1.0..=1.0).contains(&x) || !(-1.0..=1.0).contains(&y) {
            return None;
        }
        Some((x, y, z))
    }

    /// The pixel that the unit direction `w` leaving the light passes through.
    pub fn pixel_towards(&self, w: Vec3) -> Option<usize> {
        let (x, y, _) = self.frustum_point(w)?;
        let (wd, ht) = (self.image.width, self.image.height);
        let col = (((x + 1.0) * 0.5 * wd as f32) as u32).min(wd - 1);
        let row = (((1.0 - y) * 0.5 * ht as f32) as u32).min(ht - 1);
        Some((row * wd + col) as usize)
    }

    /// Radiant intensity (W/sr) towards the unit direction `w` leaving the light.
    pub fn intensity_towards(&self, w: Vec3) -> Vec3 {
        match &self.plane_irradiance {
            None => self
                .pixel_towards(w)
                .map_or(Vec3::ZERO, |i| self.scale * self.image.pixels[i]),
            Some(texture) => self.frustum_point(w).map_or(Vec3::ZERO, |(x, y, cos)| {
                let e = texture.eval(Vec2::new(0.5 * (x + 1.0), 0.5 * (y + 1.0)));
                self.scale * e * (std::f32::consts::PI / (cos * cos * cos))
            }),
        }
    }
}

impl LightSource for ProjectorLight {
    const FLAGS: LightFlags = LightFlags::DELTA_POSITION;

    fn sample_li(&self, ctx: &ShadingCtx, _u: Vec2) -> Option<LightSample> {
        positional::sample_li(self.position, ctx, |w| self.intensity_towards(w))
    }

    /// The exact potential contribution: luminance of I(ω)/d² towards `ctx` times the
    /// receiver cosine; exactly 0 where the light is dark towards the point.
    fn importance(&self, ctx: &ShadingCtx) -> f32 {
        positional::importance(self.position, ctx, |w| self.intensity_towards(w))
    }

    /// Emission within the cone through the frustum's corners (θ_o), nothing beyond
    /// (θ_e = 0), at most the brightest pixel (for Mitsuba's projection, times π/cos³
    /// at the corners, where it is largest).
    fn bounds(&self) -> Option<LightBounds> {
        let cos_corner = 1.0 / (1.0 + self.tan_x * self.tan_x + self.tan_y * self.tan_y).sqrt();
        let pixel_peak = self
            .image
            .pixels
            .iter()
            .map(|&c| luminance(self.scale * c))
            .fold(0.0f32, f32::max);
        let peak = match self.plane_irradiance {
            None => pixel_peak,
            Some(_) => pixel_peak * std::f32::consts::PI / cos_corner.powi(3),
        };
        Some(LightBounds {
            aabb: Aabb::from_points(&[self.position]),
            w: self.forward,
            intensity: peak,
            cos_theta_o: cos_corner,
            cos_theta_e: 1.0,
            two_sided: false,
        })
    }

    /// Φ = luminance(scale · ∫ image dω), the pixel solid angles taken exactly.
    fn power(&self) -> f32 {
        luminance(self.scale * self.image_integral)
    }
}
