//! Aperture shapes of a thin lens, sampled uniformly (or ∝ an image's luminance) in the
//! unit-radius lens plane. Every sampler maps `u ∈ [0,1)²` without rejection, so that it
//! uses exactly two sample dimensions.

use std::f32::consts::{FRAC_PI_2, TAU};

use glam::Vec2;

use crate::desc::ApertureDesc;
use crate::sampling::{sample_concentric_disk, sample_uniform_triangle, Distribution1D};

/// An aperture in lens coordinates where the aperture circle has radius 1; the camera
/// scales samples by its aperture radius.
#[derive(Clone, Debug)]
pub enum Aperture {
    /// The unit disc, through the concentric map.
    Disc,
    /// A regular polygon inscribed in the unit circle.
    Polygon(PolygonAperture),
    /// An image mask fitted into [-1,1]², sampled ∝ luminance.
    Image(ImageAperture),
}

impl Aperture {
    /// The aperture of a validated description (see [`crate::build`]).
    pub fn new(desc: &ApertureDesc) -> Aperture {
        match desc {
            ApertureDesc::Disc => Aperture::Disc,
            ApertureDesc::Polygon {
                blades,
                rotation_deg,
            } => Aperture::Polygon(PolygonAperture::new(*blades, rotation_deg.to_radians())),
            ApertureDesc::Image {
                width,
                height,
                luminance,
            } => Aperture::Image(ImageAperture::new(*width, *height, luminance)),
        }
    }

    /// A point of the aperture from a uniform `u`.
    pub fn sample(&self, u: Vec2) -> Vec2 {
        match self {
            Aperture::Disc => sample_concentric_disk(u),
            Aperture::Polygon(p) => p.sample(u),
            Aperture::Image(i) => i.sample(u),
        }
    }

    /// Density of [`Self::sample`] per unit area of the lens plane at `p`.
    pub fn pdf(&self, p: Vec2) -> f32 {
        match self {
            Aperture::Disc if p.length_squared() <= 1.0 => std::f32::consts::FRAC_1_PI,
            Aperture::Disc => 0.0,
            Aperture::Polygon(poly) if poly.contains(p) => 1.0 / poly.area(),
            Aperture::Polygon(_) => 0.0,
            Aperture::Image(i) => i.pdf(p),
        }
    }
}

/// A regular n-gon, split into n triangles fanned around the centre. All triangles have
/// the same area, so one coordinate picks a triangle uniformly and, rescaled, samples it
/// together with the other (Heitz 2019's square-to-triangle map).
#[derive(Clone, Debug)]
pub struct PolygonAperture {
    /// The corners, counter-clockwise, and corner 0 again at the end (a triangle's second
    /// corner without a modulo).
    corners: Vec<Vec2>,
}

impl PolygonAperture {
    /// `blades ≥ 3` corners on the unit circle, corner 0 at angle π/2 + `rotation`.
    pub fn new(blades: u32, rotation: f32) -> PolygonAperture {
        let corners = (0..=blades)
            .map(|k| {
                let k = k % blades;
                let phi = FRAC_PI_2 + rotation + TAU * k as f32 / blades as f32;
                Vec2::new(phi.cos(), phi.sin())
            })
            .collect();
        PolygonAperture { corners }
    }

    /// The corners, counter-clockwise.
    pub fn corners(&self) -> &[Vec2] {
        &self.corners[..self.corners.len() - 1]
    }

    /// Area: n/2 · sin(2π/n) for a polygon inscribed in the unit circle.
    pub fn area(&self) -> f32 {
        let n = self.corners().len() as f32;
        0.5 * n * (TAU / n).sin()
    }

    pub fn sample(&self, u: Vec2) -> Vec2 {
        let n = self.corners().len();
        let scaled = u.x * n as f32;
        let i = (scaled as usize).min(n - 1);
        let ux = (scaled - i as f32).clamp(0.0, crate::sampling::ONE_MINUS_EPSILON);
        let b = sample_uniform_triangle(Vec2::new(ux, u.y));
        // Barycentrics (b0, b1, b2) over (centre, corner i, corner i+1).
        b.y * self.corners[i] + b.z * self.corners[i + 1]
    }

