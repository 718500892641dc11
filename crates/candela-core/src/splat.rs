//! Splatting for pixel filters wider than a pixel, as Mitsuba does: each sample, uniform
//! in its pixel, adds its radiance to every pixel under the filter centred on it, weighted
//! by the filter's value at that pixel's centre, and each pixel divides by the sum of its
//! weights ([`crate::film::Pixel::value`]). The expected image is the one filter
//! importance sampling gives (a ratio estimator: consistent, not unbiased, as Mitsuba's),
//! but a pixel averages about as many samples as the filter covers pixels, so at equal
//! spp it is less noisy.
//!
//! Determinism: a work item (a band of rows) counts each sample in its own pixel of the
//! film and splats its shares into a block of its own holding its rows and an apron of
//! rows above and below as far as the filter reaches. The blocks keep their shares from
//! pass to pass as exact integer sums and are added into the film when the render ends
//! (or when their sums near capacity). Integer sums do not depend on their order, so
//! every pixel gets the same bits whatever the thread count or the order in which the
//! bands ran.
//!
//! Cost: a Gaussian of radius 2 spreads a sample over 16 pixels, four exact sums each.
//! A block therefore collects its shares in [`LimbSums`] (in the v3 copy of the render
//! loop, a row of four pixels' shares at a time in AVX2, some ten instructions a pixel)
//! and folds them into the film's pixels once: integer sums, so the same bits as adding
//! each share to the pixel.

use std::ops::Range;
use std::sync::atomic::Ordering;

use glam::{UVec2, Vec2, Vec3};
use rayon::prelude::*;

use crate::film::{Film, Pixel};
use crate::filter::PixelFilter;
use crate::integrator::{render_band, Band, PassCtx, RenderStats, SampleSink};
use crate::limb_sums::LimbSums;
use crate::options::Isa;
use crate::sampler::Sampler;

/// Rows of samples per work item; its block holds the apron besides.
const BAND_ROWS: u32 = 8;

/// A render's splatted shares: each band's block, kept from pass to pass.
pub(crate) struct Splats {
    blocks: Vec<Block>,
    /// A bound on the shares any pixel of a block has taken since the last fold.
    pending: u64,
    /// A bound on the shares a pixel takes per sample index of a pass.
    per_sample: u64,
}

/// A band's pending shares: rows from `y0`, the band's and its apron's.
struct Block {
    y0: u32,
    shares: Shares,
}

/// Where a block's shares wait for the film.
enum Shares {
    /// Exact sums in limbs (see [`crate::limb_sums`]).
    Limbs(LimbSums),
    /// Pixels' exact sums directly (sample counts unused): for filters so wide that one
    /// pass could exceed the limbs' capacity.
    Pixels(Vec<Pixel>),
}

impl Splats {
    /// Empty blocks for a `width` × `height` film under `filter`, for passes of at most
    /// `pass_spp` samples per pixel.
    pub(crate) fn new(filter: &PixelFilter, width: u32, height: u32, pass_spp: u32) -> Splats {
        let apron = apron_rows(filter.radius());
        // A pixel takes at most one share of each sample within the apron's reach per axis.
        let reach = 2 * apron as u64 + 1;
        let per_sample = reach * reach;
        let limbs = per_sample * pass_spp as u64 <= LimbSums::CAPACITY;
        let blocks = (0..height)
            .step_by(BAND_ROWS as usize)
            .map(|y| {
                let y0 = y.saturating_sub(apron);
                let y1 = (y + BAND_ROWS + apron).min(height);
                let len = (width * (y1 - y0)) as usize;
                let shares = if limbs {
                    Shares::Limbs(LimbSums::new(len))
                } else {
                    Shares::Pixels(vec![Pixel::default(); len])
                };
                Block { y0, shares }
            })
            .collect();
        Splats {
            blocks,
            pending: 0,
            per_sample,
        }
    }

