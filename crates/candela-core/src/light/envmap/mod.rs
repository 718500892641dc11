//! Environment maps: radiance by direction, looked up with bilinear filtering, and the
//! distributions that sample them in proportion to what the lookup returns.
//!
//! Two forms, each in its own native frame (the [`super::EnvironmentLight`] rotates):
//!
//! - [`Equirect`]: y up, the panorama's centre along −z,
//!   `u = (1 + atan2(d.x, −d.z)/π)/2`, `v = acos(d.y)/π` (u to the right, v down the image).
//!   So −z is at u = ½, +x at u = ¾, −x at u = ¼, +z at the left and right edges.
//! - [`Cubemap`]: six square faces in the order +x, −x, +y, −y, +z, −z, with the OpenGL /
//!   Direct3D face table (see [`cubemap`]).
//!
//! [`Equirect`] samples a bilinear density through the texel centres, so that the
//! density follows the filtered radiance within every texel ([`bilinear`], as Mitsuba 3's
//! `envmap`). [`Cubemap`] samples a piecewise-constant 2D distribution on a grid of
//! half-texels (2W × 2H cells): over each half-texel cell the bilinear lookup blends
//! exactly one 2×2 neighbourhood of texels, and the cell's weight is the maximum of those
//! four texels. Either way the density is positive wherever the filtered radiance is.

pub mod bilinear;
pub mod cubemap;
pub mod equirect;

pub use cubemap::Cubemap;
pub use equirect::Equirect;

use glam::{Vec2, Vec3};

use crate::desc::ImageDesc;
use crate::math::luminance;
use crate::sampling::{Distribution1D, ONE_MINUS_EPSILON};

/// A direction drawn from an environment map: its solid-angle density and the radiance
/// arriving along it (in the map's frame, strength not applied).
#[derive(Clone, Copy, Debug)]
pub struct MapSample {
    pub dir: Vec3,
    pub pdf: f32,
    pub radiance: Vec3,
}

/// A linear RGB image, row-major, top row first.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<Vec3>,
}

impl Image {
    pub fn from_desc(d: &ImageDesc) -> Image {
        Image {
            width: d.width as usize,
            height: d.height as usize,
            pixels: d.pixels.clone(),
        }
    }

    fn texel(&self, x: isize, y: isize, wrap_x: bool) -> Vec3 {
        let w = self.width as isize;
        let x = if wrap_x {
            x.rem_euclid(w)
        } else {
            x.clamp(0, w - 1)
        };
        let y = y.clamp(0, self.height as isize - 1);
        self.pixels[y as usize * self.width + x as usize]
    }

    /// Bilinear lookup at image coordinates `st ∈ [0,1]²` (texel centres at half-integers
    /// times the texel size). Columns wrap when `wrap_x`, otherwise they clamp; rows clamp.
    pub fn bilinear(&self, st: Vec2, wrap_x: bool) -> Vec3 {
        let x = st.x * self.width as f32 - 0.5;
        let y = st.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as isize, y0 as isize);
        let t = |dx, dy| self.texel(x0 + dx, y0 + dy, wrap_x);
        (t(0, 0) * (1.0 - fx) + t(1, 0) * fx) * (1.0 - fy)
            + (t(0, 1) * (1.0 - fx) + t(1, 1) * fx) * fy
    }

    /// Importance of each half-texel cell (2W × 2H, row-major): the largest luminance
    /// among the 2×2 texels the bilinear lookup blends over the cell, times `weight(s, t)`
    /// at the cell's centre (a Jacobian).
    pub fn half_texel_importance(&self, wrap_x: bool, weight: impl Fn(Vec2) -> f32) -> Vec<f32> {
        let (w2, h2) = (2 * self.width, 2 * self.height);
        let mut out = Vec::with_capacity(w2 * h2);
        for qy in 0..h2 as isize {
            let y0 = (qy - 1).div_euclid(2);
            for qx in 0..w2 as isize {
                let x0 = (qx - 1).div_euclid(2);
                let m = [(0, 0), (1, 0), (0, 1), (1, 1)]
                    .iter()
                    .map(|&(dx, dy)| luminance(self.texel(x0 + dx, y0 + dy, wrap_x)).max(0.0))
                    .fold(0.0f32, f32::max);
                let centre =
                    Vec2::new((qx as f32 + 0.5) / w2 as f32, (qy as f32 + 0.5) / h2 as f32);
                out.push(m * weight(centre));
            }
        }
        out
    }
}

/// A piecewise-constant density on [0,1)², sampled by a marginal CDF over rows and a
/// conditional CDF within the row, each inverted by binary search (pbrt-v3 §13.6.7).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    conditional: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// From `func`, `width × height` non-negative values, row-major.
    pub fn new(func: &[f32], width: usize, height: usize) -> Distribution2D {
        assert_eq!(func.len(), width * height);
        let conditional: Vec<Distribution1D> =
            func.chunks_exact(width).map(Distribution1D::new).collect();
        let row_weights: Vec<f32> = func
            .chunks_exact(width)
            .map(|row| row.iter().map(|&f| f.max(0.0) as f64).sum::<f64>() as f32)
            .collect();
        Distribution2D {
            conditional,
            marginal: Distribution1D::new(&row_weights),
        }
    }

    /// The integral of the function over [0,1)² (before normalisation).
    pub fn integral(&self) -> f32 {
        self.marginal.integral() / self.conditional[0].len() as f32
    }

    /// A point of [0,1)² and its density.
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (y, pdf_y, row) = self.marginal.sample_continuous(u.y);
        let (x, pdf_x, _) = self.conditional[row].sample_continuous(u.x);
        (Vec2::new(x, y), pdf_x * pdf_y)
    }

    /// Density of [`Self::sample`] at `p ∈ [0,1]²`.
    pub fn pdf(&self, p: Vec2) -> f32 {
        let h = self.marginal.len();
        let row = ((p.y * h as f32) as usize).min(h - 1);
        self.marginal.pdf(p.y.min(ONE_MINUS_EPSILON))
            * self.conditional[row].pdf(p.x.min(ONE_MINUS_EPSILON))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_texel_importance_covers_every_bilinear_footprint() {
        // One lit texel: the bilinear lookup is positive over a 2×2-texel square around
        // its centre, which must be exactly the cells of positive importance.
        let mut img = Image {
            width: 4,
            height: 3,
            pixels: vec![Vec3::ZERO; 12],
        };
        img.pixels[4 + 2] = Vec3::ONE; // x = 2, y = 1
        let imp = img.half_texel_importance(true, |_| 1.0);
        for qy in 0..6 {
            for qx in 0..8 {
                let st = Vec2::new((qx as f32 + 0.5) / 8.0, (qy as f32 + 0.5) / 6.0);
                let lit = img.bilinear(st, true).x > 0.0;
                assert_eq!(imp[qy * 8 + qx] > 0.0, lit, "cell ({qx}, {qy})");
            }
        }
    }

    #[test]
    fn distribution_2d_pdf_matches_sample() {
        let f = [0.0, 1.0, 2.0, 3.0, 0.0, 0.0, 5.0, 1.0, 0.5];
        let d = Distribution2D::new(&f, 3, 3);
        assert!((d.integral() - 12.5 / 9.0).abs() < 1e-5);
        for i in 0..100 {
            let u = Vec2::new((i as f32 * 0.618).fract(), (i as f32 * 0.414).fract());
            let (p, pdf) = d.sample(u);
            assert!(pdf > 0.0);
            assert!((d.pdf(p) - pdf).abs() < 1e-4 * pdf, "{p} {pdf}");
        }
    }
}
