//! The film: per pixel, weighted sums of radiance and of filter weights plus a sample
//! count, so it can be resolved into an image at any moment. Films of disjoint sample
//! ranges of one image add up to the film of their union ([`Film::merge`]): that is how a
//! render is split across processes or machines.

use glam::{DVec3, Vec3};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pixel {
    /// Σ wᵢ·Lᵢ over accepted samples.
    pub radiance_sum: DVec3,
    /// Σ wᵢ.
    pub weight_sum: f64,
    /// Samples taken, accepted or not.
    pub samples: u32,
    /// Samples dropped because they were not finite.
    pub rejected: u32,
}

impl Pixel {
    /// Adds a sample with filter weight `weight`. A sample with a NaN or infinite value is
    /// counted and dropped, so it never reaches the image.
    #[inline]
    pub fn add(&mut self, radiance: Vec3, weight: f32) {
        self.samples += 1;
        if !radiance.is_finite() || !weight.is_finite() {
            self.rejected += 1;
            return;
        }
        self.radiance_sum += radiance.as_dvec3() * weight as f64;
        self.weight_sum += weight as f64;
    }

    /// Counts a sample taken in this pixel whose radiance other calls share out (see
    /// [`crate::splat`]); returns whether it is finite, else it is counted as dropped.
    #[inline]
    pub fn count(&mut self, radiance: Vec3) -> bool {
        self.samples += 1;
        let finite = radiance.is_finite();
        self.rejected += !finite as u32;
        finite
    }

    /// Adds a share `weight` of a sample counted elsewhere ([`Self::count`]).
    #[inline]
    pub fn add_weighted(&mut self, radiance: Vec3, weight: f32) {
        self.radiance_sum += radiance.as_dvec3() * weight as f64;
        self.weight_sum += weight as f64;
    }

    /// Adds another accumulator of the same pixel (disjoint samples) into this one.
    pub fn merge(&mut self, other: &Pixel) {
        self.radiance_sum += other.radiance_sum;
        self.weight_sum += other.weight_sum;
        self.samples += other.samples;
        self.rejected += other.rejected;
    }

    /// The pixel's estimate: the weighted mean of its samples (black if none).
    pub fn value(&self) -> Vec3 {
        if self.weight_sum > 0.0 {
            (self.radiance_sum / self.weight_sum).as_vec3()
        } else {
            Vec3::ZERO
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first.
    pub pixels: Vec<Pixel>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        Film {
            width,
            height,
            pixels: vec![Pixel::default(); width as usize * height as usize],
        }
    }

    pub fn pixel(&self, x: u32, y: u32) -> &Pixel {
        &self.pixels[(y * self.width + x) as usize]
    }

    /// The image: each pixel divided by its own weights, so a film interrupted part-way
    /// still resolves to an unbiased (noisier) image.
    pub fn resolve(&self) -> Vec<Vec3> {
        self.pixels.iter().map(Pixel::value).collect()
    }

    /// Adds another film of the same size (a disjoint range of samples) into this one.
    pub fn merge(&mut self, other: &Film) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "films differ in size"
        );
        for (a, b) in self.pixels.iter_mut().zip(&other.pixels) {
            a.merge(b);
        }
    }

    pub fn total_samples(&self) -> u64 {
        self.pixels.iter().map(|p| p.samples as u64).sum()
    }

    pub fn rejected_samples(&self) -> u64 {
        self.pixels.iter().map(|p| p.rejected as u64).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_samples_are_counted_and_dropped() {
        let mut p = Pixel::default();
        p.add(Vec3::ONE, 1.0);
        p.add(Vec3::new(f32::NAN, 0.0, 0.0), 1.0);
        p.add(Vec3::splat(f32::INFINITY), 1.0);
        p.add(Vec3::splat(3.0), 1.0);
        assert_eq!((p.samples, p.rejected), (4, 2));
        assert_eq!(p.value(), Vec3::splat(2.0));
    }

    #[test]
    fn merged_films_equal_the_film_of_the_union() {
        let mut whole = Film::new(2, 1);
        let (mut a, mut b) = (Film::new(2, 1), Film::new(2, 1));
        for (i, v) in [0.5f32, 2.0, 4.0, 8.0].into_iter().enumerate() {
            whole.pixels[i % 2].add(Vec3::splat(v), 1.0);
            if i < 2 { &mut a } else { &mut b }.pixels[i % 2].add(Vec3::splat(v), 1.0);
        }
        a.merge(&b);
        assert_eq!(a, whole);
    }
}
