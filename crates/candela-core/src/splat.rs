//! Splatting for pixel filters wider than a pixel, as Mitsuba does: each sample, uniform
//! in its pixel, adds its radiance to every pixel under the filter centred on it, weighted
//! by the filter's value at that pixel's centre, and each pixel divides by the sum of its
//! weights ([`crate::film::Pixel::value`]). The expected image is the one filter
//! importance sampling gives (a ratio estimator: consistent, not unbiased, as Mitsuba's),
//! but a pixel averages about as many samples as the filter covers pixels, so at equal
//! spp it is less noisy.
//!
//! Determinism: a work item (a band of rows) splats into a block of its own holding its
//! rows and an apron of rows above and below as far as the filter reaches; the blocks are
//! then added into the film one after another in the order of their bands. So every pixel
//! sums the same numbers in the same order whatever the thread count or the order in
//! which the bands ran.
//!
//! Cost: a Gaussian of radius 2 spreads a sample over 16 pixels, four exact sums each.
//! A block therefore collects its shares in [`LimbSums`] (in the v3 copy of the render
//! loop, one pixel's four shares at a time in AVX2) and folds them into its pixels when
//! its band is done: integer sums, so the same bits as adding each share to the pixel.

use std::ops::Range;
use std::sync::atomic::Ordering;

use glam::{UVec2, Vec2, Vec3};
use rayon::prelude::*;

use crate::film::{Film, Pixel};
use crate::filter::PixelFilter;
use crate::integrator::{render_band, Band, PassCtx, RenderStats, SampleSink};
#[cfg(target_arch = "x86_64")]
use crate::limb_sums::add_weighted_avx2;
use crate::limb_sums::LimbSums;
use crate::options::Isa;
use crate::sampler::Sampler;

/// Rows of samples per work item; its block holds the apron besides.
const BAND_ROWS: u32 = 8;

/// Renders one pass (sample indices `pass` of every pixel) into `film` by splatting.
pub(crate) fn render_pass<S: Sampler>(
    ctx: &PassCtx,
    sampler: &S,
    film: &mut Film,
    pass: &Range<u32>,
) -> RenderStats {
    let (w, h) = (film.width, film.height);
    let filter = &ctx.scene.filter;
    let apron = apron_rows(filter.radius());
    // A pixel takes at most one share of each sample within the apron's reach per axis.
    let reach = 2 * apron as u64 + 1;
    let limbs = reach * reach * pass.len() as u64 <= LimbSums::CAPACITY;
    let bands: Vec<Range<u32>> = (0..h)
        .step_by(BAND_ROWS as usize)
        .map(|y0| y0..(y0 + BAND_ROWS).min(h))
        .collect();
    let blocks: Vec<(SplatBlock, RenderStats)> = bands
        .into_par_iter()
        .map(|rows| {
            let y0 = rows.start.saturating_sub(apron);
            let y1 = (rows.end + apron).min(h);
            let len = (w * (y1 - y0)) as usize;
            let mut block = SplatBlock {
                filter,
                width: w,
                height: h,
                y0,
                pixels: vec![Pixel::default(); len],
                limbs: vec![LimbSums::default(); if limbs { len } else { 0 }],
                isa: ctx.isa,
            };
            if ctx.cancel.load(Ordering::Relaxed) {
                return (block, RenderStats::default());
            }
            let done = rows.len() as u64 * w as u64 * pass.len() as u64;
            let band = Band {
                rows,
                width: w,
                pass: pass.clone(),
            };
            let mut sampler = sampler.clone();
            let stats = render_band(ctx.scene, ctx.isa, &mut sampler, band, &mut block);
            for (sums, pixel) in block.limbs.iter_mut().zip(&mut block.pixels) {
                sums.fold_into(pixel);
            }
            block.limbs = Vec::new();
            (ctx.progress)(done);
            (block, stats)
        })
        .collect();
    let mut stats = RenderStats::default();
    for (block, s) in blocks {
        let start = (block.y0 * w) as usize;
        for (a, b) in film.pixels[start..].iter_mut().zip(&block.pixels) {
            a.merge(b);
        }
        stats.paths += s.paths;
        stats.rays += s.rays;
    }
    stats
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

/// A work item's share of the film: rows from `y0`, the band's and its apron's.
struct SplatBlock<'a> {
    filter: &'a PixelFilter,
    width: u32,
    /// The image's height, which clips the footprint.
    height: u32,
    y0: u32,
    pixels: Vec<Pixel>,
    /// Shares pending for `pixels` (empty where a pass could exceed their capacity: the
    /// shares then go to the pixels directly).
    limbs: Vec<LimbSums>,
    /// The render loop's copy, which says whether the shares are added in AVX2.
    isa: Isa,
}

