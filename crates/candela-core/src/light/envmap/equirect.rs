//! The latitude-longitude (equirectangular) panorama.

use std::f32::consts::{FRAC_1_PI, PI};

use glam::{Vec2, Vec3, Vec4};

use super::bilinear::{Bilinear2D, GridAxis};
use super::{compensated, Image, MapSample};
use crate::math::{atan2_poly_lanes, luminance};
use crate::sampling::{sample_bilinear, sin_cos_quarter_turns, sin_cos_quarter_turns_pair};

/// A panorama in the native mapping of [`super`]: y up, centre along −z.
///
/// Lookups and sampling share one grid whose vertices are the texel centres, plus the
/// poles: columns at u = (k + ½)/W for k = 0..=W (the last one is column 0 again, one
/// turn on), rows at v = 0, (j + ½)/H for j = 0..H, and 1. The bilinear radiance blends
/// the four texels at a cell's corners (at the poles' half-rows, the edge row with
/// itself: the lookup clamps there). The sampling density in (u, v) is the same bilinear
/// blend of a weight × sin θ at the vertices (zero at the poles), sampled exactly
/// ([`Bilinear2D`]): as Mitsuba 3's `envmap`, so the density follows the radiance within
/// every texel, a sun's rim included, not a step function over it. The weight is the
/// luminance above half the map's mean (with a floor: see `compensated`).
#[derive(Clone, Debug)]
pub struct Equirect {
    pub image: Image,
    /// Per grid vertex, row-major: the texel's radiance and the sampling function there.
    grid: Vec<Vec4>,
    /// Boxed, to keep [`crate::light::Light`] small.
    distribution: Box<Bilinear2D>,
    /// Half a texel's width in u, 0.5 / width: where the grid's columns start.
    half_texel: f32,
    /// The distribution's integral times 2π²: the solid-angle density is the grid's
    /// sampling function over this and sin θ.
    integral_solid_angle: f32,
}

/// Image coordinates (u right, v down, both in \[0, 1\]) of a unit direction.
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    direction_to_uv_sin(d).0
}

/// [`direction_to_uv`] and sin θ = √(x² + z²), which it computes on the way (θ as
/// atan2(sin θ, cos θ); both angles by [`atan2_poly_lanes`], in two lanes of one pass:
/// bit for bit [`crate::math::atan2_poly`], a third of libm's `atan2f` and `acosf`, as
/// accurate).
#[inline(always)]
fn direction_to_uv_sin(d: Vec3) -> (Vec2, f32) {
    let sin_theta = (d.x * d.x + d.z * d.z).sqrt();
    let angles = atan2_poly_lanes(
        Vec4::new(d.x, sin_theta, 0.0, 0.0),
        Vec4::new(-d.z, d.y, 1.0, 1.0),
    );
    let u = 0.5 * (1.0 + angles.x * FRAC_1_PI);
    let v = angles.y * FRAC_1_PI;
    (Vec2::new(u, v), sin_theta)
}

/// The unit direction at image coordinates `uv`; the inverse of [`direction_to_uv`].
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    uv_to_direction_sin(uv).0
}

/// [`uv_to_direction`] and the sin θ it computes on the way. The angles, θ = πv and
/// φ = π(2u − 1), are taken in quarter turns, together ([`sin_cos_quarter_turns_pair`]:
/// polynomials in SIMD lanes, no library calls).
#[inline]
fn uv_to_direction_sin(uv: Vec2) -> (Vec3, f32) {
    let [(st, ct), (sp, cp)] = sin_cos_quarter_turns_pair(Vec2::new(2.0 * uv.y, 4.0 * uv.x - 2.0));
    (Vec3::new(st * sp, ct, -st * cp), st)
}

/// The mean luminance over the sphere, ∫ L dω / 4π, by texel (rows weighted by sin θ).
fn mean_luminance(image: &Image) -> f32 {
    let (w, h) = (image.width, image.height);
    let (mut sum, mut weight) = (0.0f64, 0.0f64);
    for (j, row) in image.pixels.chunks_exact(w).enumerate() {
        let sin_theta = (PI * (j as f32 + 0.5) / h as f32).sin() as f64;
        sum += sin_theta
            * row
                .iter()
                .map(|&l| luminance(l).max(0.0) as f64)
                .sum::<f64>();
        weight += sin_theta * w as f64;
    }
    (sum / weight) as f32
}

/// Solid angle per unit area of (u, v) over sin θ: dω = 2π² sin θ du dv.
const UV_TO_SOLID_ANGLE: f32 = 2.0 * PI * PI;

impl Equirect {
    /// Builds the lookup grid and the sampling distribution.
    pub fn new(image: Image) -> Equirect {
        let (w, h) = (image.width, image.height);
        let (x_axis, y_axis) = (GridAxis::Even(w), GridAxis::Centred(h));
        let mean = mean_luminance(&image);
        let mut grid = Vec::with_capacity(x_axis.vertices() * y_axis.vertices());
        for j in 0..y_axis.vertices() {
            let row = j.saturating_sub(1).min(h - 1);
            let sin_theta = if j == 0 || j > h {
                0.0
            } else {
                (PI * y_axis.position(j)).sin()
            };
            for k in 0..x_axis.vertices() {
                let l = image.pixels[row * w + k % w];
                grid.push(l.extend(compensated(luminance(l), mean) * sin_theta));
            }
        }
        let distribution = Box::new(Bilinear2D::new(
            grid.iter().map(|t| t.w).collect(),
            x_axis,
            y_axis,
        ));
        Equirect {
            half_texel: 0.5 / w as f32,
            integral_solid_angle: distribution.integral() * UV_TO_SOLID_ANGLE,
            image,
            grid,
            distribution,
        }
    }