    /// Renders one pass (sample indices `pass` of every pixel): the samples are counted in
    /// `film` and their shares wait in the blocks ([`Self::fold_into`]).
    pub(crate) fn render_pass<S: Sampler>(
        &mut self,
        ctx: &PassCtx,
        sampler: &S,
        film: &mut Film,
        pass: &Range<u32>,
    ) -> RenderStats {
        let added = self.per_sample * pass.len() as u64;
        if self.pending + added > LimbSums::CAPACITY {
            self.fold_into(film);
        }
        self.pending += added;
        let (w, h) = (film.width, film.height);
        let filter = &ctx.scene.filter;
        film.pixels
            .par_chunks_mut((w * BAND_ROWS).max(1) as usize)
            .zip(self.blocks.par_iter_mut())
            .enumerate()
            .map(|(band, (own, block))| {
                if ctx.cancel.load(Ordering::Relaxed) {
                    return RenderStats::default();
                }
                let y = band as u32 * BAND_ROWS;
                let rows = y..y + (own.len() / w as usize) as u32;
                let done = rows.len() as u64 * w as u64 * pass.len() as u64;
                let band = Band {
                    rows: rows.clone(),
                    width: w,
                    pass: pass.clone(),
                };
                let mut sink = SplatSink {
                    filter,
                    radius: filter.radius(),
                    width: w,
                    height: h,
                    own,
                    own_y0: rows.start,
                    block,
                    isa: ctx.isa,
                };
                let mut sampler = sampler.clone();
                let stats = render_band(ctx.scene, ctx.isa, &mut sampler, band, &mut sink);
                (ctx.progress)(done);
                stats
            })
            .reduce(RenderStats::default, RenderStats::add)
    }

    /// Adds the blocks' pending shares into `film`'s pixels and clears them: when the
    /// render ends, and before the limbs could exceed their capacity.
    pub(crate) fn fold_into(&mut self, film: &mut Film) {
        for block in &mut self.blocks {
            let start = (block.y0 * film.width) as usize;
            match &mut block.shares {
                Shares::Limbs(sums) => sums.fold_into(&mut film.pixels[start..start + sums.len()]),
                Shares::Pixels(pixels) => {
                    for (a, b) in film.pixels[start..].iter_mut().zip(pixels.iter_mut()) {
                        a.merge(b);
                        *b = Pixel::default();
                    }
                }
            }
        }
        self.pending = 0;
    }
}

/// Rows beyond a band that its samples can reach with a filter of radius `r`: a sample
/// at height y ∈ [y₀, y₁) reaches the pixels whose centres lie within r of it.
fn apron_rows(r: f32) -> u32 {
    (r + 0.5).ceil() as u32
}

/// The pixels a filter of radius `r` reaches along one axis from a sample at `x`, clipped
/// to `0..n`: those whose centre `q + ½` lies strictly within `r` of `x` (the filter is
/// zero at its radius).
fn footprint(x: f32, r: f32, n: u32) -> Range<u32> {
    let lo = (x - 0.5 - r).floor() as i64 + 1;
    let hi = (x - 0.5 + r).ceil() as i64;
    (lo.max(0) as u32)..(hi.clamp(0, n as i64) as u32)
}

/// A work item's view of the film for one pass: its own rows' pixels, where it counts
/// its samples, and its block, where their shares go.
struct SplatSink<'a> {
    filter: &'a PixelFilter,
    /// The filter's radius, read once.
    radius: f32,
    width: u32,
    /// The image's height, which clips the footprint.
    height: u32,
    /// The film's pixels of the band's rows, from row `own_y0`.
    own: &'a mut [Pixel],
    own_y0: u32,
    block: &'a mut Block,
    /// The render loop's copy, which says whether the shares are added in AVX2.
    isa: Isa,
}

