//! Scheduling a render over the thread pool: passes of a few samples over the whole image
//! (so that a cancelled render is even), each pass split into bands of rows that rayon's
//! threads take in any order. The result does not depend on the order: each band writes
//! its own pixels (or, splatting, its own block; see [`crate::splat`]).

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

use glam::{UVec2, Vec2, Vec3};
use rayon::prelude::*;

use super::band::{Band, SampleSink};
use super::copies::render_band;
use super::{RenderResult, RenderStats};
use crate::film::{Film, Pixel};
use crate::filter::PixelFilter;
use crate::options::FilterSampling;
use crate::sampler::Sampler;
use crate::scene::Scene;

/// Rows per parallel work item.
const BAND_ROWS: usize = 4;

/// [`super::render`] with a given sampler, monomorphized so that no sample is a dynamic call.
/// The scene's [`crate::options::Isa`] chooses the compiled copy of the render loop.
pub fn render_with<S: Sampler>(
    scene: &Scene,
    sampler: S,
    samples: Range<u32>,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64) + Sync),
) -> RenderResult {
    let (w, h) = (scene.settings.width, scene.settings.height);
    let isa = scene.settings.isa.resolve();
    assert!(
        isa.is_supported(),
        "{isa:?} render loop on a CPU without it"
    );
    let mut film = Film::new(w, h);
    let spp = samples.len() as u32;
    let pass_spp = (spp / 16).clamp(1, 8);
    let mut stats = RenderStats::default();
    let mut start = samples.start;
    let splat = scene.settings.filter_sampling == FilterSampling::Splat
        && !matches!(scene.filter, PixelFilter::Box);
    let mut splats = splat.then(|| crate::splat::Splats::new(&scene.filter, w, h, pass_spp));
    while start < samples.end && !cancel.load(Ordering::Relaxed) {
        let pass = start..(start + pass_spp).min(samples.end);
        if let Some(splats) = &mut splats {
            let ctx = PassCtx {
                scene,
                isa,
                cancel,
                progress,
            };
            stats = stats.add(splats.render_pass(&ctx, &sampler, &mut film, &pass));
            start = pass.end;
            continue;
        }
        let pass_stats = film
            .pixels
            .par_chunks_mut(w as usize * BAND_ROWS)
            .enumerate()
            .map(|(band, pixels)| {
                if cancel.load(Ordering::Relaxed) {
                    return RenderStats::default();
                }
                let mut sampler = sampler.clone();
                let done = pixels.len() as u64 * pass.len() as u64;
                let y0 = (band * BAND_ROWS) as u32;
                let band = Band {
                    rows: y0..y0 + (pixels.len() / w as usize) as u32,
                    width: w,
                    pass: pass.clone(),
                };
                let mut sink = OwnPixels {
                    pixels,
                    width: w,
                    y0,
                };
                let s = render_band(scene, isa, &mut sampler, band, &mut sink);
                progress(done);
                s
            })
            .reduce(RenderStats::default, RenderStats::add);
        stats = stats.add(pass_stats);
        start = pass.end;
    }
    if let Some(mut splats) = splats {
        splats.fold_into(&mut film);
    }
    let cancelled = film.pixels.iter().any(|p| p.samples < spp);
    RenderResult {
        film,
        stats,
        cancelled,
    }
}

/// What a render pass shares with its work items.
pub(crate) struct PassCtx<'a> {
    pub scene: &'a Scene,
    /// The resolved copy of the render loop (supported by the CPU).
    pub isa: crate::options::Isa,
    pub cancel: &'a AtomicBool,
    pub progress: &'a (dyn Fn(u64) + Sync),
}

/// Filter importance sampling's sink: each sample to its own pixel, with weight 1.
struct OwnPixels<'a> {
    /// Rows from `y0`.
    pixels: &'a mut [Pixel],
    width: u32,
    y0: u32,
}

impl SampleSink for OwnPixels<'_> {
    const SPLATS: bool = false;
    #[inline(always)]
    fn add(&mut self, p: UVec2, _film_pos: Vec2, l: Vec3) {
        self.pixels[((p.y - self.y0) * self.width + p.x) as usize].add(l, 1.0);
    }
}
