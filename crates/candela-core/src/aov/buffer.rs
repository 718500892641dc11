//! The AOV film: per pixel, sums of the passes over its samples, beside the beauty's
//! [`crate::film::Film`] (which it leaves alone).

use glam::{DVec3, Vec3};

use super::{AovKind, FirstSurface};

/// One pixel's sums.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AovPixel {
    /// Σ albedo (0 for a sample that found no surface).
    pub albedo_sum: DVec3,
    /// Σ shading normal (0 for a sample that found no surface).
    pub normal_sum: DVec3,
    /// Σ depth over the samples that hit something.
    pub depth_sum: f64,
    /// Samples that hit something.
    pub hits: u32,
    /// Samples taken.
    pub samples: u32,
}

impl AovPixel {
    /// Adds one sample: what its camera ray found, if anything.
    pub fn add(&mut self, s: Option<&FirstSurface>) {
        self.samples += 1;
        let Some(s) = s else {
            return;
        };
        // A sample whose values are not finite counts as a miss, as the beauty drops them.
        if !(s.albedo.is_finite() && s.normal.is_finite() && s.depth.is_finite()) {
            return;
        }
        self.albedo_sum += s.albedo.as_dvec3();
        self.normal_sum += s.normal.as_dvec3();
        self.depth_sum += s.depth as f64;
        self.hits += 1;
    }

    /// Mean albedo over the pixel's samples, background counting black: edges blend as
    /// the beauty's do.
    pub fn albedo(&self) -> Vec3 {
        self.mean(self.albedo_sum)
    }

    /// Mean shading normal over the samples (not renormalized: at an edge it is the
    /// average of both sides, as OIDN expects of an antialiased normal pass).
    pub fn normal(&self) -> Vec3 {
        self.mean(self.normal_sum)
    }

    /// Mean depth over the samples that hit something; +∞ where none did.
    pub fn depth(&self) -> f32 {
        if self.hits > 0 {
            (self.depth_sum / self.hits as f64) as f32
        } else {
            f32::INFINITY
        }
    }

    fn mean(&self, sum: DVec3) -> Vec3 {
        if self.samples > 0 {
            (sum / self.samples as f64).as_vec3()
        } else {
            Vec3::ZERO
        }
    }
}

/// The passes of a whole image.
#[derive(Clone, Debug, PartialEq)]
pub struct AovFilm {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first.
    pub pixels: Vec<AovPixel>,
}

impl AovFilm {
    pub fn new(width: u32, height: u32) -> AovFilm {
        AovFilm {
            width,
            height,
            pixels: vec![AovPixel::default(); width as usize * height as usize],
        }
    }

    pub fn pixel(&self, x: u32, y: u32) -> &AovPixel {
        &self.pixels[(y * self.width + x) as usize]
    }

    /// The albedo pass, row-major.
    pub fn albedo(&self) -> Vec<Vec3> {
        self.pixels.iter().map(AovPixel::albedo).collect()
    }

    /// The normal pass, row-major.
    pub fn normal(&self) -> Vec<Vec3> {
        self.pixels.iter().map(AovPixel::normal).collect()
    }

    /// The depth pass, row-major.
    pub fn depth(&self) -> Vec<f32> {
        self.pixels.iter().map(AovPixel::depth).collect()
    }

    /// One pass's channels, each row-major, in the order [`AovKind::layer`] names them.
    pub fn channels(&self, kind: AovKind) -> Vec<Vec<f32>> {
        let split = |v: Vec<Vec3>| {
            (0..3)
                .map(|c| v.iter().map(|p| p[c]).collect())
                .collect::<Vec<_>>()
        };
        match kind {
            AovKind::Albedo => split(self.albedo()),
            AovKind::Normal => split(self.normal()),
            AovKind::Depth => vec![self.depth()],
        }
    }

    /// Adds the film of a disjoint range of samples of the same image.
    pub fn merge(&mut self, other: &AovFilm) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "AOV films differ in size"
        );
        for (a, b) in self.pixels.iter_mut().zip(&other.pixels) {
            a.albedo_sum += b.albedo_sum;
            a.normal_sum += b.normal_sum;
            a.depth_sum += b.depth_sum;
            a.hits += b.hits;
            a.samples += b.samples;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn surface(albedo: f32, depth: f32) -> FirstSurface {
        FirstSurface {
            albedo: Vec3::splat(albedo),
            normal: Vec3::Z,
            depth,
        }
    }

    #[test]
    fn misses_darken_albedo_and_normal_but_not_depth() {
        let mut p = AovPixel::default();
        p.add(Some(&surface(0.8, 2.0)));
        p.add(None);
        p.add(Some(&surface(f32::NAN, 1.0)));
        p.add(Some(&surface(0.4, 4.0)));
        assert_eq!((p.samples, p.hits), (4, 2));
        assert_eq!(p.albedo(), Vec3::splat(0.3));
        assert_eq!(p.normal(), Vec3::Z * 0.5);
        assert_eq!(p.depth(), 3.0);
        assert_eq!(AovPixel::default().depth(), f32::INFINITY);
    }

    #[test]
    fn merged_films_equal_the_film_of_the_union() {
        let (mut whole, mut a, mut b) =
            (AovFilm::new(1, 1), AovFilm::new(1, 1), AovFilm::new(1, 1));
        for (i, d) in [1.0f32, 2.0, 5.0].into_iter().enumerate() {
            let s = surface(0.5, d);
            whole.pixels[0].add(Some(&s));
            if i == 0 { &mut a } else { &mut b }.pixels[0].add(Some(&s));
        }
        a.merge(&b);
        assert_eq!(a, whole);
    }
}
