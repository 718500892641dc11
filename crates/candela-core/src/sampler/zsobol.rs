//! Screen-space blue-noise error: one Owen-scrambled Sobol' sequence for the whole image,
//! each pixel taking an aligned block of it at its (scrambled) Morton index. This is
//! Ahmed and Wonka's "Screen-space blue-noise diffusion of Monte Carlo sampling error via
//! hierarchical ordering of pixels" (SIGGRAPH Asia 2020) as pbrt-v4 ships it
//! (`ZSobolSampler`, *PBR* 4th ed., §8.7.7).
//!
//! **The sequence.** Sample `i` of pixel `p` of a render of n planned samples takes point
//! `π_d(z(p) · 2ᵏ + i)` of the first two Sobol' dimensions ([`super::sobol_2d`]), 2ᵏ the
//! planned count rounded up to a power of two and `z` the Morton (Z-order) index, for
//! every request `d` of the pixel sample, each coordinate then Owen-scrambled by a hash of
//! `(seed, d)` ([`super::owen_scramble`]). `π_d` permutes the base-4 digits of that
//! extended Morton index, each digit by one of the 24 permutations of {0, 1, 2, 3} that a
//! hash of `d` and the digits *above* it picks (a nested scramble in base 4; the lowest
//! bit alone, flipped by a hash, where the index has an odd number of bits). A digit is
//! the quadrant of a 2 × 2 block of pixels (or of sample indices), so `π_d` maps every
//! aligned 2ʲ × 2ʲ block of pixels onto an aligned block of 4ʲ · 2ᵏ indices.
//!
//! **What that buys.** An aligned block of 2ᵐ indices of a (0, 2)-sequence is a
//! (0, m, 2)-net, and Owen scrambling keeps nets. So each pixel's 2ᵏ samples are a net
//! (stratified as [`super::SobolSampler`]'s), *and* so is the union of the samples of
//! every aligned 2ʲ × 2ʲ block of pixels, for every 2D request. Neighbouring pixels then
//! sample different strata of every request: their estimates err in opposite directions,
//! and the image's error is blue noise (little power at low spatial frequencies), which
//! the eye and HDR-FLIP forgive and a denoiser removes more easily than white noise. The
//! per-pixel error (relMSE) is that of the Sobol' sampler: each pixel is still a net.
//!
//! **Why the permutations.** The identity order would give every request the same pixel
//! pairing (visible structure, Ahmed and Wonka's Fig. 4), and a padded request must not
//! repeat another's order: each request's digits are permuted by its own hashes, so two
//! requests of one pixel sample are as uncorrelated as the Sobol' sampler's padding makes
//! them. All 24 permutations are used (not the 8 a base-2 nested scramble reaches), so a
//! stratum pair may join horizontal, vertical or diagonal neighbours alike.
//!
//! **Limits, and what happens past them.**
//! - *Sample counts that are not powers of two*: the pixel owns a block of 2ᵏ indices and
//!   takes the first n of them, in the scrambled order of the low digits; its samples are
//!   then a union of smaller nets (as the Sobol' sampler's are), and the blocks of pixels
//!   lose part of their joint stratification (the 2ᵏ − n missing points). Still unbiased.
//! - *Sample indices at or past 2ᵏ* (a render extended by more passes): each further block
//!   of 2ᵏ indices (an *epoch*) is a fresh blue-noise set, the whole sequence rescrambled
//!   by a hash of the epoch, so a sample range `[a, b)` is drawn the same whatever the
//!   split and films of disjoint ranges add up.
//! - *Index bits*: the extended index is 32 bits (the Sobol' tables' width), so the
//!   pixel part covers tiles of 2ᵗ × 2ᵗ pixels, t = ⌊(32 − k)/2⌋ (4096² at 256 spp, 1024²
//!   at 4096 spp); a larger image is cut into such tiles, each rescrambled by a hash of its
//!   position (errors blue within a tile, independent across tiles).
//! - *Dimensions*: unbounded, as the Sobol' sampler's: every request is a new hash, not a
//!   new table column.
//!
//! Deterministic per (seed, pixel, sample index, request) like every sampler here, so the
//! image does not depend on the thread count. The samples of different pixels are not
//! independent (that is the point), but each number is uniform on [0, 1).

use glam::{UVec2, Vec2};

use super::sobol::to_unit;
use super::{mix64, owen_scramble, sobol_2d, Sampler};

