//! Owen-scrambled Sobol' points, padded per dimension: each 1D or 2D request of a pixel
//! sample draws from the first two dimensions of the Sobol' sequence (a (0, 2)-sequence in
//! base 2), through its own random shuffle of the sample index and its own nested uniform
//! (Owen) scramble of the coordinates. This is Burley's "shuffled scrambled Sobol'"
//! (B. Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020) and pbrt-v4's
//! `PaddedSobolSampler` (Pharr, Jakob, Humphreys, *PBR* 4th ed., §8.7).
//!
//! What that buys, for the samples of one pixel:
//!
//! - **Stratification.** The first 2ᵏ samples of every 2D request form a (0, k, 2)-net:
//!   exactly one point in every elementary interval of area 2⁻ᵏ (every 2ᵃ × 2ᵇ grid of
//!   boxes with a + b = k), so in particular exactly one in each of the 2ᵏ intervals of
//!   each coordinate. The same holds for any aligned block [j·2ᵏ, (j+1)·2ᵏ) of sample
//!   indices, which is why a render split into sample ranges stays stratified.
//! - **Any sample count.** Nothing depends on the number of samples per pixel. For a count
//!   n that is not a power of two, the indices 0..n split into aligned blocks by the binary
//!   digits of n (12 = 8 + 4), and each block is a net of its own size: stratification is
//!   that of the largest block, the rest adds well-spread points but no finer strata.
//! - **Unbiasedness.** An Owen-scrambled point is uniform on the unit square, so every
//!   sample is a uniform sample, as with the independent sampler.
//! - **Padding.** Every request (dimension index) of every pixel gets its own hashes, so
//!   two requests are uncorrelated (as far as the hash is random) and pixels are
//!   independent of one another, which the per-pixel statistics of the tests rely on. Only
//!   within one 2D request are the two coordinates jointly stratified (the pairs the
//!   integrator takes together: pixel position, lens point, light point, BSDF direction).
//!
//! Why the shuffle keeps the nets: a nested scramble of the index (bit-reversed, so that
//! each bit is flipped by a hash of the bits *above* it) maps every aligned block of 2ᵏ
//! indices onto another aligned block, and any aligned block of a (0, 2)-sequence is a
//! (0, k, 2)-net; scrambling the coordinates preserves nets (Owen 1995).

use glam::{UVec2, Vec2};

use super::{mix64, Sampler};

/// Generator matrix of the second Sobol' dimension, one column per index bit: the
/// direction numbers of the primitive polynomial x + 1 (Joe and Kuo's dimension 2:
/// s = 1, a = 0, m₁ = 1), mᵢ = 2mᵢ₋₁ ⊕ mᵢ₋₁, column i = mᵢ₊₁ · 2^(31−i). (The first
/// dimension is the van der Corput sequence, the identity matrix, a bit reversal.)
const SOBOL_DIM1: [u32; 32] = {
    let mut c = [0u32; 32];
    let mut m: u64 = 1;
    let mut i = 0;
    while i < 32 {
        c[i] = (m << (31 - i)) as u32;
        m ^= m << 1;
        i += 1;
    }
    c
};

/// The second dimension's matrix by bytes of the *bit-reversed* index:
/// `SOBOL_DIM1_BY_REVERSED[k][b]` is the point of index `(b << 8k).reverse_bits()`, so the
/// point of index `i` is four lookups xored on the bytes of `i.reverse_bits()` (instead
/// of a loop over the index's set bits), which is what the sampler's shuffle yields
/// before its reversal.
const SOBOL_DIM1_BY_REVERSED: [[u32; 256]; 4] = {
    let mut t = [[0u32; 256]; 4];
    let mut k = 0;
    while k < 4 {
        let mut b = 0;
        while b < 256 {
            let mut v = 0u32;
            let mut j = 0;
            while j < 8 {
                // Bit 8k + j of the reversed index is bit 31 − 8k − j of the index.
                if b & (1 << j) != 0 {
                    v ^= SOBOL_DIM1[31 - (8 * k + j)];
                }
                j += 1;
            }
            t[k][b] = v;
            b += 1;
        }
        k += 1;
    }
    t
};

/// Point `index` of the first two Sobol' dimensions, as 32-bit fractions.
pub fn sobol_2d(index: u32) -> (u32, u32) {
    let reversed = index.reverse_bits();
    (reversed, sobol_dim1_of_reversed(reversed))
}

/// The second coordinate of point `reversed.reverse_bits()` (not reversed).
#[inline]
fn sobol_dim1_of_reversed(reversed: u32) -> u32 {
    let b = reversed.to_le_bytes();
    SOBOL_DIM1_BY_REVERSED[0][b[0] as usize]
        ^ SOBOL_DIM1_BY_REVERSED[1][b[1] as usize]
        ^ SOBOL_DIM1_BY_REVERSED[2][b[2] as usize]
        ^ SOBOL_DIM1_BY_REVERSED[3][b[3] as usize]
}

