//! The latitude-longitude (equirectangular) panorama.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{Distribution2D, Image};

/// A panorama in the native mapping of [`super`]: y up, centre along −z.
#[derive(Clone, Debug)]
pub struct Equirect {
    pub image: Image,
    distribution: Distribution2D,
}

/// Image coordinates (u right, v down, both in [0,1]) of a unit direction.
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let u = 0.5 * (1.0 + d.x.atan2(-d.z) / PI);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    Vec2::new(u, v)
}

/// The unit direction at image coordinates `uv`; the inverse of [`direction_to_uv`].
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let phi = PI * (2.0 * uv.x - 1.0);
    let theta = PI * uv.y;
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * sp, ct, -st * cp)
}

impl Equirect {
    /// Builds the sampling distribution: half-texel importance times sin θ, the Jacobian
    /// of the mapping (dω = 2π² sin θ du dv).
    pub fn new(image: Image) -> Equirect {
        let imp = image.half_texel_importance(true, |st| (PI * st.y).sin());
        let distribution = Distribution2D::new(&imp, 2 * image.width, 2 * image.height);
        Equirect {
            image,
            distribution,
        }
    }

    /// Bilinearly filtered radiance towards unit direction `d`.
    pub fn eval(&self, d: Vec3) -> Vec3 {
        self.image.bilinear(direction_to_uv(d), true)
    }

    /// A direction drawn in proportion to the importance, with its solid-angle density.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, f32)> {
        let (uv, pdf_uv) = self.distribution.sample(u);
        let sin_theta = (PI * uv.y).sin();
        if pdf_uv == 0.0 || sin_theta <= 0.0 {
            return None;
        }
        Some((uv_to_direction(uv), pdf_uv / (2.0 * PI * PI * sin_theta)))
    }

    /// Solid-angle density of [`Self::sample`] towards unit direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let uv = direction_to_uv(d);
        let sin_theta = (PI * uv.y).sin();
        if sin_theta <= 0.0 {
            return 0.0;
        }
        self.distribution.pdf(uv) / (2.0 * PI * PI * sin_theta)
    }

    /// ∫ luminance(L) dω, by the midpoint rule over half-texels of the bilinear map.
    pub fn luminance_integral(&self) -> f32 {
        let (w2, h2) = (2 * self.image.width, 2 * self.image.height);
        let mut sum = 0.0f64;
        for qy in 0..h2 {
            let v = (qy as f32 + 0.5) / h2 as f32;
            let mut row = 0.0f64;
            for qx in 0..w2 {
                let uv = Vec2::new((qx as f32 + 0.5) / w2 as f32, v);
                row += crate::math::luminance(self.image.bilinear(uv, true)) as f64;
            }
            sum += row * (PI * v).sin() as f64;
        }
        (sum * 2.0 * (PI as f64).powi(2) / (w2 * h2) as f64) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn native_mapping_puts_minus_z_at_the_centre_and_plus_x_at_three_quarters() {
        let uv = direction_to_uv(-Vec3::Z);
        assert!((uv - Vec2::new(0.5, 0.5)).length() < 1e-6);
        let uv = direction_to_uv(Vec3::X);
        assert!((uv - Vec2::new(0.75, 0.5)).length() < 1e-6);
        let uv = direction_to_uv(-Vec3::X);
        assert!((uv - Vec2::new(0.25, 0.5)).length() < 1e-6);
        assert!(direction_to_uv(Vec3::Y).y.abs() < 1e-6);
        for i in 0..50 {
            let uv = Vec2::new(
                (i as f32 * 0.618).fract(),
                0.02 + 0.96 * (i as f32 * 0.414).fract(),
            );
            let back = direction_to_uv(uv_to_direction(uv));
            let du = (back.x - uv.x).abs();
            let du = du.min(1.0 - du); // u wraps around
            assert!(du < 1e-4 && (back.y - uv.y).abs() < 1e-4, "{uv} -> {back}");
        }
    }
}
