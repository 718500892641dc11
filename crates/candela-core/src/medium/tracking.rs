//! Delta tracking against a majorant: the collisions of a ray with a medium at the
//! majorant's rate in the hero channel, stretch by stretch of constant majorant (pbrt-v4's
//! `SampleT_maj`, as an iterator so that the caller's state needs no closure).

use glam::Vec3;

use super::{MajorantSegment, Majorants, Medium, MediumProperties};
use crate::geometry::Ray;

/// A tentative collision: real (absorption or scattering) or null, for the caller to
/// choose.
#[derive(Clone, Copy, Debug)]
pub struct Collision {
    pub p: Vec3,
    pub t: f32,
    pub props: MediumProperties,
    pub sigma_maj: Vec3,
    /// The majorant transmittance from the previous collision (or where the ray enters) to
    /// this one, all channels.
    pub t_maj: Vec3,
}

/// σ·d per channel, with a zero coefficient giving zero over any distance (so that an
/// unbounded ray through a partly clear medium is not NaN; see [`super::transmittance`]).
#[inline]
fn optical_depth(sigma: Vec3, d: f32) -> Vec3 {
    let one = |s: f32| if s == 0.0 { 0.0 } else { s * d };
    Vec3::new(one(sigma.x), one(sigma.y), one(sigma.z))
}

/// The collisions along `(0, t_max)` of a ray, one per call of [`MajorantTracker::next`].
pub struct MajorantTracker<'a> {
    medium: &'a Medium,
    ray: Ray,
    /// The stretches of constant majorant still ahead, after `segment`.
    segments: Majorants<'a>,
    /// The stretch the last collision is in (or the first one); `None` once passed.
    segment: Option<MajorantSegment>,
    t: f32,
    hero: usize,
    t_maj_end: Vec3,
}

impl<'a> MajorantTracker<'a> {
    /// Tracking of `ray` (unit direction) through `medium` up to `t_max`, distances drawn
    /// at the majorant of channel `hero` (0..3).
    #[inline]
    pub fn new(medium: &'a Medium, ray: &Ray, t_max: f32, hero: usize) -> Self {
        let mut segments = medium.majorants(ray, t_max);
        let segment = segments.next();
        MajorantTracker {
            medium,
            ray: *ray,
            t: segment.map_or(0.0, |s| s.t0),
            segments,
            segment,
            hero,
            t_maj_end: Vec3::ONE,
        }
    }

    /// The next collision, drawn from the uniform `u` ∈ [0, 1); `None` once the ray has
    /// passed the end (then [`Self::t_maj_to_end`] holds the rest of the way's majorant
    /// transmittance). One number serves however many stretches the step crosses: the
    /// optical depth −ln(1 − u) to the collision is spent stretch by stretch, each at its
    /// own majorant (the exponential law is memoryless).
    #[inline]
    pub fn next(&mut self, u: f32) -> Option<Collision> {
        let mut tau = -(1.0 - u).ln();
        // The majorant's optical depth since the last collision, all channels: one
        // exponential at the end, not one per stretch crossed.
        let mut depth = Vec3::ZERO;
        loop {
            let seg = self.segment?;
            let sigma_maj = seg.sigma_maj;
            let rate = sigma_maj[self.hero];
            let len = seg.t1 - self.t;
            if rate > 0.0 && tau < rate * len {
                let dt = tau / rate;
                self.t += dt;
                let p = self.ray.at(self.t);
                return Some(Collision {
                    p,
                    t: self.t,
                    props: self.medium.properties(p),
                    sigma_maj,
                    t_maj: (-(depth + optical_depth(sigma_maj, dt))).exp(),
                });
            }
            if rate > 0.0 {
                tau -= rate * len;
            }
            depth += optical_depth(sigma_maj, len);
            self.segment = self.segments.next();
            match self.segment {
                Some(next) => self.t = next.t0,
                None => self.t_maj_end = (-depth).exp(),
            }
        }
    }