/// A nested uniform (Owen) scramble of a 32-bit fraction by a hash: each bit is flipped by
/// a function of `seed` and the bits above it (pbrt-v4's `FastOwenScrambler`, after
/// Laine and Karras 2011 and Burley 2020). In bit-reversed order every step (adding the
/// seed, multiplying by an odd number, xor with a multiple by an even number) changes a
/// bit only as a function of the bits below it, so the whole is a nested scramble: it
/// maps each dyadic interval of length 2⁻ᵏ onto another.
pub fn owen_scramble(v: u32, seed: u32) -> u32 {
    scramble_reversed(v.reverse_bits(), seed).reverse_bits()
}

/// [`owen_scramble`] on bit-reversed input and output (the sampler keeps values reversed
/// where it can, to save reversals).
#[inline]
pub(super) fn scramble_reversed(v: u32, seed: u32) -> u32 {
    scramble_premixed(premix(v), seed)
}

/// The first step of [`scramble_reversed`], the one that does not depend on the seed: the
/// sampler takes it once per pixel sample for the index that every request shuffles.
#[inline(always)]
fn premix(v: u32) -> u32 {
    v ^ v.wrapping_mul(0x3d20_adea)
}

/// The rest of [`scramble_reversed`], from the output of [`premix`].
#[inline(always)]
fn scramble_premixed(mut v: u32, seed: u32) -> u32 {
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6c56);
    v ^= v.wrapping_mul(0x53a2_2864);
    v
}

