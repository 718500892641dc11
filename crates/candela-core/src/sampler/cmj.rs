//! Correlated multi-jittered points, padded per request (A. Kensler, "Correlated
//! Multi-Jittered Sampling", Pixar Technical Memo 13-01, 2013). For a pixel's `n` samples,
//! `n = m × q` with `m` the largest divisor of `n` not above √n, every 2D request is a
//! multi-jittered pattern: one point in each cell of the `m × q` grid and one in each of
//! the `n` columns and `n` rows of the fine grid, its sub-cell offsets permuted alike in
//! every column (and every row), the "correlated" part that spreads the points evenly.
//! Every 1D request is jittered: one number in each of the `n` intervals of length 1/n.
//!
//! Padding: each request of each pixel has its own pattern seed (a hash of the seed, the
//! pixel and the request), which both permutes the pattern's cells and shuffles which
//! sample index gets which point, so requests are uncorrelated, as in [`super::SobolSampler`].
//! Each point is uniform on the unit square over the seeds, so every sample is unbiased.
//!
//! The pattern needs the sample count (at most 2²⁰). Sample indices at or beyond it (a
//! render extended by more passes) start new patterns of the same size, one per block of
//! `n` indices with seeds of their own: each block is stratified by itself, and their
//! union no better than a union of independent patterns.
//!
//! [`super::SobolCmjSampler`] takes one request of each pixel sample from this pattern.

use glam::{UVec2, Vec2};

use super::sobol::scramble_reversed;
use super::{mix64, Sampler};

/// The bits of numbers below `l`: the mask of [`permute`]'s cycle walk (0 for l ≤ 1).
const fn mask(l: u32) -> u32 {
    if l <= 1 {
        0
    } else {
        u32::MAX >> (l - 1).leading_zeros()
    }
}

/// Kensler's `permute`: a hash-keyed pseudo-random permutation of 0..l, evaluated at `i`,
/// by cycle-walking a bijective hash over the next power of two; `w = mask(l)`, computed
/// once per pattern. For a power of two (`l = w + 1`, every size the grids of 4ᵏ spp
/// have) the hash's first value is already below `l`, so the walk ends at once and the
/// final `% l` is a mask: that case costs no division.
#[inline(always)]
fn permute(mut i: u32, l: u32, w: u32, p: u32) -> u32 {
    if l <= 1 {
        return 0;
    }
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < l {
            break;
        }
    }
    if l == w.wrapping_add(1) {
        i.wrapping_add(p) & w
    } else {
        i.wrapping_add(p) % l
    }
}

/// A hash-keyed permutation of 0..l, `w = mask(l)`: for a power of two the Laine–Karras
/// hash restricted to the low bits (each step changes a bit only as a function of the bits
/// below it, so the low bits alone are a bijection), five operations; otherwise
/// [`permute`]. For a uniform seed each value is uniform: the seed is added to the low
/// bits, and the multiplier comes from the seed's high half.
#[inline(always)]
fn fast_permute(v: u32, l: u32, w: u32, seed: u32) -> u32 {
    if l == w.wrapping_add(1) {
        lk_permute(v, w, seed)
    } else {
        permute(v, l, w, seed)
    }
}

/// The Laine–Karras hash of `v` (the Sobol' sampler's scramble), its bits under `w`.
#[inline(always)]
fn lk_permute(v: u32, w: u32, seed: u32) -> u32 {
    scramble_reversed(v, seed) & w
}

/// Kensler's `randfloat` without its float conversion: a hash of (i, p) as a 32-bit
/// fraction.
#[inline]
fn rand_u32(mut i: u32, p: u32) -> u32 {
    i ^= p;
    i ^= i >> 17;
    i ^= i >> 10;
    i = i.wrapping_mul(0xb365_34e5);
    i ^= i >> 12;
    i ^= i >> 21;
    i = i.wrapping_mul(0x93fc_4795);
    i ^= 0xdf6e_307f;
    i ^= i >> 17;
    i.wrapping_mul(1 | p >> 18)
}

/// The largest pattern: its strata must stay wider than the 2⁻²⁴ steps of a float's
/// fraction ([`CmjPattern::in_stratum`]); sample indices past it start new patterns.
const MAX_PATTERN: u32 = 1 << 20;