    /// The grid's coordinates of `uv`: columns start half a texel to the right of u = 0.
    #[inline(always)]
    fn grid_point(&self, uv: Vec2) -> Vec2 {
        let x = uv.x - self.half_texel;
        Vec2::new(if x < 0.0 { x + 1.0 } else { x }, uv.y)
    }

    /// The grid vertices at the corners of the cell of column `k`, row `j`: top left,
    /// top right, bottom left, bottom right. One bounds check for the four (slicing
    /// them out, then indexing the slice, took six).
    #[inline]
    fn cell(&self, k: usize, j: usize) -> [Vec4; 4] {
        let stride = self.image.width + 1;
        let i = j * stride + k;
        assert!(
            i < self.grid.len().saturating_sub(stride + 1),
            "cell ({k}, {j}) outside the grid"
        );
        // SAFETY: i + stride + 1 < len, checked above; the other three are smaller.
        unsafe {
            [
                *self.grid.get_unchecked(i),
                *self.grid.get_unchecked(i + 1),
                *self.grid.get_unchecked(i + stride),
                *self.grid.get_unchecked(i + stride + 1),
            ]
        }
    }

    /// Radiance and sampling function, blended at grid point `p`.
    #[inline(always)]
    fn lookup(&self, p: Vec2) -> Vec4 {
        let (k, s) = GridAxis::Even(self.image.width).locate(p.x);
        let (j, t) = GridAxis::Centred(self.image.height).locate(p.y);
        let c = self.cell(k, j);
        c[0].lerp(c[1], s).lerp(c[2].lerp(c[3], s), t)
    }

    /// Bilinearly filtered radiance towards unit direction `d`.
    pub fn eval(&self, d: Vec3) -> Vec3 {
        self.lookup(self.grid_point(direction_to_uv(d))).truncate()
    }

    /// The radiance towards unit direction `d` and the solid-angle density with which
    /// [`Self::sample`] draws `d`, from one lookup.
    pub fn eval_pdf(&self, d: Vec3) -> (Vec3, f32) {
        let (uv, sin_theta) = direction_to_uv_sin(d);
        let c = self.lookup(self.grid_point(uv));
        let pdf = if sin_theta > 0.0 && self.integral_solid_angle > 0.0 {
            c.w / (self.integral_solid_angle * sin_theta)
        } else {
            0.0
        };
        (c.truncate(), pdf)
    }

    /// A direction drawn with density ∝ the luminance of the radiance (the grid's bilinear
    /// approximation of it): see [`Equirect`]. The cell comes from the distribution; the
    /// point within it, its radiance and its density from the cell's four grid vertices.
    pub fn sample(&self, u: Vec2) -> Option<MapSample> {
        let (k, j, rest) = self.distribution.sample_cell(u)?;
        let [g00, g10, g01, g11] = self.cell(k, j);
        let st = sample_bilinear(rest, [g00.w, g10.w, g01.w, g11.w]);
        let c = g00.lerp(g10, st.x).lerp(g01.lerp(g11, st.x), st.y);
        let p = self.distribution.cell_point(k, j, st);
        let x = p.x + self.half_texel;
        let uv = Vec2::new(if x >= 1.0 { x - 1.0 } else { x }, p.y);
        let (dir, sin_theta) = uv_to_direction_sin(uv);
        if sin_theta <= 0.0 || c.w <= 0.0 {
            return None;
        }
        Some(MapSample {
            dir,
            pdf: c.w / (self.integral_solid_angle * sin_theta),
            radiance: c.truncate(),
        })
    }

    /// Solid-angle density of [`Self::sample`] towards unit direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        self.eval_pdf(d).1
    }

    /// Each texel's direction (its centre), luminance × solid angle, and solid angle.
    pub fn luminance_patches(&self) -> impl Iterator<Item = (Vec3, f32, f32)> + Clone + '_ {
        let (w, h) = (self.image.width, self.image.height);
        let texel_area = UV_TO_SOLID_ANGLE / (w * h) as f32;
        // The angles' sines and cosines by row and by column, not by texel.
        let rows: Vec<(f32, f32)> = (0..h)
            .map(|j| sin_cos_quarter_turns(2.0 * (j as f32 + 0.5) / h as f32))
            .collect();
        let cols: Vec<(f32, f32)> = (0..w)
            .map(|i| sin_cos_quarter_turns(4.0 * (i as f32 + 0.5) / w as f32 - 2.0))
            .collect();
        self.image.pixels.iter().enumerate().map(move |(i, &l)| {
            let ((st, ct), (sp, cp)) = (rows[i / w], cols[i % w]);
            let area = st * texel_area;
            let d = Vec3::new(st * sp, ct, -st * cp);
            (d, luminance(l).max(0.0) * area, area)
        })
    }

    /// ∫ luminance(L) dω, by the midpoint rule over the texels.
    pub fn luminance_integral(&self) -> f32 {
        self.luminance_patches()
            .map(|(_, w, _)| w as f64)
            .sum::<f64>() as f32
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
