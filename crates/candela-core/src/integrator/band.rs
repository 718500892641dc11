//! One work item: a band of rows and the sample indices to take in each of its pixels.
//! Each pixel sample starts with its camera ray ([`camera_ray`]), follows one path and
//! hands its radiance to the item's [`SampleSink`].

use std::ops::Range;

use glam::{UVec2, Vec2, Vec3};

use super::path::li;
use super::RenderStats;
use crate::filter::PixelFilter;
use crate::geometry::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;

/// One work item: rows `rows` of an image `width` pixels wide, and the sample indices to
/// take in each of their pixels.
pub(crate) struct Band {
    pub rows: Range<u32>,
    pub width: u32,
    pub pass: Range<u32>,
}

/// Where a work item's samples go.
pub(crate) trait SampleSink {
    /// Whether samples are splatted: then each sample lies uniformly in its pixel and the
    /// sink spreads it under the filter; else its offset is drawn from the filter.
    const SPLATS: bool;
    /// Takes the radiance `l` of a sample of pixel `p` at film position `film_pos`.
    fn add(&mut self, p: UVec2, film_pos: Vec2, l: Vec3);
}

/// Starts pixel sample `index` of pixel `p` and makes its camera ray: the film position
/// (uniform in the pixel for the box filter and where the sample is splatted, else drawn
/// from the filter) and the ray through it. A pinhole takes no lens dimensions, so its
/// streams are as they were before lenses. The AOV pass makes its rays here too (with
/// `splats` false: the filter's own positions).
#[inline(always)]
pub(crate) fn camera_ray<S: Sampler>(
    scene: &Scene,
    sampler: &mut S,
    p: UVec2,
    index: u32,
    splats: bool,
) -> (Vec2, Ray) {
    sampler.start_pixel_sample(p, index);
    let u_pixel = sampler.get_pixel_2d();
    let film_pos = match scene.filter {
        PixelFilter::Box => p.as_vec2() + u_pixel,
        _ if splats => p.as_vec2() + u_pixel,
        ref f => p.as_vec2() + 0.5 + f.sample(u_pixel),
    };
    let lens_u = if scene.camera.needs_lens_sample() {
        sampler.get_2d()
    } else {
        Vec2::splat(0.5)
    };
    (film_pos, scene.camera.generate_lens_ray(film_pos, lens_u))
}

/// Takes a band's samples; inlined into each copy of the render loop, so that it and
/// its callees (the path loop and its next event estimation included) are compiled for
/// each.
#[inline(always)]
pub(super) fn render_pixels<S: Sampler, K: SampleSink>(
    scene: &Scene,
    sampler: &mut S,
    band: Band,
    sink: &mut K,
) -> RenderStats {
    let Band { rows, width, pass } = band;
    let mut stats = RenderStats::default();
    // Plain nested loops: a `flat_map` over the rows kept its inner iterator's state in
    // memory (about ten instructions a path more).
    for y in rows {
        for x in 0..width {
            let p = UVec2::new(x, y);
            for index in pass.clone() {
                let (film_pos, ray) = camera_ray(scene, sampler, p, index, K::SPLATS);
                let l = li(scene, ray, sampler, &mut stats.rays);
                stats.paths += 1;
                sink.add(p, film_pos, l);
            }
        }
    }
    stats
}
