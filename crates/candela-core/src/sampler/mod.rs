//! Sample streams. Each pixel sample gets its own deterministic stream, derived from
//! (seed, pixel, sample index) alone, so an image does not depend on the thread count or
//! on the order in which tiles are rendered.
//!
//! Each pixel sample starts with the position in the pixel (2D) and, for a camera with a
//! thin lens only, the lens point (2D). Then, per bounce, the integrator takes its
//! dimensions in a fixed order: light pick (1D), light point (2D), BSDF lobe (1D), BSDF
//! direction (2D), Russian roulette (1D). A low-discrepancy sampler can rely on that order.
//!
//! Five samplers: [`IndependentSampler`] (uniform random numbers), [`SobolSampler`]
//! (Owen-scrambled Sobol' points, stratified within each pixel), [`ZSobolSampler`] (one
//! Sobol' sequence for the whole image in a scrambled Morton order of the pixels, so that
//! neighbouring pixels are stratified together and the error is blue noise),
//! [`SobolCmjSampler`] (the Sobol' sampler's numbers except for the first bounce's BSDF
//! direction, which a correlated multi-jittered pattern gives; that request sits at
//! [`first_direction_dimension`] in the order above) and [`CmjSampler`] (correlated
//! multi-jittered points for every request, for the study in `bench/sampler.sh`; the
//! renderer does not offer it).
//! The integrator picks one by [`crate::desc::SamplerKind`] and is monomorphized for each,
//! so no call is dynamic.
//!
//! The lanes integrator may take a bounce's numbers for eight streams at once
//! ([`Sampler::draw_bounce_lanes`]): the independent sampler does so in AVX2
//! (`pcg_lanes`), the others one stream at a time.

mod cmj;
#[cfg(target_arch = "x86_64")]
mod pcg_lanes;
mod sobol;
mod sobol_cmj;
mod zsobol;

use glam::{UVec2, Vec2};

pub use cmj::CmjSampler;
pub use sobol::{owen_scramble, sobol_2d, SobolSampler};
pub use sobol_cmj::{first_direction_dimension, SobolCmjSampler};
pub use zsobol::ZSobolSampler;

/// Streams a batched draw serves at once ([`Sampler::draw_bounce_lanes`]): the lanes
/// integrator's paths in flight.
pub const LANES: usize = 8;

/// One bounce's numbers for [`LANES`] streams, in the order the integrator takes them
/// (light pick, light point, BSDF lobe, BSDF direction, Russian roulette): entry `[i]` (or
/// `[k][i]` for the two coordinates of a 2D request) is stream `i`'s.
pub struct BounceDraws<D> {
    pub light: [f32; LANES],
    pub point: [[f32; LANES]; 2],
    pub lobe: [D; LANES],
    pub dir: [[f32; LANES]; 2],
    pub roulette: [f32; LANES],
}

/// A source of uniform numbers in [0, 1) for one pixel sample at a time.
pub trait Sampler: Send + Sync + Clone {
    /// Positions the stream at sample `index` of `pixel`.
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32);
    fn get_1d(&mut self) -> f32;
    fn get_2d(&mut self) -> Vec2;
    /// Passes over the next 1D request without computing it: the requests after it are
    /// those that would have followed [`Self::get_1d`], so a consumer that does not need a
    /// number (one light to pick, a one-lobe BSDF) keeps every later dimension in place.
    fn skip_1d(&mut self) {
        self.get_1d();
    }
    /// The sample's position inside its pixel.
    fn get_pixel_2d(&mut self) -> Vec2 {
        self.get_2d()
    }
    /// What [`Self::defer_1d`] keeps.
    type Deferred1d: Copy;
    /// Takes the next 1D request's place, like [`Self::skip_1d`], but keeps what
    /// [`Self::resolve_1d`] needs to compute it later in the same pixel sample, where it
    /// equals what [`Self::get_1d`] would have returned here: for a number that only some
    /// consumers read (a BSDF's lobe choice, before the hit says which BSDF).
    fn defer_1d(&mut self) -> Self::Deferred1d;
    /// The value of a request [`Self::defer_1d`] deferred in the current pixel sample.
    fn resolve_1d(&self, d: Self::Deferred1d) -> f32;
    /// One bounce's requests (see [`BounceDraws`]) of each of `streams` at once, as
    /// `get_1d`, `get_2d`, `defer_1d`, `get_2d`, `get_1d` would give them one stream at a
    /// time (a request the caller would skip is drawn all the same: it takes its place
    /// either way); `None`, with the streams untouched, where the sampler has no batched
    /// draw. `avx2`: whether the caller runs where the CPU has AVX2.
    fn draw_bounce_lanes(
        streams: &mut [Self; LANES],
        avx2: bool,
    ) -> Option<BounceDraws<Self::Deferred1d>> {
        let _ = (streams, avx2);
        None
    }
}

