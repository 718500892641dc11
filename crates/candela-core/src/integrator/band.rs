//! One work item: a band of rows and the sample indices to take in each of its pixels.
//! Each pixel sample starts with its camera ray ([`camera_ray`]), follows one path and
//! hands its radiance to the item's [`SampleSink`].

use std::ops::Range;

use glam::{UVec2, Vec2, Vec3};

use super::path::{li, li_from_hit};
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
    /// [`Self::add`] from the copy of the render loop that `V3` names (true: the
    /// x86-64-v3 copy, whose CPU has AVX2 and FMA): a sink may inline its AVX2 code there,
    /// which it cannot from [`Self::add`], compiled for every copy. The same result.
    #[inline(always)]
    fn add_in<const V3: bool>(&mut self, p: UVec2, film_pos: Vec2, l: Vec3) {
        self.add(p, film_pos, l);
    }
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
/// each. Where the scene packs camera rays ([`Scene::packs_camera_rays`]) and has no
/// media, the camera rays go eight at a time ([`render_pixels_packed`]). `V3`: whether
/// this is the x86-64-v3 copy (see [`SampleSink::add_in`]).
#[inline(always)]
pub(super) fn render_pixels<S: Sampler, K: SampleSink, const V3: bool>(
    scene: &Scene,
    sampler: &mut S,
    band: Band,
    sink: &mut K,
) -> RenderStats {
    if scene.media.is_none() && scene.packs_camera_rays() {
        return render_pixels_packed::<S, K, V3>(scene, sampler, band, sink);
    }
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
                sink.add_in::<V3>(p, film_pos, l);
            }
        }
    }
    stats
}

/// [`render_pixels`] with the camera rays of eight consecutive samples of the band
/// (in its order: the samples of a pixel, then the next pixel's, across rows) traced
/// as one packet ([`Scene::intersect_coherent8`]); then each path goes on from its
/// hit ([`li_from_hit`]) and its radiance goes to the sink, in the band's order. Each
/// of the eight samples has its own sampler, positioned at its pixel sample, which
/// draws the same dimensions in the same order as one sampler taking the samples one
/// after the other: the image is the same, bit for bit.
#[inline(always)]
fn render_pixels_packed<S: Sampler, K: SampleSink, const V3: bool>(
    scene: &Scene,
    sampler: &mut S,
    band: Band,
    sink: &mut K,
) -> RenderStats {
    let Band { rows, width, pass } = band;
    let mut stats = RenderStats::default();
    let mut packet = CameraPacket {
        samplers: std::array::from_fn(|_| sampler.clone()),
        film: [(UVec2::ZERO, Vec2::ZERO); PACKET],
        rays: [Ray::new(Vec3::ZERO, Vec3::NEG_Z); PACKET],
        len: 0,
    };
    for y in rows {
        for x in 0..width {
            let p = UVec2::new(x, y);
            for index in pass.clone() {
                let i = packet.len;
                let (film_pos, ray) =
                    camera_ray(scene, &mut packet.samplers[i], p, index, K::SPLATS);
                packet.film[i] = (p, film_pos);
                packet.rays[i] = ray;
                packet.len += 1;
                if packet.len == PACKET {
                    packet.finish::<K, V3>(scene, sink, &mut stats);
                }
            }
        }
    }
    if packet.len > 0 {
        packet.finish::<K, V3>(scene, sink, &mut stats);
    }
    stats
}

/// Camera rays traced together.
const PACKET: usize = 8;

/// Up to eight pixel samples whose camera rays are made and not yet traced: each one's
/// sampler, pixel and film position, and ray.
struct CameraPacket<S: Sampler> {
    samplers: [S; PACKET],
    film: [(UVec2, Vec2); PACKET],
    rays: [Ray; PACKET],
    len: usize,
}

impl<S: Sampler> CameraPacket<S> {
    /// Traces the rays, follows each path from its hit and hands the radiance to
    /// `sink`, in the order the samples came; the packet is then empty.
    #[inline(always)]
    fn finish<K: SampleSink, const V3: bool>(
        &mut self,
        scene: &Scene,
        sink: &mut K,
        stats: &mut RenderStats,
    ) {
        let hits = scene.intersect_coherent8(&self.rays, (1u32 << self.len) - 1);
        let samples = (self.samplers.iter_mut().zip(hits))
            .zip(self.film.iter().zip(&self.rays))
            .take(self.len);
        for ((sampler, hit), (&(p, film_pos), &ray)) in samples {
            let l = li_from_hit(scene, ray, hit, sampler, &mut stats.rays);
            stats.paths += 1;
            sink.add_in::<V3>(p, film_pos, l);
        }
        self.len = 0;
    }
}
