//! The film: per pixel, weighted sums of radiance and of filter weights plus a sample
//! count, so it can be resolved into an image at any moment. Films of disjoint sample
//! ranges of one image add up to the film of their union ([`Film::merge`]): that is how a
//! render is split across processes or machines.
//!
//! The sums are [`ExactSum`]s, fixed-point integers (see [`crate::exact_sum`] for their
//! range and resolution), so that the merge of any split of a sample range is the film
//! of the whole range **bit for bit**, whatever the grouping and order of the parts. The
//! same holds for any other way contributions reach a pixel: [`Pixel::add`] is "add this
//! weighted contribution to this pixel", and a renderer that splats a sample into
//! neighbouring pixels from several threads gets the same film in every run.

use glam::Vec3;

use crate::exact_sum::ExactSum;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pixel {
    /// Σ wᵢ·Lᵢ over accepted samples, per channel.
    pub radiance_sum: [ExactSum; 3],
    /// Σ wᵢ.
    pub weight_sum: ExactSum,
    /// Samples taken, accepted or not.
    pub samples: u32,
    /// Samples dropped because they were not finite.
    pub rejected: u32,
}

impl Pixel {
    /// Adds a sample with filter weight `weight`. A sample with a NaN or infinite value,
    /// or one beyond [`crate::exact_sum::MAX_CONTRIBUTION`], is counted and dropped, so
    /// it never reaches the image.
    #[inline]
    pub fn add(&mut self, radiance: Vec3, weight: f32) {
        self.samples += 1;
        if !self.add_weighted(radiance, weight) {
            self.rejected += 1;
        }
    }

    /// Adds another pixel's sums and counts (a disjoint set of samples).
    #[inline]
    pub fn merge(&mut self, other: &Pixel) {
        for (a, b) in self.radiance_sum.iter_mut().zip(other.radiance_sum) {
            *a += b;
        }
        self.weight_sum += other.weight_sum;
        self.samples += other.samples;
        self.rejected += other.rejected;
    }

    /// Counts a sample taken in this pixel whose radiance other calls share out (see
    /// [`crate::splat`]); returns whether it is accepted: finite and within
    /// [`crate::exact_sum::MAX_CONTRIBUTION`], as [`Self::add`] accepts a sample, else it
    /// is counted as dropped.
    #[inline]
    pub fn count(&mut self, radiance: Vec3) -> bool {
        self.samples += 1;
        // Each |channel| below the limit, 2⁴⁰ (exact in f32); NaN fails the comparison.
        let limit = crate::exact_sum::MAX_CONTRIBUTION as f32;
        let m = radiance.abs();
        let accepted = (m.x < limit) & (m.y < limit) & (m.z < limit);
        self.rejected += !accepted as u32;
        accepted
    }

    /// Adds `weight` × `radiance` and `weight` to the sums without counting a sample: a
    /// share of a sample counted elsewhere ([`Self::count`]), or [`Self::add`]'s own.
    /// Each term is rounded once, on its own (f32 × f32 is exact in f64), so the order in
    /// which contributions arrive does not change the sums. Returns false, adding
    /// nothing, where a term is not finite or beyond
    /// [`crate::exact_sum::MAX_CONTRIBUTION`]; an accepted sample's shares (weights at
    /// most 1) always fit.
    #[inline]
    pub fn add_weighted(&mut self, radiance: Vec3, weight: f32) -> bool {
        let w = weight as f64;
        let terms = [
            ExactSum::of(radiance.x as f64 * w),
            ExactSum::of(radiance.y as f64 * w),
            ExactSum::of(radiance.z as f64 * w),
            ExactSum::of(w),
        ];
        let [Some(r), Some(g), Some(b), Some(w)] = terms else {
            return false;
        };
        for (sum, t) in self.radiance_sum.iter_mut().zip([r, g, b]) {
            *sum += t;
        }
        self.weight_sum += w;
        true
    }

    /// The pixel's estimate: the weighted mean of its samples (black if none).
    pub fn value(&self) -> Vec3 {
        let w = self.weight_sum.to_f64();
        if w > 0.0 {
            let [r, g, b] = self.radiance_sum.map(|s| (s.to_f64() / w) as f32);
            Vec3::new(r, g, b)
        } else {
            Vec3::ZERO
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
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

    /// Adds a contribution with filter weight `weight` to pixel (`x`, `y`): a sample of
    /// its own or one splatted from a neighbour. The film does not depend on the order of
    /// the additions.
    pub fn add(&mut self, x: u32, y: u32, radiance: Vec3, weight: f32) {
        self.pixels[(y * self.width + x) as usize].add(radiance, weight);
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

    /// Values whose f64 sums depend on the order: the film's do not.
    #[test]
    fn merges_in_any_grouping_and_order_are_the_same_bits() {
        let values: Vec<f32> = (0..64)
            .map(|i| {
                let i = i as f32;
                (i * 0.731).sin().abs() * 10f32.powi((i as i32 % 13) - 6)
            })
            .collect();
        let film_of = |range: std::ops::Range<usize>| {
            let mut f = Film::new(1, 1);
            for &v in &values[range] {
                f.add(0, 0, Vec3::new(v, 0.5 * v, 3.0 * v), 0.75);
            }
            f
        };
        let whole = film_of(0..64);
        for cuts in [vec![32], vec![1], vec![5, 17, 40, 63], (1..64).collect()] {
            let mut bounds = vec![0];
            bounds.extend(&cuts);
            bounds.push(64);
            let parts: Vec<Film> = bounds.windows(2).map(|b| film_of(b[0]..b[1])).collect();
            let mut merged = Film::new(1, 1);
            for part in parts.iter().rev() {
                merged.merge(part);
            }
            assert_eq!(merged, whole, "split at {cuts:?}");
        }
        let sequential: f64 = values.iter().map(|&v| v as f64 * 0.75).sum();
        let reversed: f64 = values.iter().rev().map(|&v| v as f64 * 0.75).sum();
        assert_ne!(sequential, reversed, "the data must defeat plain f64 sums");
    }
}