impl SampleSink for SplatSink<'_> {
    const SPLATS: bool = true;

    /// Inlined into each copy of the render loop: in the v3 copy its floors and ceilings
    /// are single instructions. The v3 shares go through [`add_in_lanes`], out of line
    /// (the lanes integrator's call).
    #[inline(always)]
    fn add(&mut self, p: UVec2, film_pos: Vec2, l: Vec3) {
        #[cfg(target_arch = "x86_64")]
        let lanes = matches!(self.isa, Isa::V3);
        #[cfg(not(target_arch = "x86_64"))]
        let lanes = false;
        // SAFETY: the render loop runs its v3 copy only where the CPU has it.
        unsafe { self.add_sharing::<false>(p, film_pos, l, lanes) }
    }

    /// [`Self::add`]; in the v3 copy of the path integrator's render loop the AVX2 shares
    /// ([`add_in_lanes_inlined`]) are inlined into it, without a call's entry and exit.
    #[inline(always)]
    fn add_in<const V3: bool>(&mut self, p: UVec2, film_pos: Vec2, l: Vec3) {
        if V3 {
            // SAFETY: `V3` is the v3 copy, which runs only where the CPU has it.
            return unsafe { self.add_sharing::<true>(p, film_pos, l, true) };
        }
        self.add(p, film_pos, l);
    }
}