    /// Whether `p` lies inside (or on) the polygon.
    pub fn contains(&self, p: Vec2) -> bool {
        self.corners.windows(2).all(|e| {
            let (a, b) = (e[0], e[1]);
            (b - a).perp_dot(p - a) >= -1e-6
        })
    }
}

/// An image mask sampled ∝ pixel luminance: a marginal distribution over rows and one
/// conditional distribution per row (pbrt-v3 §13.6.7, "Piecewise-Constant 2D
/// Distributions").
#[derive(Clone, Debug)]
pub struct ImageAperture {
    marginal: Distribution1D,
    rows: Vec<Distribution1D>,
    /// Half extents of the image in lens coordinates: the longer side spans [-1, 1].
    half: Vec2,
}

impl ImageAperture {
    /// From a validated mask (`width·height` finite, non-negative values, not all zero).
    pub fn new(width: u32, height: u32, luminance: &[f32]) -> ImageAperture {
        let rows: Vec<Distribution1D> = luminance
            .chunks(width as usize)
            .map(Distribution1D::new)
            .collect();
        // Not `Distribution1D::integral`, which is 1 for an all-black row.
        let row_weights: Vec<f32> = luminance
            .chunks(width as usize)
            .map(|row| row.iter().map(|&v| v as f64).sum::<f64>() as f32)
            .collect();
        let longer = width.max(height) as f32;
        ImageAperture {
            marginal: Distribution1D::new(&row_weights),
            rows,
            half: Vec2::new(width as f32 / longer, height as f32 / longer),
        }
    }

    /// Half extents in lens coordinates.
    pub fn half_extent(&self) -> Vec2 {
        self.half
    }

    pub fn sample(&self, u: Vec2) -> Vec2 {
        let (y, _, row) = self.marginal.sample_continuous(u.y);
        let (x, _, _) = self.rows[row].sample_continuous(u.x);
        // Image rows run downwards, the lens's y axis upwards.
        Vec2::new((2.0 * x - 1.0) * self.half.x, (1.0 - 2.0 * y) * self.half.y)
    }

    pub fn pdf(&self, p: Vec2) -> f32 {
        let x = (p.x / self.half.x + 1.0) * 0.5;
        let y = (1.0 - p.y / self.half.y) * 0.5;
        if !(0.0..1.0).contains(&x) || !(0.0..1.0).contains(&y) {
            return 0.0;
        }
        let row = ((y * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        // Density on the unit square, then per unit lens area (the square maps to an area
        // of 4·half.x·half.y).
        self.marginal.pdf(y) * self.rows[row].pdf(x) / (4.0 * self.half.x * self.half.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygon_samples_stay_inside_and_reach_every_triangle() {
        for n in [3, 5, 6, 8] {
            let poly = PolygonAperture::new(n, 0.3);
            let mut hit = vec![false; n as usize];
            for k in 0..4096 {
                let u = Vec2::new((k % 64) as f32 / 64.0, (k / 64) as f32 / 64.0);
                let p = poly.sample(u);
                assert!(poly.contains(p), "n = {n}, u = {u}, p = {p}");
                hit[(u.x * n as f32) as usize] = true;
            }
            assert!(hit.iter().all(|&h| h));
        }
        // Corner 0 points up at rotation 0.
        let c0 = PolygonAperture::new(6, 0.0).corners()[0];
        assert!((c0 - Vec2::Y).length() < 1e-6);
    }

    #[test]
    fn image_aperture_never_samples_black_pixels_and_keeps_image_upright() {
        // 2×2 mask: only the top-left pixel is lit.
        let img = ImageAperture::new(2, 2, &[1.0, 0.0, 0.0, 0.0]);
        for k in 0..1000 {
            let u = Vec2::new((k % 31) as f32 / 31.0, (k / 31) as f32 / 33.0);
            let p = img.sample(u);
            assert!(p.x <= 0.0 && p.y >= 0.0, "{p}");
            assert!((img.pdf(p) - 1.0).abs() < 1e-5, "u {u}: pdf {}", img.pdf(p));
            // ¼ of [-1,1]²
        }
        assert_eq!(img.pdf(Vec2::new(0.5, 0.5)), 0.0);
    }
}
