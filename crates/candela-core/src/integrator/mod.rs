//! The path tracer: next event estimation towards one light chosen by the scene's
//! [`crate::light_sampler::LightSampler`], BSDF sampling, and the two combined by multiple
//! importance sampling (Veach 1997, ch. 9), with Russian roulette on the throughput.
//!
//! One concern per file, in the order a render runs through them:
//! - here: the entry point [`render`], which picks the sampler, and the records a render
//!   returns;
//! - `schedule`: passes over the image and bands of rows on the thread pool;
//! - `copies`: the compiled copies of the render loop (baseline and x86-64-v3) and the
//!   dispatch between them;
//! - `band`: one work item's pixel samples, each its camera ray and its path;
//! - `path`: the path loop ([`li`]) for scenes without media;
//! - `lanes`: the lanes integrator, eight paths at a time in SIMD lanes, for scenes
//!   without media that ask for it ([`crate::options::IntegratorKind::Lanes`]);
//! - `direct`: next event estimation and its MIS weight;
//! - `volpath`: the volumetric path tracer, for scenes with media.

use std::ops::Range;
use std::sync::atomic::AtomicBool;

use crate::film::Film;
use crate::options::SamplerKind;
use crate::sampler::{IndependentSampler, SobolCmjSampler, SobolSampler, ZSobolSampler};
use crate::scene::Scene;

mod band;
mod copies;
mod direct;
mod lanes;
mod path;
mod schedule;
mod sky;
mod volpath;

pub(crate) use band::{camera_ray, Band, SampleSink};
pub(crate) use copies::render_band;
pub use lanes::lanes_fallback;
pub use path::li;
pub use schedule::render_with;
pub(crate) use schedule::PassCtx;

/// Counters of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Camera paths traced.
    pub paths: u64,
    /// Rays cast: camera, bounce and shadow rays.
    pub rays: u64,
}

impl RenderStats {
    /// The stats of two disjoint sets of paths together.
    pub(crate) fn add(self, o: RenderStats) -> RenderStats {
        RenderStats {
            paths: self.paths + o.paths,
            rays: self.rays + o.rays,
        }
    }
}

/// What a render produced: the film (possibly partial) and its counters.
#[derive(Clone, Debug)]
pub struct RenderResult {
    pub film: Film,
    pub stats: RenderStats,
    /// Whether the cancel flag stopped the render before all samples were taken.
    pub cancelled: bool,
}

/// Renders samples `samples` (a range of sample indices, e.g. `0..spp`) of every pixel.
/// Works in passes of a few samples over the whole image; between work items it checks
/// `cancel`, and after each item it reports the number of pixel samples done to
/// `progress`. The result depends only on the scene, its seed and the range: not on the
/// thread count or the order of work. The scene's [`SamplerKind`] chooses the sampler.
pub fn render(
    scene: &Scene,
    samples: Range<u32>,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64) + Sync),
) -> RenderResult {
    let seed = scene.settings.seed;
    match scene.settings.sampler {
        SamplerKind::Independent => render_with(
            scene,
            IndependentSampler::new(seed),
            samples,
            cancel,
            progress,
        ),
        SamplerKind::Sobol => {
            render_with(scene, SobolSampler::new(seed), samples, cancel, progress)
        }
        SamplerKind::SobolCmj => {
            let s =
                SobolCmjSampler::new(seed, scene.settings.spp, scene.camera.needs_lens_sample());
            render_with(scene, s, samples, cancel, progress)
        }
        SamplerKind::Zsobol => {
            let settings = &scene.settings;
            let s = ZSobolSampler::new(seed, settings.spp, settings.width, settings.height);
            render_with(scene, s, samples, cancel, progress)
        }
    }
}
