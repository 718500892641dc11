//! Delta tracking against a majorant: the collisions of a ray with a medium at the
//! majorant's rate in the hero channel (pbrt-v4's `SampleT_maj`, as an iterator so that the
//! caller's state needs no closure).

use glam::Vec3;

use super::{transmittance, MajorantSegment, Medium, MediumProperties};
use crate::geometry::Ray;

/// A tentative collision: real (absorption or scattering) or null, for the caller to
/// choose.
#[derive(Clone, Copy, Debug)]
pub struct Collision {
    pub p: Vec3,
    pub t: f32,
    pub props: MediumProperties,
    pub sigma_maj: Vec3,
    /// The majorant transmittance from the previous collision (or the segment's start) to
    /// this one, all channels.
    pub t_maj: Vec3,
}

/// The collisions along `(0, t_max)` of a ray, one per call of [`MajorantTracker::next`].
pub struct MajorantTracker<'a> {
    medium: &'a Medium,
    ray: Ray,
    segment: Option<MajorantSegment>,
    t: f32,
    hero: usize,
    t_maj_end: Vec3,
}

impl<'a> MajorantTracker<'a> {
    /// Tracking of `ray` (unit direction) through `medium` up to `t_max`, distances drawn
    /// at the majorant of channel `hero` (0..3).
    pub fn new(medium: &'a Medium, ray: &Ray, t_max: f32, hero: usize) -> Self {
        let segment = medium.majorant(ray, t_max);
        MajorantTracker {
            medium,
            ray: *ray,
            t: segment.map_or(0.0, |s| s.t0),
            segment,
            hero,
            t_maj_end: Vec3::ONE,
        }
    }

    /// The next collision, drawn from the uniform `u` ∈ [0, 1); `None` once the ray has
    /// passed the end (then [`Self::t_maj_to_end`] holds the rest of the way's majorant
    /// transmittance).
    #[inline]
    pub fn next(&mut self, u: f32) -> Option<Collision> {
        let seg = self.segment?;
        let sigma_maj = seg.sigma_maj;
        let rate = sigma_maj[self.hero];
        let dt = if rate > 0.0 {
            -(1.0 - u).ln() / rate
        } else {
            f32::INFINITY
        };
        let t = self.t + dt;
        if t.is_nan() || t >= seg.t1 {
            self.t_maj_end = transmittance(sigma_maj, seg.t1 - self.t);
            self.segment = None;
            return None;
        }
        self.t = t;
        let p = self.ray.at(t);
        Some(Collision {
            p,
            t,
            props: self.medium.properties(p),
            sigma_maj,
            t_maj: transmittance(sigma_maj, dt),
        })
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