/// The shifts of a pattern of n = 2ᵏ samples.
#[derive(Clone, Copy, Debug)]
struct Pow2Shifts {
    /// 24 − k: a stratum's first step of 2⁻²⁴.
    stratum: u32,
    /// 8 + k: a 32-bit jitter to the 24 − k bits of a step within a stratum.
    jitter: u32,
    /// ⌊k/2⌋ = log₂ m: a cell's row.
    row: u32,
}

/// The shape of a pattern of `n` samples: its `m × q` grid, `m` the largest divisor of
/// `n` not above √n.
#[derive(Clone, Copy, Debug)]
pub(super) struct CmjPattern {
    n: u32,
    m: u32,
    q: u32,
    /// [`mask`] of n, m and q.
    masks: [u32; 3],
    /// Where n = 2ᵏ is a power of two, every division is a shift: these are its shifts.
    pow2: Option<Pow2Shifts>,
}

impl CmjPattern {
    /// The pattern of `spp` samples (at least one, at most [`MAX_PATTERN`]).
    pub(super) fn new(spp: u32) -> Self {
        let n = spp.clamp(1, MAX_PATTERN);
        let mut m = (n as f64).sqrt() as u32;
        while !n.is_multiple_of(m) {
            m -= 1;
        }
        CmjPattern {
            n,
            m,
            q: n / m,
            masks: [mask(n), mask(m), mask(n / m)],
            pow2: n.is_power_of_two().then(|| {
                let k = n.trailing_zeros();
                Pow2Shifts {
                    stratum: 24 - k,
                    jitter: 8 + k,
                    row: k / 2,
                }
            }),
        }
    }

    /// Samples in a pattern.
    pub(super) fn len(&self) -> u32 {
        self.n
    }