/// The 24 permutations of a base-4 digit, in lexicographic order.
const PERMUTATIONS: [[u8; 4]; 24] = {
    let mut table = [[0u8; 4]; 24];
    let mut n = 0;
    let mut a = 0;
    while a < 4 {
        let mut b = 0;
        while b < 4 {
            let mut c = 0;
            while c < 4 {
                let d = 6 - a - b - c;
                if a != b && a != c && b != c {
                    table[n] = [a as u8, b as u8, c as u8, d as u8];
                    n += 1;
                }
                c += 1;
            }
            b += 1;
        }
        a += 1;
    }
    table
};

/// ⌈log₂ n⌉ (0 for n ≤ 1).
fn ceil_log2(n: u32) -> u32 {
    n.max(1).next_power_of_two().trailing_zeros()
}

/// Interleaves the low 16 bits of `x` (even bits) and `y` (odd bits): the Morton index.
fn morton_2d(x: u32, y: u32) -> u32 {
    fn spread(v: u32) -> u32 {
        let mut v = v & 0xffff;
        v = (v | (v << 8)) & 0x00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333;
        (v | (v << 1)) & 0x5555_5555
    }
    spread(x) | (spread(y) << 1)
}

/// Blue-noise-ordered Owen-scrambled Sobol' points (see the module docs).
#[derive(Clone, Debug)]
pub struct ZSobolSampler {
    seed: u64,
    /// k: log₂ of the planned sample count rounded up to a power of two.
    log2_spp: u32,
    /// t: pixel bits per axis in the extended index (tiles of 2ᵗ × 2ᵗ pixels).
    pixel_bits: u32,
    /// Bits of the extended index, 2t + k ≤ 32.
    index_bits: u32,
    /// The current pixel sample's extended index z(p mod 2ᵗ) · 2ᵏ + (i mod 2ᵏ).
    extended: u32,
    /// Hash of (seed, tile, epoch) of the current pixel sample: every request's key.
    sample_key: u64,
    /// Requests taken so far in this pixel sample (a 2D request counts two).
    dimension: u32,
}

impl ZSobolSampler {
    /// A sampler for renders of `spp` planned samples per pixel of a `width` × `height`
    /// image.
    pub fn new(seed: u64, spp: u32, width: u32, height: u32) -> Self {
        let log2_spp = ceil_log2(spp);
        let pixel_bits = ceil_log2(width.max(height)).min((32 - log2_spp) / 2);
        ZSobolSampler {
            seed,
            log2_spp,
            pixel_bits,
            index_bits: 2 * pixel_bits + log2_spp,
            extended: 0,
            sample_key: 0,
            dimension: 0,
        }
    }

    /// The extended index of the current pixel sample with its base-4 digits permuted for
    /// the request whose key is `key` (see the module docs).
    #[inline]
    fn permuted_index(&self, key: u64) -> u32 {
        let m = self.extended as u64;
        let odd = self.index_bits & 1;
        let mut out = 0u64;
        // Digits from the most significant down; each one's permutation is picked by the
        // digits above it (unpermuted) and its position, so the scramble is nested.
        let mut shift = self.index_bits;
        while shift >= 2 + odd {
            shift -= 2;
            let digit = (m >> shift) & 3;
            let higher = m >> (shift + 2);
            let h = mix64(key ^ higher ^ ((shift as u64) << 56));
            let p = (((h >> 32) * 24) >> 32) as usize;
            out |= (PERMUTATIONS[p][digit as usize] as u64) << shift;
        }
        if odd == 1 {
            let h = mix64(key ^ (m >> 1) ^ (63u64 << 56));
            out |= (m & 1) ^ (h >> 63);
        }
        out as u32
    }

    /// The key of the request at `dimension` of the current pixel sample.
    #[inline]
    fn request_key(&self, dimension: u32) -> u64 {
        const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;
        mix64(
            self.sample_key
                .wrapping_add((dimension as u64 + 1).wrapping_mul(GOLDEN)),
        )
    }

    /// The 1D number of the request at `dimension`.
    #[inline]
    fn number_1d(&self, dimension: u32) -> f32 {
        let key = self.request_key(dimension);
        let (x, _) = sobol_2d(self.permuted_index(key));
        to_unit(owen_scramble(x, (key >> 32) as u32))
    }
}