impl SplatSink<'_> {
    /// [`SampleSink::add`]'s body: the sample counted, then its shares, in AVX2 where
    /// `lanes` ([`add_in_lanes`], or with `INLINED` its body [`add_in_lanes_inlined`]
    /// inlined into the caller), one by one otherwise and where the lanes decline it.
    ///
    /// # Safety
    /// Where `lanes`, the CPU must have AVX2 and FMA.
    #[inline(always)]
    unsafe fn add_sharing<const INLINED: bool>(
        &mut self,
        p: UVec2,
        film_pos: Vec2,
        l: Vec3,
        lanes: bool,
    ) {
        if !self.count(p, l) {
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if lanes {
            let film = (self.width, self.height, self.radius);
            if let Shares::Limbs(sums) = &mut self.block.shares {
                let (filter, y0) = (self.filter, self.block.y0);
                // SAFETY: the caller's promise for `lanes`.
                let added = unsafe {
                    if INLINED {
                        add_in_lanes_inlined(sums, filter, film, y0, film_pos, l)
                    } else {
                        add_in_lanes(sums, filter, film, y0, film_pos, l)
                    }
                };
                if added {
                    return;
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = lanes;
        self.add_footprint(film_pos, l);
    }

    /// Counts a sample of pixel `p` in the band's own pixels; whether it is accepted.
    #[inline(always)]
    fn count(&mut self, p: UVec2, l: Vec3) -> bool {
        let own = ((p.y - self.own_y0) * self.width + p.x) as usize;
        self.own[own].count(l)
    }

    /// An accepted sample's shares over its footprint, one by one.
    #[inline(always)]
    fn add_footprint(&mut self, film_pos: Vec2, l: Vec3) {
        let xs = footprint(film_pos.x, self.radius, self.width);
        let ys = footprint(film_pos.y, self.radius, self.height);
        self.add_shares(xs, ys, film_pos, l);
    }

    /// [`SampleSink::add`]'s shares one by one, each weight computed as the AVX2 rows
    /// compute it (a row's x weights once where they fit a cache).
    fn add_shares(&mut self, xs: Range<u32>, ys: Range<u32>, film_pos: Vec2, l: Vec3) {
        let filter = self.filter;
        let axis = |q: u32, pos: f32| filter.eval_axis(q as f32 + 0.5 - pos);
        let mut cache = [0.0f32; 16];
        let cached = xs.len() <= cache.len();
        if cached {
            for (w, x) in cache.iter_mut().zip(xs.clone()) {
                *w = axis(x, film_pos.x);
            }
        }
        for y in ys {
            let wy = axis(y, film_pos.y);
            // A zero weight adds nothing: its shares are zero.
            if wy == 0.0 {
                continue;
            }
            let row = ((y - self.block.y0) * self.width) as usize;
            for (k, x) in xs.clone().enumerate() {
                let wx = if cached {
                    cache[k]
                } else {
                    axis(x, film_pos.x)
                };
                if wx == 0.0 {
                    continue;
                }
                let i = row + x as usize;
                match &mut self.block.shares {
                    Shares::Limbs(sums) => sums.add_weighted(i, l, wx * wy),
                    Shares::Pixels(pixels) => {
                        pixels[i].add_weighted(l, wx * wy);
                    }
                }
            }
        }
    }
}

/// [`SampleSink::add`]'s shares for a footprint of at most 4 × 4 pixels (a Gaussian
/// of radius ≤ 2, Mitsuba's default; a tent of radius ≤ 1.5) in AVX2, into `sums` of the
/// block whose rows start at `y0` of a film `width` × `height` under a filter of radius
/// `r`: both axes' footprints in one register, the 4 + 4 axis weights in one
/// [`PixelFilter::eval_axis8`] (or one by one for other filters), and the shares by
/// [`LimbSums::add_4x4_avx2`] (rows by [`LimbSums::add_row_avx2`] where the footprint is
/// clipped). The same numbers as [`footprint`] and [`SplatSink::add_shares`]. Returns
/// false, adding nothing, where the footprint does not fit.
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma")]
#[inline]
fn add_in_lanes(
    sums: &mut LimbSums,
    filter: &PixelFilter,
    film: (u32, u32, f32),
    y0: u32,
    film_pos: Vec2,
    l: Vec3,
) -> bool {
    // SAFETY: this function's features.
    unsafe { add_in_lanes_inlined(sums, filter, film, y0, film_pos, l) }
}

/// [`add_in_lanes`]' body, inlined into its caller: a function compiled for AVX2 and FMA
/// (the v3 copy of the render loop, or [`add_in_lanes`]), whose intrinsics it inlines.
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn add_in_lanes_inlined(
    sums: &mut LimbSums,
    filter: &PixelFilter,
    (width, height, r): (u32, u32, f32),
    y0: u32,
    film_pos: Vec2,
    l: Vec3,
) -> bool {
    use std::arch::x86_64::*;
    let (xs, ys, bounds) = footprints_in_lanes(film_pos, r, (width, height));
    if xs.len() > 4 || ys.len() > 4 {
        return false;
    }
    // Lanes 0‥3: the pixels xs.start + i; lanes 4‥7: ys.start + i (exact integers),
    // offset as `add_shares` offsets them: (q + ½) − film_pos.
    let lane = _mm256_setr_ps(0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0);
    let first = _mm256_set_m128(
        _mm_permute_ps::<0x55>(bounds),
        _mm_permute_ps::<0x00>(bounds),
    );
    let pos = _mm256_set_m128(_mm_set1_ps(film_pos.y), _mm_set1_ps(film_pos.x));
    let offsets = _mm256_sub_ps(
        _mm256_add_ps(_mm256_add_ps(first, lane), _mm256_set1_ps(0.5)),
        pos,
    );
    let w = filter.eval_axis8(offsets).unwrap_or_else(|| {
        let mut x = [0.0f32; 8];
        // SAFETY: `x` holds eight f32, as does the array loaded.
        unsafe {
            _mm256_storeu_ps(x.as_mut_ptr(), offsets);
            _mm256_loadu_ps(x.map(|x| filter.eval_axis(x)).as_ptr())
        }
    });
    let (wx, wy) = (_mm256_castps256_ps128(w), _mm256_extractf128_ps::<1>(w));
    let rgb1 = crate::limb_sums::rgb1(l);
    let start = ((ys.start - y0) * width + xs.start) as usize;
    if xs.len() == 4 && ys.len() == 4 {
        // A row of zero weights adds zero shares: no need to skip it.
        sums.add_4x4_avx2((start, width as usize), rgb1, wx, wy);
        return true;
    }
    let mut wy_lanes = [0.0f32; 4];
    // SAFETY: `wy_lanes` holds four f32.
    unsafe { _mm_storeu_ps(wy_lanes.as_mut_ptr(), wy) };
    for (j, &wy) in wy_lanes.iter().enumerate().take(ys.len()) {
        // A zero weight adds nothing: its shares are zero.
        if wy == 0.0 {
            continue;
        }
        // The row's weights wx·wy, rounded to f32 as the scalar path rounds them.
        let weights = _mm256_cvtps_pd(_mm_mul_ps(wx, _mm_set1_ps(wy)));
        sums.add_row_avx2(start + j * width as usize, xs.len(), rgb1, weights);
    }
    true
}

/// [`footprint`] along both axes in one SSE register, lanes (x, y, x, y): (x − ½ − r)
/// floored plus one, then (x − ½ + r) ceiled, clamped at 0 and the ends at the image's
/// size (exact integers below 2²⁴, as the scalar i64s are). Returns the x and y
/// footprints and the register (first x, first y, end x, end y).
///
/// # Safety
/// The CPU must have AVX2 and FMA. Inlined, so that its intrinsics inline into a caller
/// compiled for them.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn footprints_in_lanes(
    film_pos: Vec2,
    r: f32,
    (width, height): (u32, u32),
) -> (Range<u32>, Range<u32>, std::arch::x86_64::__m128) {
    use std::arch::x86_64::*;
    let pos = _mm_setr_ps(film_pos.x, film_pos.y, film_pos.x, film_pos.y);
    let centred = _mm_sub_ps(pos, _mm_set1_ps(0.5));
    let radius = _mm_set1_ps(r);
    let lo = _mm_add_ps(_mm_floor_ps(_mm_sub_ps(centred, radius)), _mm_set1_ps(1.0));
    let hi = _mm_ceil_ps(_mm_add_ps(centred, radius));
    let size = _mm_setr_ps(f32::MAX, f32::MAX, width as f32, height as f32);
    let bounds = _mm_min_ps(
        _mm_max_ps(_mm_blend_ps::<0b1100>(lo, hi), _mm_setzero_ps()),
        size,
    );
    let mut b = [0i32; 4];
    // SAFETY: `b` holds four i32.
    unsafe { _mm_storeu_si128(b.as_mut_ptr() as *mut __m128i, _mm_cvttps_epi32(bounds)) };
    (b[0] as u32..b[2] as u32, b[1] as u32..b[3] as u32, bounds)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The footprint holds exactly the pixels whose centre is strictly within the radius,
    /// and the apron covers every footprint of a band's samples.
    #[test]
    fn footprint_is_the_pixels_within_the_radius() {
        for r in [0.5f32, 1.0, 1.5, 2.0, 2.3] {
            for k in 0..=64 {
                let x = 10.0 + k as f32 / 64.0 * 0.999;
                let fp = footprint(x, r, 100);
                for q in 0..100u32 {
                    let inside = (q as f32 + 0.5 - x).abs() < r;
                    assert_eq!(fp.contains(&q), inside, "r {r} x {x} q {q}");
                }
                assert!(fp.start >= 10 - apron_rows(r) && fp.end <= 11 + apron_rows(r));
            }
        }
        assert_eq!(footprint(0.2, 2.0, 3), 0..2);
        assert_eq!(footprint(0.2, 2.0, 1), 0..1);
    }

    /// The v3 splat's footprints are `footprint`'s, inside the image, at its edges and
    /// beyond them, at pixel corners and centres (exact halves) and between.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn footprints_in_lanes_are_the_scalar_ones() {
        if !(std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma"))
        {
            return;
        }
        let (w, h) = (37u32, 5u32);
        for r in [0.5f32, 1.0, 1.5, 2.0, 2.3, 7.9] {
            for k in 0..=40 * 64 {
                let x = k as f32 / 64.0 - 1.0;
                let y = (k * 7 % (8 * 64)) as f32 / 64.0 - 1.5;
                let p = Vec2::new(x, y);
                // SAFETY: the CPU has AVX2 and FMA (checked above).
                let (xs, ys, _) = unsafe { footprints_in_lanes(p, r, (w, h)) };
                assert_eq!(xs.len(), footprint(x, r, w).len(), "r {r} x {x}");
                if !xs.is_empty() {
                    assert_eq!(xs, footprint(x, r, w), "r {r} x {x}");
                }
                assert_eq!(ys.len(), footprint(y, r, h).len(), "r {r} y {y}");
                if !ys.is_empty() {
                    assert_eq!(ys, footprint(y, r, h), "r {r} y {y}");
                }
            }
        }
    }
}