    /// (stratum + jitter) / n for a stratum below n and a 32-bit fraction `jitter`, as
    /// a float on the grid of 2⁻²⁴ steps (all exact in f32), inside the stratum and below
    /// 1: the stratum's grid steps are those from ⌈stratum · 2²⁴/n⌉ on, below the next
    /// stratum's first, and the jitter picks one of them uniformly (for a power of two
    /// exactly; otherwise up to one step in the 2²⁴/n of a stratum).
    #[inline(always)]
    fn in_stratum(&self, stratum: u32, jitter: u32) -> f32 {
        let step = match self.pow2 {
            // The stratum's bits above the jitter's top 24 − k bits.
            Some(p) => (stratum << p.stratum) | (jitter >> p.jitter),
            None => {
                let n = self.n as u64;
                let first = |s: u32| ((s as u64) << 24).div_ceil(n);
                let (lo, hi) = (first(stratum), first(stratum + 1));
                (lo + ((jitter as u64 * (hi - lo)) >> 32)) as u32
            }
        };
        step as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// The 1D number of sample `s` (below `n`) of the pattern with seed `p`: the shuffled
    /// index's stratum, jittered.
    #[inline(always)]
    fn number_1d(&self, s: u32, p: u32) -> f32 {
        let stratum = permute(s, self.n, self.masks[0], p.wrapping_mul(0x5163_3e2d));
        self.in_stratum(stratum, rand_u32(s, p.wrapping_mul(0xa399_d265)))
    }

    /// Kensler's `cmj` of sample `s` (below `n`) of the pattern with seed `p`, with the
    /// sample index shuffled first; `jitter` is a 64-bit hash of (s, p), both jitters.
    #[inline(always)]
    fn point_2d(&self, s: u32, p: u32, jitter: u64) -> Vec2 {
        let [wn, wm, wq] = self.masks;
        self.cell_point(
            permute(s, self.n, wn, p.wrapping_mul(0x5163_3e2d)),
            |col| permute(col, self.m, wm, p.wrapping_mul(0x68bc_21eb)),
            |row| permute(row, self.q, wq, p.wrapping_mul(0x02e5_be93)),
            jitter,
        )
    }

    /// The point of sample `index` (below `n`) for [`super::SobolCmjSampler`]: cell
    /// `(index + rotation) mod n` of the pattern, in row-major order, its offsets in the
    /// columns and the rows permuted by [`fast_permute`] with `seeds`, and jittered by
    /// `jitter`. The three values must be independent hashes: every point is then uniform
    /// on the square (the rotation makes the cell uniform, the permutations its offsets).
    #[inline(always)]
    pub(super) fn rotated_point(
        &self,
        index: u32,
        rotation: u32,
        seeds: [u32; 2],
        jitter: u64,
    ) -> Vec2 {
        let [wn, wm, wq] = self.masks;
        let s = match self.pow2 {
            Some(_) => index.wrapping_add(rotation) & wn,
            None => ((index as u64 + rotation as u64) % self.n as u64) as u32,
        };
        self.cell_point(
            s,
            |col| fast_permute(col, self.m, wm, seeds[0]),
            |row| fast_permute(row, self.q, wq, seeds[1]),
            jitter,
        )
    }

    /// Cell `s` (below n) of the m × q grid, column `s mod m` and row `s div m`, with the
    /// offsets `sx(column)` of its column and `sy(row)` of its row: x = (col + (sy + jx)
    /// / q) / m and y = (row + (sx + jy) / m) / q, that is stratum col·q + sy of the n in
    /// x and row·m + sx in y, jittered by the two halves of `jitter`.
    #[inline(always)]
    fn cell_point(
        &self,
        s: u32,
        sx: impl Fn(u32) -> u32,
        sy: impl Fn(u32) -> u32,
        jitter: u64,
    ) -> Vec2 {
        let (m, q) = (self.m, self.q);
        let (col, row) = match self.pow2 {
            // m = 2^⌊k/2⌋.
            Some(p) => (s & (m - 1), s >> p.row),
            None => (s % m, s / m),
        };
        Vec2::new(
            self.in_stratum(col * q + sy(row), jitter as u32),
            self.in_stratum(row * m + sx(col), (jitter >> 32) as u32),
        )
    }
}

/// Padded correlated multi-jittered samples (see the module docs). Deterministic per
/// (seed, pixel, sample index, request).
#[derive(Clone, Debug)]
pub struct CmjSampler {
    seed: u64,
    pattern: CmjPattern,
    /// Hash of (seed, pixel, block of `n` sample indices) for the current pixel sample.
    pixel_key: u64,
    /// The sample's index within its block.
    s: u32,
    /// Requests taken so far in this pixel sample (a 2D request counts two, as in the
    /// Sobol' sampler, so that the two number the integrator's dimensions alike).
    dimension: u32,
}

impl CmjSampler {
    /// A sampler for `spp` samples per pixel (at least one).
    pub fn new(seed: u64, spp: u32) -> Self {
        CmjSampler {
            seed,
            pattern: CmjPattern::new(spp),
            pixel_key: 0,
            s: 0,
            dimension: 0,
        }
    }

    /// The pattern seed of the request at `dimension`.
    #[inline(always)]
    fn seed_at(&self, dimension: u32) -> u32 {
        const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;
        (mix64(
            self.pixel_key
                .wrapping_add((dimension as u64).wrapping_mul(GOLDEN)),
        ) >> 32) as u32
    }
}

impl Sampler for CmjSampler {
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        let key = ((pixel.x as u64) << 32) | pixel.y as u64;
        let n = self.pattern.len();
        let block = (index / n) as u64;
        self.pixel_key = mix64(self.seed ^ mix64(key) ^ block.wrapping_mul(0xd134_2543_de82_ef95));
        self.s = index % n;
        self.dimension = 0;
    }

    #[inline]
    fn get_1d(&mut self) -> f32 {
        self.dimension += 1;
        self.resolve_1d(self.dimension - 1)
    }

    #[inline]
    fn skip_1d(&mut self) {
        self.dimension += 1;
    }

    type Deferred1d = u32;

    #[inline]
    fn defer_1d(&mut self) -> u32 {
        self.dimension += 1;
        self.dimension - 1
    }

    #[inline]
    fn resolve_1d(&self, dimension: u32) -> f32 {
        self.pattern.number_1d(self.s, self.seed_at(dimension))
    }

    #[inline]
    fn get_2d(&mut self) -> Vec2 {
        self.dimension += 2;
        let p = self.seed_at(self.dimension - 2);
        let jitter = mix64(((p as u64) << 32) | self.s as u64);
        self.pattern.point_2d(self.s, p, jitter)
    }
}