impl Sampler for ZSobolSampler {
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        let low = |v: u32| v & ((1u32 << self.pixel_bits) - 1);
        let (epoch, in_block) = if self.log2_spp == 32 {
            (0, index)
        } else {
            (
                index >> self.log2_spp,
                index & ((1u32 << self.log2_spp) - 1),
            )
        };
        let z = morton_2d(low(pixel.x), low(pixel.y)) as u64;
        self.extended = ((z << self.log2_spp) | in_block as u64) as u32;
        let tile =
            ((pixel.x >> self.pixel_bits) as u64) << 32 | (pixel.y >> self.pixel_bits) as u64;
        self.sample_key = mix64(mix64(self.seed ^ mix64(tile)) ^ epoch as u64);
        self.dimension = 0;
    }

    #[inline]
    fn get_1d(&mut self) -> f32 {
        self.dimension += 1;
        self.number_1d(self.dimension - 1)
    }

    #[inline]
    fn skip_1d(&mut self) {
        self.dimension += 1;
    }

    #[inline]
    fn get_2d(&mut self) -> Vec2 {
        let key = self.request_key(self.dimension);
        self.dimension += 2;
        let (x, y) = sobol_2d(self.permuted_index(key));
        Vec2::new(
            to_unit(owen_scramble(x, (key >> 32) as u32)),
            to_unit(owen_scramble(y, key as u32)),
        )
    }

    /// The request's dimension: the pixel sample's index and key are still the sampler's
    /// when it is resolved.
    type Deferred1d = u32;

    #[inline]
    fn defer_1d(&mut self) -> u32 {
        self.dimension += 1;
        self.dimension - 1
    }

    #[inline]
    fn resolve_1d(&self, dimension: u32) -> f32 {
        self.number_1d(dimension)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_permutation_table_holds_each_permutation_once() {
        let mut seen = std::collections::HashSet::new();
        for p in PERMUTATIONS {
            let mut sorted = p;
            sorted.sort();
            assert_eq!(sorted, [0, 1, 2, 3]);
            assert!(seen.insert(p));
        }
        assert_eq!(seen.len(), 24);
    }

    #[test]
    fn morton_interleaves_x_in_even_bits() {
        assert_eq!(morton_2d(1, 0), 1);
        assert_eq!(morton_2d(0, 1), 2);
        assert_eq!(morton_2d(3, 3), 15);
        assert_eq!(morton_2d(0xffff, 0), 0x5555_5555);
        assert_eq!(morton_2d(5, 9), 0b1001_0011);
    }

    #[test]
    fn the_digit_permutation_is_a_bijection_of_the_extended_index() {
        // For every request key, pi_d maps the 2^bits extended indices one to one: each
        // (pixel, sample) gets a point of its own, none repeated. Odd and even bit counts.
        for (spp, res) in [(4u32, 8u32), (8, 8), (2, 16), (1, 32), (12, 4)] {
            let mut s = ZSobolSampler::new(5, spp, res, res);
            let n = 1usize << s.index_bits;
            for key in [0u64, 1, 0xdead_beef_1234_5678] {
                let mut seen = vec![false; n];
                for e in 0..n as u32 {
                    s.extended = e;
                    let p = s.permuted_index(key) as usize;
                    assert!(p < n && !std::mem::replace(&mut seen[p], true));
                }
            }
        }
    }

    #[test]
    fn aligned_pixel_blocks_map_onto_aligned_index_blocks() {
        // The 2^j x 2^j pixel block at (bx, by) with all its samples must occupy one
        // aligned block of 4^j * 2^k permuted indices, for every request.
        let (spp, res) = (8u32, 32u32);
        let mut s = ZSobolSampler::new(1, spp, res, res);
        for j in 0..=5u32 {
            let side = 1u32 << j;
            let block = (side * side * spp) as u64;
            for (bx, by) in [(0u32, 0u32), (side, 0), (0, side), (3 * side, 2 * side)] {
                if bx + side > res || by + side > res {
                    continue;
                }
                for d in [0u32, 3, 17] {
                    let mut first = None;
                    for y in by..by + side {
                        for x in bx..bx + side {
                            for i in 0..spp {
                                s.start_pixel_sample(UVec2::new(x, y), i);
                                let b = s.permuted_index(s.request_key(d)) as u64 / block;
                                assert_eq!(*first.get_or_insert(b), b, "j {j}, d {d}");
                            }
                        }
                    }
                }
            }
        }
    }
}
