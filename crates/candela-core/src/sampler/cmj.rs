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
//! The pattern needs the sample count. Sample indices at or beyond it (a render extended
//! by more passes) start new patterns of the same size, one per block of `n` indices with
//! seeds of their own: each block is stratified by itself, and their union no better than
//! a union of independent patterns.

use glam::{UVec2, Vec2};

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
/// once per pattern.
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
    (i.wrapping_add(p)) % l
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

/// (stratum + jitter) / n, for a stratum below n and a 32-bit fraction `jitter`, as the
/// float next below it, or the float next above the stratum's lower edge where that is
/// higher: it stays inside the stratum and below 1 (a float rounded to nearest could
/// reach the next stratum, or 1).
#[inline]
fn in_stratum(stratum: u32, jitter: u32, inv_n: f64) -> f32 {
    let lo = stratum as f64 * inv_n;
    let x = lo + jitter as f64 * (1.0 / 4294967296.0) * inv_n;
    let f = x as f32;
    if f as f64 > x {
        let below = f32::from_bits(f.to_bits() - 1);
        if (below as f64) < lo {
            f
        } else {
            below
        }
    } else if (f as f64) < lo {
        f32::from_bits(f.to_bits() + 1)
    } else {
        f
    }
}

/// The shape of a pattern of `n` samples: its `m × q` grid, `m` the largest divisor of
/// `n` not above √n.
#[derive(Clone, Copy, Debug)]
struct CmjPattern {
    n: u32,
    m: u32,
    q: u32,
    /// [`mask`] of n, m and q.
    masks: [u32; 3],
    inv_n: f64,
}

impl CmjPattern {
    /// The pattern of `spp` samples (at least one).
    fn new(spp: u32) -> Self {
        let n = spp.max(1);
        let mut m = (n as f64).sqrt() as u32;
        while !n.is_multiple_of(m) {
            m -= 1;
        }
        CmjPattern {
            n,
            m,
            q: n / m,
            masks: [mask(n), mask(m), mask(n / m)],
            inv_n: 1.0 / n as f64,
        }
    }

    /// Samples in a pattern.
    fn len(&self) -> u32 {
        self.n
    }

    /// The 1D number of sample `s` (below `n`) of the pattern with seed `p`: the shuffled
    /// index's stratum, jittered.
    #[inline(always)]
    fn number_1d(&self, s: u32, p: u32) -> f32 {
        let stratum = permute(s, self.n, self.masks[0], p.wrapping_mul(0x5163_3e2d));
        in_stratum(
            stratum,
            rand_u32(s, p.wrapping_mul(0xa399_d265)),
            self.inv_n,
        )
    }

    /// Kensler's `cmj` of sample `s` (below `n`) of the pattern with seed `p`, with the
    /// sample index shuffled first.
    #[inline(always)]
    fn point_2d(&self, s: u32, p: u32) -> Vec2 {
        let (m, q) = (self.m, self.q);
        let [wn, wm, wq] = self.masks;
        let s = permute(s, self.n, wn, p.wrapping_mul(0x5163_3e2d));
        let (col, row) = (s % m, s / m);
        let sx = permute(col, m, wm, p.wrapping_mul(0x68bc_21eb));
        let sy = permute(row, q, wq, p.wrapping_mul(0x02e5_be93));
        // x = (col + (sy + jx) / q) / m and y = (row + (sx + jy) / m) / q: stratum
        // col·q + sy of n in x, row·m + sx in y.
        // Both jitters from one 64-bit hash of (s, p).
        let j = mix64(((p as u64) << 32) | s as u64);
        let (jx, jy) = (j as u32, (j >> 32) as u32);
        Vec2::new(
            in_stratum(col * q + sy, jx, self.inv_n),
            in_stratum(row * m + sx, jy, self.inv_n),
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
        self.pattern
            .point_2d(self.s, self.seed_at(self.dimension - 2))
    }
}