/// Independent uniform random numbers from PCG32 (O'Neill 2014), one stream per pixel
/// sample.
#[derive(Clone, Debug)]
pub struct IndependentSampler {
    seed: u64,
    rng: Pcg32,
}

impl IndependentSampler {
    pub fn new(seed: u64) -> Self {
        IndependentSampler {
            seed,
            rng: Pcg32::new(seed, 0),
        }
    }
}

impl Sampler for IndependentSampler {
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        let key = mix64(((pixel.x as u64) << 32) | pixel.y as u64);
        self.rng = Pcg32::new(
            mix64(self.seed ^ key),
            mix64(key.wrapping_add(index as u64)),
        );
    }

    fn get_1d(&mut self) -> f32 {
        self.rng.uniform_f32()
    }

    fn get_2d(&mut self) -> Vec2 {
        let x = self.rng.uniform_f32();
        Vec2::new(x, self.rng.uniform_f32())
    }

    fn skip_1d(&mut self) {
        self.rng.next_u32();
    }

    /// The generator's state before the deferred step: the stream steps past the request
    /// now (one multiply-add) and only a request that is read pays for the output
    /// permutation and the conversion.
    type Deferred1d = u64;

    fn defer_1d(&mut self) -> u64 {
        self.rng.step()
    }

    fn resolve_1d(&self, old: u64) -> f32 {
        Pcg32::uniform_of(Pcg32::output(old))
    }

    /// PCG32 for the eight streams at once in AVX2 (`pcg_lanes`); none without AVX2.
    fn draw_bounce_lanes(streams: &mut [Self; LANES], avx2: bool) -> Option<BounceDraws<u64>> {
        #[cfg(target_arch = "x86_64")]
        if avx2 {
            // SAFETY: `avx2` says the CPU has AVX2.
            let ([light, px, py, _, dx, dy, roulette], lobe) =
                unsafe { pcg_lanes::uniform_lanes::<7>(streams, 3) };
            return Some(BounceDraws {
                light,
                point: [px, py],
                lobe,
                dir: [dx, dy],
                roulette,
            });
        }
        let _ = (streams, avx2);
        None
    }
}

/// PCG32: 64-bit LCG state with a xorshift-rotate output permutation.
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

impl Pcg32 {
    const MULT: u64 = 0x5851_f42d_4c95_7f2d;

