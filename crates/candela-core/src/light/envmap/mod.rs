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
//! Both sample a bilinear density through the texel centres (and the edges, where the
//! lookup clamps), so that the density follows the filtered radiance within every texel
//! ([`bilinear`], as Mitsuba 3's `envmap`); its weights are the luminance above half the
//! map's mean, floored (`compensated`), times the mapping's Jacobian. The density is positive
//! wherever the filtered radiance is.

pub mod bilinear;
pub mod cubemap;
pub mod equirect;

pub use cubemap::Cubemap;
pub use equirect::Equirect;

use glam::{Vec2, Vec3};

use crate::desc::ImageDesc;

/// A direction drawn from an environment map: its solid-angle density and the radiance
/// arriving along it (in the map's frame, strength not applied).
#[derive(Clone, Copy, Debug)]
pub struct MapSample {
    pub dir: Vec3,
    pub pdf: f32,
    pub radiance: Vec3,
}

/// The fraction of the map's mean luminance that [`compensated`] subtracts.
const COMPENSATION: f32 = 0.5;

/// The share of a texel's luminance that its sampling weight keeps at least.
const COMPENSATION_FLOOR: f32 = 1.0 / 16.0;

/// The sampling weight of a texel of luminance `lum` in a map of mean luminance `mean`:
/// what exceeds half the mean, and never under a sixteenth of the texel's own luminance.
/// MIS compensation (Karlík et al. 2019, "MIS Compensation: Optimizing Sampling
/// Techniques in Multiple Importance Sampling", who subtract the whole mean; Mitsuba 3's
/// `mis_compensation`, off by default there): with MIS, BSDF sampling finds an even
/// sky's light about as well as light sampling does, so light samples are worth more on
/// what stands out (a sun) than spread over the rest. The floor keeps the density
/// positive wherever the radiance is, so that light sampling without MIS stays unbiased.
///
/// Half the mean, not all of it: relMSE at equal spp against the uncompensated bilinear
/// density (bench/RESULTS.md, `## env_paths`) was 0.83× (half) and 0.81× (whole) on
/// `bench/scenes/hdr-sky-sun.xml`, 64 spp, 8 seeds; 0.90× and 1.43× on `bench/env_mis.sh`'s
/// synthetic sky, 16 spp, 16 seeds, whose smooth sky lies wholly below its mean, so that
/// subtracting all of it left the sky's light to BSDF sampling alone. Floors of 0 to ¼
/// changed hdr-sky-sun by under 6 %.
pub(crate) fn compensated(lum: f32, mean: f32) -> f32 {
    let lum = lum.max(0.0);
    (lum - COMPENSATION * mean).max(COMPENSATION_FLOOR * lum)
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
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One lit texel: the density is positive exactly where the bilinear lookup is (the
    /// 2×2-texel square around the texel's centre), on both forms of map.
    #[test]
    fn density_covers_every_bilinear_footprint() {
        let lit = |w: usize, h: usize, at: usize| {
            let mut pixels = vec![Vec3::ZERO; w * h];
            pixels[at] = Vec3::ONE;
            Image {
                width: w,
                height: h,
                pixels,
            }
        };
        let pano = Equirect::new(lit(8, 4, 8 + 2));
        let cube = Cubemap::new(Box::new(std::array::from_fn(|f| {
            lit(4, 4, if f == 1 { 5 } else { 15 })
        })));
        let (mut positive, mut total) = (0, 0);
        for i in 0..400 {
            for j in 1..200 {
                let uv = Vec2::new((i as f32 + 0.5) / 400.0, j as f32 / 200.0);
                let d = equirect::uv_to_direction(uv);
                for (radiance, pdf) in [(pano.eval(d), pano.pdf(d)), (cube.eval(d), cube.pdf(d))] {
                    assert_eq!(radiance.x > 0.0, pdf > 0.0, "{d}: {radiance} {pdf}");
                    positive += (pdf > 0.0) as usize;
                    total += 1;
                }
            }
        }
        assert!(
            positive > total / 100 && positive < total / 4,
            "{positive} of {total}"
        );
    }
}