impl SampleSink for SplatBlock<'_> {
    const SPLATS: bool = true;

    /// Inlined into each copy of the render loop: in the v3 copy its floors and ceilings
    /// are single instructions and the AVX2 row is inlined, not called.
    #[inline(always)]
    fn add(&mut self, p: UVec2, film_pos: Vec2, l: Vec3) {
        let (y0, width) = (self.y0, self.width);
        let row = move |y: u32| ((y - y0) * width) as usize;
        if !self.pixels[row(p.y) + p.x as usize].count(l) {
            return;
        }
        let r = self.filter.radius();
        let xs = footprint(film_pos.x, r, self.width);
        #[cfg(target_arch = "x86_64")]
        if matches!(self.isa, Isa::V3) && !self.limbs.is_empty() {
            let ys = footprint(film_pos.y, r, self.height);
            // SAFETY: the render loop runs its v3 copy only where the CPU has it.
            if unsafe { self.add_in_lanes(xs.clone(), ys, film_pos, l) } {
                return;
            }
        }
        // At most 2⌈r⌉ + 1 weights per axis; a wider filter is computed per pixel.
        let mut wx = [0.0f32; 16];
        if xs.len() > wx.len() || self.limbs.is_empty() {
            return self.add_per_pixel(film_pos, l);
        }
        let wx = &mut wx[..xs.len()];
        for (w, x) in wx.iter_mut().zip(xs.clone()) {
            *w = self.filter.eval_axis(x as f32 + 0.5 - film_pos.x);
        }
        for y in footprint(film_pos.y, r, self.height) {
            let wy = self.filter.eval_axis(y as f32 + 0.5 - film_pos.y);
            if wy == 0.0 {
                continue;
            }
            let start = row(y) + xs.start as usize;
            let sums = &mut self.limbs[start..start + xs.len()];
            match self.isa {
                // SAFETY: the render loop runs its v3 copy only where the CPU has it.
                #[cfg(target_arch = "x86_64")]
                Isa::V3 => unsafe { add_row_avx2(sums, l, wx, wy) },
                // A zero weight adds nothing: its shares are zero.
                _ => {
                    for (s, &wx) in sums.iter_mut().zip(wx.iter()) {
                        s.add_weighted(l, wx * wy);
                    }
                }
            }
        }
    }
}

impl SplatBlock<'_> {
    /// [`SampleSink::add`]'s shares for a footprint of at most 4 × 4 pixels (a Gaussian
    /// of radius ≤ 2, Mitsuba's default) in AVX2: the 4 + 4 axis weights in one
    /// [`PixelFilter::eval_axis8`], a row's 4 products in one multiply, each pixel's four
    /// shares in one [`add_weighted_avx2`]. The same numbers as the scalar path. Returns
    /// false, adding nothing, where the footprint or the filter does not fit it.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma")]
    #[inline]
    fn add_in_lanes(&mut self, xs: Range<u32>, ys: Range<u32>, film_pos: Vec2, l: Vec3) -> bool {
        use std::arch::x86_64::*;
        if xs.len() > 4 || ys.len() > 4 {
            return false;
        }
        // Lanes 0‥3: the pixels xs.start + i; lanes 4‥7: ys.start + i (exact integers),
        // offset as `eval_axis`'s callers offset them: (q + ½) − film_pos.
        let lane = _mm256_setr_ps(0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0);
        let first = _mm256_set_m128(_mm_set1_ps(ys.start as f32), _mm_set1_ps(xs.start as f32));
        let pos = _mm256_set_m128(_mm_set1_ps(film_pos.y), _mm_set1_ps(film_pos.x));
        let offsets = _mm256_sub_ps(
            _mm256_add_ps(_mm256_add_ps(first, lane), _mm256_set1_ps(0.5)),
            pos,
        );
        let Some(w) = self.filter.eval_axis8(offsets) else {
            return false;
        };
        let wx = _mm256_castps256_ps128(w);
        let mut wy = [0.0f32; 4];
        // SAFETY: `wy` holds four f32.
        unsafe { _mm_storeu_ps(wy.as_mut_ptr(), _mm256_extractf128_ps::<1>(w)) };
        let rgb1 = crate::limb_sums::rgb1(l);
        for (y, &wy) in ys.zip(&wy) {
            // A zero weight adds nothing: its shares are zero.
            if wy == 0.0 {
                continue;
            }
            // The row's weights wx·wy, rounded to f32 as the scalar path rounds them.
            let mut weights = [0.0f64; 4];
            // SAFETY: `weights` holds four f64.
            unsafe {
                _mm256_storeu_pd(
                    weights.as_mut_ptr(),
                    _mm256_cvtps_pd(_mm_mul_ps(wx, _mm_set1_ps(wy))),
                )
            };
            let start = ((y - self.y0) * self.width + xs.start) as usize;
            let sums = &mut self.limbs[start..start + xs.len()];
            for (s, w) in sums.iter_mut().zip(&weights) {
                add_weighted_avx2(s, rgb1, _mm256_broadcast_sd(w));
            }
        }
        true
    }

    /// [`SampleSink::add`]'s shares straight into the pixels, each filter weight computed
    /// where it is used: for filters too wide for the per-axis cache and the limbs.
    fn add_per_pixel(&mut self, film_pos: Vec2, l: Vec3) {
        let r = self.filter.radius();
        let xs = footprint(film_pos.x, r, self.width);
        for y in footprint(film_pos.y, r, self.height) {
            let wy = self.filter.eval_axis(y as f32 + 0.5 - film_pos.y);
            if wy == 0.0 {
                continue;
            }
            let start = ((y - self.y0) * self.width) as usize;
            for x in xs.clone() {
                let wx = self.filter.eval_axis(x as f32 + 0.5 - film_pos.x);
                if wx != 0.0 {
                    self.pixels[start + x as usize].add_weighted(l, wx * wy);
                }
            }
        }
    }
}

/// One row of a sample's shares, `l` × `wx[i]` × `wy` into `sums[i]`, in AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma")]
fn add_row_avx2(sums: &mut [LimbSums], l: Vec3, wx: &[f32], wy: f32) {
    let rgb1 = crate::limb_sums::rgb1(l);
    for (s, &wx) in sums.iter_mut().zip(wx) {
        let w = std::arch::x86_64::_mm256_set1_pd((wx * wy) as f64);
        add_weighted_avx2(s, rgb1, w);
    }
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
}