/// The top 24 bits of a fraction as a float in [0, 1), exactly.
#[inline]
pub(super) fn to_unit(v: u32) -> f32 {
    (v >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Owen-scrambled, shuffled Sobol' points per pixel (see the module docs). Deterministic
/// per (seed, pixel, sample index, request), like [`super::IndependentSampler`].
#[derive(Clone, Debug)]
pub struct SobolSampler {
    seed: u64,
    /// Hash of (seed, pixel) for the current pixel sample.
    pixel_key: u64,
    /// [`premix`] of the sample index bit-reversed: the seed-independent first step of
    /// every request's shuffle, taken once per pixel sample.
    index_premixed: u32,
    /// Requests taken so far in this pixel sample (a 2D request counts two).
    dimension: u32,
}

impl SobolSampler {
    pub fn new(seed: u64) -> Self {
        SobolSampler {
            seed,
            pixel_key: 0,
            index_premixed: 0,
            dimension: 0,
        }
    }

    /// The next request's shuffled index `owen_scramble(index, low half of the hash)`,
    /// bit-reversed, and its hash (splitmix64's sequence from the pixel's key).
    #[inline]
    fn next_request(&mut self, width: u32) -> (u32, u64) {
        let r = self.request_at(self.dimension);
        self.dimension += width;
        r
    }

    /// [`Self::next_request`] of the request at `dimension`.
    #[inline(always)]
    fn request_at(&self, dimension: u32) -> (u32, u64) {
        const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;
        let h = mix64(
            self.pixel_key
                .wrapping_add((dimension as u64).wrapping_mul(GOLDEN)),
        );
        (scramble_premixed(self.index_premixed, h as u32), h)
    }

    /// Requests taken so far in the current pixel sample (a 2D request counts two).
    #[inline(always)]
    pub(super) fn dimension(&self) -> u32 {
        self.dimension
    }

    /// The current pixel's hash of (seed, pixel), from which every request's is derived.
    #[inline(always)]
    pub(super) fn pixel_key(&self) -> u64 {
        self.pixel_key
    }

    /// The 1D number of request `(i_reversed, h)`.
    #[inline(always)]
    fn number_1d((i_reversed, h): (u32, u64)) -> f32 {
        // The first coordinate of point i is reverse(i); its scramble works on reverse of
        // that, i itself.
        let i = i_reversed.reverse_bits();
        to_unit(scramble_reversed(i, (h >> 32) as u32).reverse_bits())
    }
}

/// The third 32-bit seed of a 2D request from its 64-bit hash: the high half of an odd
/// multiple (a multiply is cheaper than a second finalizer, and the hash is already mixed).
#[inline]
fn y_seed(h: u64) -> u32 {
    (h.wrapping_mul(0xd134_2543_de82_ef95) >> 32) as u32
}

impl Sampler for SobolSampler {
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        let key = ((pixel.x as u64) << 32) | pixel.y as u64;
        self.pixel_key = mix64(self.seed ^ mix64(key));
        self.index_premixed = premix(index.reverse_bits());
        self.dimension = 0;
    }

    #[inline]
    fn get_1d(&mut self) -> f32 {
        Self::number_1d(self.next_request(1))
    }

    #[inline]
    fn skip_1d(&mut self) {
        self.dimension += 1;
    }

    /// The request's dimension: the pixel sample's key and index are still the sampler's
    /// when it is resolved.
    type Deferred1d = u32;

    #[inline]
    fn defer_1d(&mut self) -> u32 {
        self.dimension += 1;
        self.dimension - 1
    }

    #[inline]
    fn resolve_1d(&self, dimension: u32) -> f32 {
        Self::number_1d(self.request_at(dimension))
    }

    #[inline]
    fn get_2d(&mut self) -> Vec2 {
        let (i_reversed, h) = self.next_request(2);
        // The point's coordinates bit-reversed, which the scrambles take: reverse(i)'s
        // reversal, i, and the second coordinate's. Both come from the shuffled index
        // before its reversal and are reversed together (one vector op in the v3 loop).
        let x_in = i_reversed.reverse_bits();
        let y_in = sobol_dim1_of_reversed(i_reversed).reverse_bits();
        let x = scramble_reversed(x_in, (h >> 32) as u32);
        let y = scramble_reversed(y_in, y_seed(h));
        Vec2::new(to_unit(x.reverse_bits()), to_unit(y.reverse_bits()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_sobol_points_match_the_published_sequence() {
        // Joe–Kuo dimension 2: direction numbers m = 1, 3, 5, 15, 17, 51; in index order
        // (not the Gray-code order of Antonov–Saleev) the points are
        // 0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8.
        let m: Vec<u32> = (0..6).map(|i| SOBOL_DIM1[i] >> (31 - i)).collect();
        assert_eq!(m, [1, 3, 5, 15, 17, 51]);
        let y: Vec<f64> = (0..8)
            .map(|i| sobol_2d(i).1 as f64 / 4294967296.0)
            .collect();
        assert_eq!(y, [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875]);
        let x: Vec<f64> = (0..4)
            .map(|i| sobol_2d(i).0 as f64 / 4294967296.0)
            .collect();
        assert_eq!(x, [0.0, 0.5, 0.25, 0.75]);
    }

    #[test]
    fn owen_scramble_maps_dyadic_intervals_onto_dyadic_intervals() {
        // For every k, values sharing their top k bits are scrambled to values sharing
        // their top k bits: the defining property of a nested scramble.
        let mut rng = super::super::Pcg32::new(3, 9);
        for _ in 0..2000 {
            let (a, seed) = (rng.next_u32(), rng.next_u32());
            let k = rng.next_u32() % 32;
            let mask = if k == 0 { 0 } else { !0u32 << (32 - k) };
            let b = (a & mask) | (rng.next_u32() & !mask);
            let (sa, sb) = (owen_scramble(a, seed), owen_scramble(b, seed));
            assert_eq!(sa & mask, sb & mask, "k = {k}");
        }
    }

    #[test]
    fn table_lookup_equals_the_generator_matrix() {
        let mut rng = super::super::Pcg32::new(1, 2);
        for i in (0..4096).chain((0..4096).map(|_| rng.next_u32())) {
            let mut y = 0u32;
            for (bit, column) in SOBOL_DIM1.iter().enumerate() {
                if i & (1 << bit) != 0 {
                    y ^= column;
                }
            }
            assert_eq!(sobol_2d(i).1, y, "index {i}");
        }
    }

    #[test]
    fn the_sampler_is_the_documented_composition() {
        // 2D request d of sample i: shuffle i, take Sobol' point, scramble each coordinate.
        let mut s = SobolSampler::new(3);
        s.start_pixel_sample(UVec2::new(8, 9), 37);
        let key = s.pixel_key;
        s.get_1d();
        let got = s.get_2d();
        let h = mix64(key.wrapping_add(0x9e37_79b9_7f4a_7c15));
        let (x, y) = sobol_2d(owen_scramble(37, h as u32));
        let want = Vec2::new(
            to_unit(owen_scramble(x, (h >> 32) as u32)),
            to_unit(owen_scramble(y, y_seed(h))),
        );
        assert_eq!(got, want);
    }

    #[test]
    fn streams_are_reproducible() {
        let mut a = SobolSampler::new(7);
        let mut b = SobolSampler::new(7);
        a.start_pixel_sample(UVec2::new(3, 4), 5);
        b.start_pixel_sample(UVec2::new(3, 4), 5);
        let xa: Vec<f32> = (0..8).map(|_| a.get_1d()).collect();
        let xb: Vec<f32> = (0..8).map(|_| b.get_1d()).collect();
        assert_eq!(xa, xb);
        b.start_pixel_sample(UVec2::new(4, 3), 5);
        let xd: Vec<f32> = (0..8).map(|_| b.get_1d()).collect();
        assert_ne!(xa, xd);
    }
}