    /// A generator on stream `sequence` starting from `seed`.
    pub fn new(seed: u64, sequence: u64) -> Pcg32 {
        let mut rng = Pcg32 {
            state: 0,
            inc: (sequence << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    pub fn next_u32(&mut self) -> u32 {
        Self::output(self.step())
    }

    /// Advances the state; returns the state before, whose [`Self::output`] is this
    /// step's number.
    #[inline]
    pub fn step(&mut self) -> u64 {
        let old = self.state;
        self.state = old.wrapping_mul(Self::MULT).wrapping_add(self.inc);
        old
    }

    /// The output permutation (xorshift, random rotation) of the state before a step.
    #[inline]
    pub fn output(old: u64) -> u32 {
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// A uniform float in [0, 1), with 24 bits of randomness.
    pub fn uniform_f32(&mut self) -> f32 {
        Self::uniform_of(self.next_u32())
    }

    /// [`Self::uniform_f32`] of an output.
    #[inline]
    pub fn uniform_of(word: u32) -> f32 {
        (word >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }
}

/// A 64-bit finalizer (splitmix64), used to turn structured keys into seeds.
pub fn mix64(mut v: u64) -> u64 {
    v = v.wrapping_add(0x9e37_79b9_7f4a_7c15);
    v = (v ^ (v >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    v = (v ^ (v >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    v ^ (v >> 31)
}

/// A uniform number in [0, 1) fixed by a key and some floats (splitmix64 over their
/// bits): the same inputs always give the same number.
pub fn hash_uniform(key: u64, values: &[f32]) -> f32 {
    let mut h = mix64(key);
    for v in values {
        h = mix64(h ^ v.to_bits() as u64);
    }
    (h >> 40) as f32 / (1u64 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let mut a = IndependentSampler::new(7);
        let mut b = IndependentSampler::new(7);
        a.start_pixel_sample(UVec2::new(3, 4), 5);
        b.start_pixel_sample(UVec2::new(3, 4), 5);
        let xa: Vec<f32> = (0..8).map(|_| a.get_1d()).collect();
        let xb: Vec<f32> = (0..8).map(|_| b.get_1d()).collect();
        assert_eq!(xa, xb);
        b.start_pixel_sample(UVec2::new(3, 4), 6);
        let xc: Vec<f32> = (0..8).map(|_| b.get_1d()).collect();
        assert_ne!(xa, xc);
        b.start_pixel_sample(UVec2::new(4, 3), 5);
        let xd: Vec<f32> = (0..8).map(|_| b.get_1d()).collect();
        assert_ne!(xa, xd);
    }

    /// After `skip_1d` every later request equals what it is after `get_1d`.
    fn skipping_keeps_later_requests<S: Sampler>(mut a: S, mut b: S) {
        for index in 0..4 {
            a.start_pixel_sample(UVec2::new(5, 6), index);
            b.start_pixel_sample(UVec2::new(5, 6), index);
            let _ = (a.get_2d(), b.get_2d());
            a.get_1d();
            b.skip_1d();
            assert_eq!(a.get_2d(), b.get_2d());
            assert_eq!(a.get_1d(), b.get_1d());
        }
    }

    #[test]
    fn skipping_a_request_keeps_the_later_ones_in_place() {
        skipping_keeps_later_requests(IndependentSampler::new(3), IndependentSampler::new(3));
        skipping_keeps_later_requests(SobolSampler::new(3), SobolSampler::new(3));
    }

    /// A deferred request resolves, after later requests, to what `get_1d` gives in its
    /// place, and the requests after it are those after `get_1d`.
    fn deferring_equals_drawing<S: Sampler>(mut a: S, mut b: S) {
        for index in 0..4 {
            a.start_pixel_sample(UVec2::new(5, 6), index);
            b.start_pixel_sample(UVec2::new(5, 6), index);
            let _ = (a.get_2d(), b.get_2d());
            let want = a.get_1d();
            let d = b.defer_1d();
            assert_eq!(a.get_2d(), b.get_2d());
            assert_eq!(a.get_1d(), b.get_1d());
            assert_eq!(b.resolve_1d(d), want);
        }
    }

    #[test]
    fn a_deferred_request_is_the_one_drawn_in_its_place() {
        deferring_equals_drawing(IndependentSampler::new(3), IndependentSampler::new(3));
        deferring_equals_drawing(SobolSampler::new(3), SobolSampler::new(3));
    }

    #[test]
    fn uniform_values_stay_below_one() {
        let mut r = Pcg32::new(1, 2);
        let mut mean = 0.0f64;
        for _ in 0..100_000 {
            let u = r.uniform_f32();
            assert!((0.0..1.0).contains(&u));
            mean += u as f64;
        }
        mean /= 100_000.0;
        // Standard error of the mean of U(0,1) at n = 1e5 is 0.00091; 5 sigma.
        assert!((mean - 0.5).abs() < 0.0046, "mean {mean}");
    }
}
