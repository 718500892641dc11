//! The AOV pass: one camera ray per pixel sample, in parallel over bands of rows.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

use glam::UVec2;
use rayon::prelude::*;

use super::{first_surface, AovFilm, AovPixel};
use crate::integrator::camera_ray;
use crate::options::SamplerKind;
use crate::sampler::{IndependentSampler, Sampler, SobolCmjSampler, SobolSampler, ZSobolSampler};
use crate::scene::Scene;

/// Rows per parallel work item.
const BAND_ROWS: usize = 4;

/// Renders the passes of samples `samples` of every pixel. Each sample's camera ray is
/// the path tracer's for the same pixel and index (the scene's sampler and seed, the
/// same first dimensions), so the passes are antialiased over the beauty's own sample
/// positions; the numbers after the camera's choose the delta lobes. Between bands it
/// checks `cancel`, leaving the rest of the film at zero samples.
pub fn render_aovs(scene: &Scene, samples: Range<u32>, cancel: &AtomicBool) -> AovFilm {
    let seed = scene.settings.seed;
    match scene.settings.sampler {
        SamplerKind::Independent => {
            render_with(scene, IndependentSampler::new(seed), samples, cancel)
        }
        SamplerKind::Sobol => render_with(scene, SobolSampler::new(seed), samples, cancel),
        SamplerKind::SobolCmj => {
            let s =
                SobolCmjSampler::new(seed, scene.settings.spp, scene.camera.needs_lens_sample());
            render_with(scene, s, samples, cancel)
        }
        SamplerKind::Zsobol => {
            let settings = &scene.settings;
            let s = ZSobolSampler::new(seed, settings.spp, settings.width, settings.height);
            render_with(scene, s, samples, cancel)
        }
    }
}

fn render_with<S: Sampler>(
    scene: &Scene,
    sampler: S,
    samples: Range<u32>,
    cancel: &AtomicBool,
) -> AovFilm {
    let (w, h) = (scene.settings.width, scene.settings.height);
    let mut film = AovFilm::new(w, h);
    film.pixels
        .par_chunks_mut(w as usize * BAND_ROWS)
        .enumerate()
        .for_each(|(band, pixels)| {
            if cancel.load(Ordering::Relaxed) {
                return;
            }
            let mut sampler = sampler.clone();
            let y0 = (band * BAND_ROWS) as u32;
            for (i, pixel) in pixels.iter_mut().enumerate() {
                let p = UVec2::new(i as u32 % w, y0 + i as u32 / w);
                render_pixel(scene, &mut sampler, p, samples.clone(), pixel);
            }
        });
    film
}

/// Takes samples `samples` of pixel `p`.
fn render_pixel<S: Sampler>(
    scene: &Scene,
    sampler: &mut S,
    p: UVec2,
    samples: Range<u32>,
    pixel: &mut AovPixel,
) {
    for index in samples {
        // The camera ray of the beauty's filter importance sampling, number for number.
        let (_, ray) = camera_ray(scene, sampler, p, index, false);
        pixel.add(first_surface(scene, ray, sampler).as_ref());
    }
}