    /// The majorant transmittance from the last collision to the end, once
    /// [`Self::next`] has returned `None` (one where the ray missed the medium).
    pub fn t_maj_to_end(&self) -> Vec3 {
        self.t_maj_end
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chi2::{discrete, sidak_alpha};
    use crate::medium::{HenyeyGreenstein, Homogeneous};
    use crate::sampler::Pcg32;

    /// The first collision distance against the exponential law: a histogram of 40 bins
    /// over [0, t_max) plus the escape bin, for each channel as hero; χ² at α = 0.01.
    #[test]
    fn collision_distances_follow_the_majorant_chi2() {
        let m = Medium::Homogeneous(Homogeneous {
            sigma_a: Vec3::new(0.2, 0.5, 1.0),
            sigma_s: Vec3::new(0.3, 1.0, 2.0),
            phase: HenyeyGreenstein::ISOTROPIC,
        });
        let ray = Ray::new(Vec3::new(0.1, 0.2, 0.3), Vec3::new(0.0, 0.6, 0.8));
        let (t_max, bins, n) = (2.0f32, 40usize, 500_000usize);
        let alpha = sidak_alpha(0.01, 3);
        for hero in 0..3 {
            let sigma =
                (m.properties(Vec3::ZERO).sigma_a + m.properties(Vec3::ZERO).sigma_s)[hero] as f64;
            let mut counts = vec![0u64; bins + 1];
            let mut rng = Pcg32::new(7 + hero as u64, 3);
            for _ in 0..n {
                let mut tr = MajorantTracker::new(&m, &ray, t_max, hero);
                match tr.next(rng.uniform_f32()) {
                    Some(c) => {
                        assert!((c.p - ray.at(c.t)).length() < 1e-5);
                        counts[((c.t / t_max * bins as f32) as usize).min(bins - 1)] += 1
                    }
                    None => counts[bins] += 1,
                }
            }
            let cdf = |t: f64| 1.0 - (-sigma * t).exp();
            let mut pmf: Vec<f64> = (0..bins)
                .map(|i| {
                    let w = t_max as f64 / bins as f64;
                    cdf((i + 1) as f64 * w) - cdf(i as f64 * w)
                })
                .collect();
            pmf.push(1.0 - cdf(t_max as f64));
            let r = discrete(&format!("distance, hero {hero}"), &counts, &pmf, alpha);
            println!(
                "distance hero {hero}: χ² = {:.1}, p = {:.3}",
                r.statistic, r.p_value
            );
            r.assert_passed();
        }
    }

    /// Through a grid's coarse majorants the first tentative collision follows
    /// 1 − e^(−∫σ_maj) with σ_maj piecewise constant along the ray: the same χ² over 40
    /// bins and the escape bin, the expected law integrated from the walk's stretches
    /// (whose tiling of the ray `majorant`'s tests check). And each collision's `t_maj`
    /// is e^(−∫σ_maj) from the previous one, checked against that integral.
    #[test]
    fn collision_distances_through_a_majorant_grid_chi2() {
        use crate::medium::grid::{Albedo, GridMedium, VoxelGrid};
        use glam::Affine3A;
        // A sparse 20³ grid: a dense corner, thin elsewhere, placed on [−1, 1]³.
        let res = 20u32;
        let data: Vec<f32> = (0..res.pow(3))
            .map(|i| {
                let (x, y, z) = (i % res, i / res % res, i / res / res);
                if x < 6 && y < 8 && z > 12 {
                    4.0
                } else {
                    0.05 * ((x + 2 * y + 3 * z) % 5) as f32
                }
            })
            .collect();
        let grid = VoxelGrid::new([res; 3], 3, {
            let mut rgb = Vec::new();
            for v in &data {
                rgb.extend_from_slice(&[*v, 0.5 * v, 2.0 * v]);
            }
            rgb
        })
        .unwrap();
        let to_local =
            Affine3A::from_scale(Vec3::splat(0.5)) * Affine3A::from_translation(Vec3::ONE);
        let m = Medium::Grid(GridMedium::new(
            grid,
            Albedo::Constant(Vec3::splat(0.5)),
            1.5,
            to_local,
            HenyeyGreenstein::ISOTROPIC,
        ));
        let o = Vec3::new(-1.5, -0.9, 0.9);
        let ray = Ray::new(o, (Vec3::new(1.2, 0.7, -0.8) - o).normalize());
        let t_max = 4.0f32;
        let segments: Vec<_> = m.majorants(&ray, t_max).collect();
        assert!(segments.len() > 10, "{} stretches", segments.len());
        // ∫σ_maj from 0 to t, per channel.
        let depth = |t: f32| {
            segments.iter().fold(Vec3::ZERO, |acc, s| {
                acc + s.sigma_maj * (t.min(s.t1) - s.t0).max(0.0)
            })
        };
        let (bins, n) = (40usize, 400_000usize);
        let alpha = sidak_alpha(0.01, 3);
        for hero in 0..3 {
            let cdf = |t: f32| 1.0 - (-depth(t)[hero] as f64).exp();
            let mut counts = vec![0u64; bins + 1];
            let mut rng = Pcg32::new(11 + hero as u64, 5);
            for i in 0..n {
                let mut tr = MajorantTracker::new(&m, &ray, t_max, hero);
                let mut last = 0.0f32;
                let mut first = None;
                // Follow every collision of some paths, checking each t_maj.
                while let Some(c) = tr.next(rng.uniform_f32()) {
                    let expected = (-(depth(c.t) - depth(last))).exp();
                    assert!(
                        (c.t_maj - expected).abs().max_element()
                            < 1e-4 * expected.max_element().max(1.0),
                        "t_maj {} against {expected} from {last} to {}",
                        c.t_maj,
                        c.t
                    );
                    first.get_or_insert(c.t);
                    last = c.t;
                    if i % 16 != 0 {
                        break;
                    }
                }
                match first {
                    Some(t) => counts[((t / t_max * bins as f32) as usize).min(bins - 1)] += 1,
                    None => counts[bins] += 1,
                }
            }
            let mut pmf: Vec<f64> = (0..bins)
                .map(|i| {
                    let w = t_max / bins as f32;
                    cdf((i + 1) as f32 * w) - cdf(i as f32 * w)
                })
                .collect();
            pmf.push(1.0 - cdf(t_max));
            let r = discrete(&format!("grid distance, hero {hero}"), &counts, &pmf, alpha);
            println!(
                "grid distance hero {hero}: χ² = {:.1}, p = {:.3}",
                r.statistic, r.p_value
            );
            r.assert_passed();
        }
    }

    #[test]
    fn escape_reports_the_majorant_transmittance_of_the_rest() {
        let m = Medium::Homogeneous(Homogeneous {
            sigma_a: Vec3::new(0.0, 1.0, 3.0),
            sigma_s: Vec3::ZERO,
            phase: HenyeyGreenstein::ISOTROPIC,
        });
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        // Hero 0 has no extinction: no collision ever, and the whole way's transmittance.
        let mut tr = MajorantTracker::new(&m, &ray, 2.0, 0);
        assert!(tr.next(0.999).is_none());
        let t = tr.t_maj_to_end();
        assert_eq!(t.x, 1.0);
        assert!((t.y - (-2.0f32).exp()).abs() < 1e-6 && (t.z - (-6.0f32).exp()).abs() < 1e-6);
        // Unbounded: channels with extinction reach zero, the clear one stays one.
        let mut tr = MajorantTracker::new(&m, &ray, f32::INFINITY, 0);
        assert!(tr.next(0.5).is_none());
        assert_eq!(tr.t_maj_to_end(), Vec3::new(1.0, 0.0, 0.0));
    }
}
