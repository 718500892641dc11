//! Padded Sobol' points for every request but one: the first bounce's BSDF direction,
//! which comes from a padded correlated multi-jittered pattern (Kensler 2013, the pattern
//! of [`super::CmjSampler`]) of the render's planned sample count.
//!
//! Why that one request: at the first vertex the indirect light is a piecewise-smooth
//! function of the BSDF's sample square, which CMJ's points (one in each cell of an
//! m × q grid and in each of the n rows and columns, the offsets permuted alike) integrate
//! better than a scrambled (0, k, 2)-net.
//! For the pixel position and the lens (sharp edges), for light points and for deeper
//! bounces Sobol' does as well or better (bench/JOURNAL.md, "Sampler study (stop 19)" and
//! "First-bounce pattern (stop 20)").
//!
//! The pattern: the m × q grid of [`super::CmjSampler`]'s (m the largest divisor of n not
//! above √n), its offsets in the columns and rows permuted (for power-of-two sizes by the
//! Laine–Karras hash, five operations, instead of Kensler's permutation), each point
//! jittered in its stratum. Sample index i takes cell (i + r) mod n in row-major order, r
//! a random rotation per pixel, not a random shuffle of the cells: consecutive indices
//! then take consecutive cells of a row, and since the Sobol' requests map aligned blocks
//! of indices onto nets, each row of directions meets well-spread pixel positions and
//! light points. That pairing lowered the Cornell box's error at 64 spp by 14 % against
//! Sobol', where Kensler's shuffle gave 7 %; it costs nothing in uniformity (the rotation
//! alone makes each sample's cell uniform; the rotation, the two permutations and the
//! jitters come from independent hashes, which the chi-square tests check).
//!
//! Every other request is exactly [`SobolSampler`]'s, so its stratification, padding and
//! cost stay as they are. The pattern point is computed in
//! [`Sampler::start_pixel_sample`]: it depends on the pixel and the sample index only, not
//! on the hit, so its hashing overlaps the camera ray's traversal instead of following it.
//!
//! Sample indices at or past the planned count (a render extended by more passes, or a
//! count above the pattern's limit) take the Sobol' sampler's point for that request too:
//! an aligned block of 2ᵏ such indices is then a (0, k, 2)-net, as with plain Sobol'.
//! A sample range `[a, b)` of the planned count uses the same pattern as the whole render,
//! so films of disjoint ranges still add up to the film of their union.

use glam::{UVec2, Vec2};

use super::cmj::CmjPattern;
use super::{mix64, Sampler, SobolSampler};

/// The dimension of the first bounce's BSDF direction in the integrator's order (see the
/// [`super`] module docs): the pixel position (2), the lens point (2, thin lens only), the
/// light pick (1), the light point (2) and the BSDF lobe (1) come before it.
pub const fn first_direction_dimension(has_lens: bool) -> u32 {
    let lens = if has_lens { 2 } else { 0 };
    2 + lens + 1 + 2 + 1
}

/// Padded Sobol' with the first bounce's BSDF direction from a CMJ pattern (see the module
/// docs). Deterministic per (seed, pixel, sample index, request).
#[derive(Clone, Debug)]
pub struct SobolCmjSampler {
    sobol: SobolSampler,
    pattern: CmjPattern,
    /// [`first_direction_dimension`] of the scene's camera.
    first_direction: u32,
    /// Where the current pixel sample takes `point`: `first_direction`, or `u32::MAX`
    /// (never) for an index past the pattern.
    cmj_dimension: u32,
    /// The current pixel sample's pattern point.
    point: Vec2,
}

impl SobolCmjSampler {
    /// A sampler for renders of `spp` planned samples per pixel, through a camera that
    /// takes a lens sample (`has_lens`) or not.
    pub fn new(seed: u64, spp: u32, has_lens: bool) -> Self {
        SobolCmjSampler {
            sobol: SobolSampler::new(seed),
            pattern: CmjPattern::new(spp),
            first_direction: first_direction_dimension(has_lens),
            cmj_dimension: u32::MAX,
            point: Vec2::ZERO,
        }
    }
}

impl Sampler for SobolCmjSampler {
    #[inline(always)]
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        self.sobol.start_pixel_sample(pixel, index);
        if index < self.pattern.len() {
            // Three independent hashes of the pixel (its Sobol' key, which the Sobol'
            // requests use only through a finalizer `mix64(key + d·φ)`): the cell
            // rotation from one more finalizer, the two permutations from the key's
            // halves; and the jitters from a finalizer of the key and the index.
            let key = self.sobol.pixel_key();
            let rotation = mix64(key ^ 0x5851_f42d_4c95_7f2d) as u32;
            let step = (index as u64 + 1).wrapping_mul(0xa076_1d64_78bd_642f);
            let jitter = mix64(key.wrapping_add(step));
            let seeds = [key as u32, (key >> 32) as u32];
            self.point = self.pattern.rotated_point(index, rotation, seeds, jitter);
            self.cmj_dimension = self.first_direction;
        } else {
            self.cmj_dimension = u32::MAX;
        }
    }

    #[inline]
    fn get_1d(&mut self) -> f32 {
        self.sobol.get_1d()
    }

    #[inline]
    fn get_2d(&mut self) -> Vec2 {
        if self.sobol.dimension() == self.cmj_dimension {
            // The request's two dimensions stay taken in the Sobol' stream.
            self.sobol.skip_1d();
            self.sobol.skip_1d();
            self.point
        } else {
            self.sobol.get_2d()
        }
    }

    #[inline]
    fn skip_1d(&mut self) {
        self.sobol.skip_1d();
    }

    #[inline]
    fn get_pixel_2d(&mut self) -> Vec2 {
        self.sobol.get_pixel_2d()
    }

    type Deferred1d = u32;

    #[inline]
    fn defer_1d(&mut self) -> u32 {
        self.sobol.defer_1d()
    }

    #[inline]
    fn resolve_1d(&self, dimension: u32) -> f32 {
        self.sobol.resolve_1d(dimension)
    }
}
