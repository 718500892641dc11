//! The path tracer: next event estimation towards one light chosen by the scene's
//! [`crate::light_sampler::LightSampler`], BSDF sampling, and the two combined by multiple
//! importance sampling (Veach 1997, ch. 9), with Russian roulette on the throughput.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

use glam::{UVec2, Vec2, Vec3};
use rayon::prelude::*;

use crate::bsdf::Bsdf;
use crate::desc::{FilterSampling, MisMode, SamplerKind};
use crate::film::{Film, Pixel};
use crate::filter::PixelFilter;
use crate::geometry::Ray;
use crate::light::{Light, LightId, LightSample, LightSource, ShadingCtx};
use crate::light_sampler::LightPick;
use crate::math::max_component;
use crate::sampler::{IndependentSampler, Sampler, SobolCmjSampler, SobolSampler};
use crate::sampling::{balance_heuristic, power_heuristic};
use crate::scene::{Scene, SurfaceInteraction};

mod volpath;

/// Rows per parallel work item.
const BAND_ROWS: usize = 4;

/// Counters of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Camera paths traced.
    pub paths: u64,
    /// Rays cast: camera, bounce and shadow rays.
    pub rays: u64,
}

impl RenderStats {
    fn add(self, o: RenderStats) -> RenderStats {
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
    }
}

/// [`render`] with a given sampler, monomorphized so that no sample is a dynamic call.
/// The scene's [`crate::desc::Isa`] chooses the compiled copy of the render loop.
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
    while start < samples.end && !cancel.load(Ordering::Relaxed) {
        let pass = start..(start + pass_spp).min(samples.end);
        if splat {
            let ctx = PassCtx {
                scene,
                isa,
                cancel,
                progress,
            };
            stats = stats.add(crate::splat::render_pass(&ctx, &sampler, &mut film, &pass));
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
    let cancelled = film.pixels.iter().any(|p| p.samples < spp);
    RenderResult {
        film,
        stats,
        cancelled,
    }
}

/// Marks a function compiled for x86-64-v3 (see [`crate::isa`]; the list is the one
/// `Isa::is_supported` detects).
macro_rules! v3_fn {
    ($f:item) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(
            enable = "avx,avx2,bmi1,bmi2,cmpxchg16b,f16c,fma,lzcnt,movbe,popcnt,sse3,sse4.1,sse4.2,ssse3,xsave"
        )]
        $f
    };
}

v3_fn! {
    /// [`render_pixels`] compiled for x86-64-v3.
    fn render_pixels_v3<S: Sampler, K: SampleSink>(
        scene: &Scene,
        sampler: &mut S,
        band: Band,
        sink: &mut K,
    ) -> RenderStats {
        render_pixels::<S, K, true>(scene, sampler, band, sink)
    }
}

/// What a render pass shares with its work items.
pub(crate) struct PassCtx<'a> {
    pub scene: &'a Scene,
    /// The resolved copy of the render loop (supported by the CPU).
    pub isa: crate::desc::Isa,
    pub cancel: &'a AtomicBool,
    pub progress: &'a (dyn Fn(u64) + Sync),
}

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

/// Takes a work item's samples with the render loop's copy `isa`, which the CPU must run.
pub(crate) fn render_band<S: Sampler, K: SampleSink>(
    scene: &Scene,
    isa: crate::desc::Isa,
    sampler: &mut S,
    band: Band,
    sink: &mut K,
) -> RenderStats {
    debug_assert!(isa.is_supported());
    match isa {
        // SAFETY: `render_with` asserted that the CPU has the resolved ISA.
        #[cfg(target_arch = "x86_64")]
        crate::desc::Isa::V3 => unsafe { render_pixels_v3(scene, sampler, band, sink) },
        _ => render_pixels::<S, K, false>(scene, sampler, band, sink),
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
/// its callees are compiled for each. `V3`: whether this is the x86-64-v3 copy (which
/// then calls the v3 copy of next event estimation).
#[inline(always)]
fn render_pixels<S: Sampler, K: SampleSink, const V3: bool>(
    scene: &Scene,
    sampler: &mut S,
    band: Band,
    sink: &mut K,
) -> RenderStats {
    let Band { rows, width, pass } = band;
    let mut stats = RenderStats::default();
    let pixels = rows.flat_map(|y| (0..width).map(move |x| UVec2::new(x, y)));
    for p in pixels {
        for index in pass.clone() {
            let (film_pos, ray) = camera_ray(scene, sampler, p, index, K::SPLATS);
            let l = li_isa::<S, V3>(scene, ray, sampler, &mut stats.rays);
            stats.paths += 1;
            sink.add(p, film_pos, l);
        }
    }
    stats
}

/// MIS weight of a strategy with density `pdf_f` against one with density `pdf_g`.
fn mis_weight(mode: MisMode, pdf_f: f32, pdf_g: f32) -> f32 {
    match mode {
        MisMode::Power => power_heuristic(pdf_f, pdf_g),
        _ => balance_heuristic(pdf_f, pdf_g),
    }
}

/// Radiance arriving along `ray`, estimated by one path.
#[inline(always)]
pub fn li<S: Sampler>(scene: &Scene, ray: Ray, sampler: &mut S, rays: &mut u64) -> Vec3 {
    li_isa::<S, false>(scene, ray, sampler, rays)
}

/// [`li`] in the copy of the render loop `V3` says (see [`render_pixels`]).
#[inline(always)]
fn li_isa<S: Sampler, const V3: bool>(
    scene: &Scene,
    mut ray: Ray,
    sampler: &mut S,
    rays: &mut u64,
) -> Vec3 {
    if let Some(media) = scene.media.as_deref() {
        return volpath::li(scene, media, ray, sampler, rays);
    }
    let mode = scene.settings.mis;
    let mut l = Vec3::ZERO;
    let mut beta = Vec3::ONE;
    // The product of η′² over the refractions so far (see `Bsdf::eta_crossed_sq`).
    let mut eta_scale = 1.0f32;
    let mut depth = 0u32;
    // Whether the path's last bounce was a delta lobe (or the path just left the camera):
    // then no light sampling could have found what the ray hits, so it counts in full.
    let mut specular = true;
    let mut prev_ctx = ShadingCtx {
        p: ray.o,
        n: Vec3::ZERO,
    };
    let mut prev_bsdf_pdf = 0.0f32;

    // Weight of emission found by BSDF sampling, against NEE having found it.
    let emitter_weight = |specular: bool,
                          prev_ctx: &ShadingCtx,
                          prev_bsdf_pdf: f32,
                          id: LightId,
                          d: Vec3| match mode {
        _ if specular => 1.0,
        MisMode::BsdfOnly => 1.0,
        MisMode::NeeOnly => 0.0,
        MisMode::Balance | MisMode::Power => {
            let light_pdf =
                scene.light_sampler.pmf(prev_ctx, id) * scene.light(id).pdf_li(prev_ctx, d);
            mis_weight(mode, prev_bsdf_pdf, light_pdf)
        }
    };

    loop {
        *rays += 1;
        // This bounce's numbers come before the traversal: they do not depend on the hit,
        // and their hashing (tens of cycles of dependent multiplies) then overlaps the
        // traversal instead of following it on the path's critical chain. The dimensions
        // are those of drawing them where they are used; a path that ends here wastes them.
        let u = (depth < scene.settings.max_depth).then(
            #[inline(always)]
            || BounceSamples::<S>::draw(scene, sampler),
        );
        let hit = scene.intersect(&ray, f32::INFINITY);
        if depth == 0
            && scene.settings.hide_emitters
            && hit.as_ref().is_none_or(|si| si.light.is_some())
        {
            break;
        }
        let Some(si) = hit.as_ref() else {
            for &id in &scene.infinite_lights {
                let light = scene.light(id);
                let (le, weight) = if depth == 0 {
                    (light.le_camera(&ray), 1.0)
                } else if !specular && matches!(mode, MisMode::Balance | MisMode::Power) {
                    // The radiance and the density MIS weighs it by, from one lookup.
                    let (le, pdf) = light.le_pdf(&prev_ctx, &ray);
                    let light_pdf = scene.light_sampler.pmf(&prev_ctx, id) * pdf;
                    (le, mis_weight(mode, prev_bsdf_pdf, light_pdf))
                } else {
                    let weight = emitter_weight(specular, &prev_ctx, prev_bsdf_pdf, id, ray.d);
                    (light.le(&ray), weight)
                };
                if le != Vec3::ZERO {
                    l += beta * le * weight;
                }
            }
            break;
        };
        let wo = -ray.d;
        if let Some(id) = si.light {
            let le = scene.light(id).radiance(si.ng, si.uv, wo);
            if le != Vec3::ZERO {
                l += beta * le * emitter_weight(specular, &prev_ctx, prev_bsdf_pdf, id, ray.d);
            }
        }
        let Some(u) = u else {
            break;
        };

        let bsdf = scene.materials[si.material.0 as usize].bsdf_at(si);
        let ctx = ShadingCtx { p: si.p, n: si.ns };
        // The next direction first: it does not depend on light sampling, so its chain of
        // divisions and square roots runs while the shadow ray is traced.
        let u_lobe = if bsdf.lobe.takes_lobe_sample() {
            sampler.resolve_1d(u.lobe)
        } else {
            0.5
        };
        let bs = bsdf.sample(wo, u_lobe, u.dir);
        if !bsdf.is_delta() {
            let v = NeeVertex {
                si,
                ctx: &ctx,
                bsdf: &bsdf,
                wo,
                u_light: u.light,
                u_point: u.point,
            };
            l += beta
                * match V3 {
                    // SAFETY: only the v3 copy of the render loop has `V3`, and `render_with`
                    // asserted that the CPU runs it.
                    #[cfg(target_arch = "x86_64")]
                    true => unsafe { sample_direct_v3(scene, &v, rays) },
                    _ => sample_direct_baseline(scene, &v, rays),
                };
        }
        let Some(bs) = bs else {
            break;
        };
        beta *= bs.f * (bsdf.abs_cos(bs.wi) / bs.pdf);
        specular = bs.flags.is_delta();
        prev_bsdf_pdf = bs.pdf;
        prev_ctx = ctx;
        ray = si.spawn_ray(bs.wi);
        depth += 1;

        eta_scale *= bsdf.eta_crossed_sq(wo, &bs);
        if depth < scene.settings.rr_depth {
            sampler.skip_1d();
        } else {
            let u_rr = sampler.get_1d();
            // Survival in proportion to the throughput, so survivors carry weight ~1.
            // No cap below 1 (Mitsuba caps at 0.95): in a white furnace a cap makes the
            // weights grow by 1/0.95 per bounce and the variance unbounded.
            let q = (1.0 - max_component(beta) * eta_scale).max(0.0);
            if u_rr < q {
                break;
            }
            beta *= 1.0 / (1.0 - q);
        }
        if beta == Vec3::ZERO || !beta.is_finite() {
            break;
        }
    }
    l
}

/// The numbers one bounce takes, in the order of their dimensions.
struct BounceSamples<S: Sampler> {
    /// The light pick (0.5, its dimension skipped, where there is one light).
    light: f32,
    /// The point on the light.
    point: Vec2,
    /// The BSDF's lobe choice, deferred: the hit is not known yet, and most BSDFs (one
    /// lobe) do not read it.
    lobe: S::Deferred1d,
    /// The BSDF direction.
    dir: Vec2,
}

impl<S: Sampler> BounceSamples<S> {
    #[inline(always)]
    fn draw(scene: &Scene, sampler: &mut S) -> BounceSamples<S> {
        // A number nothing reads is skipped, not computed (its dimension stays taken).
        let light = if scene.lights.len() > 1 {
            sampler.get_1d()
        } else {
            sampler.skip_1d();
            0.5
        };
        let point = sampler.get_2d();
        let lobe = sampler.defer_1d();
        let dir = sampler.get_2d();
        BounceSamples {
            light,
            point,
            lobe,
            dir,
        }
    }
}

/// [`sample_direct`] for the baseline target, out of line (inlined into the loop it
/// measured slower).
#[inline(never)]
fn sample_direct_baseline(scene: &Scene, v: &NeeVertex, rays: &mut u64) -> Vec3 {
    sample_direct(scene, v, rays)
}

v3_fn! {
    /// [`sample_direct`] compiled for x86-64-v3, out of line, called by the v3 copy of the
    /// loop.
    #[inline(never)]
    fn sample_direct_v3(scene: &Scene, v: &NeeVertex, rays: &mut u64) -> Vec3 {
        sample_direct(scene, v, rays)
    }
}

/// What next event estimation at a path vertex takes.
#[derive(Clone, Copy)]
struct NeeVertex<'a> {
    si: &'a SurfaceInteraction,
    ctx: &'a ShadingCtx,
    bsdf: &'a Bsdf,
    wo: Vec3,
    /// The light pick's number (see [`BounceSamples::light`]).
    u_light: f32,
    /// The point on the light.
    u_point: Vec2,
}

/// Next event estimation: one light picked by the light sampler, one point on it, a
/// shadow ray, and the MIS weight against BSDF sampling of the same direction.
#[inline(always)]
fn sample_direct(scene: &Scene, v: &NeeVertex, rays: &mut u64) -> Vec3 {
    let NeeVertex {
        si,
        ctx,
        bsdf,
        wo,
        u_light,
        u_point,
    } = *v;
    let mode = scene.settings.mis;
    let Some(pick) = scene.light_sampler.sample(ctx, u_light, &scene.lights) else {
        return Vec3::ZERO;
    };
    let id = pick.id;
    let light = scene.light(id);
    // BSDF-only estimation still needs NEE for delta lights, which no ray can hit.
    if mode == MisMode::BsdfOnly && !light.is_delta() {
        return Vec3::ZERO;
    }
    // Flat area lights, most scenes' lamps, get a copy of the rest of NEE of their own:
    // merged with the other lights' samples, which come back through memory, their sample
    // went through the stack too, stored field by field and loaded back in other pieces (a
    // failed store forwarding on every shadow ray).
    let ls = match light {
        Light::Parallelogram(p) => p.sample_li(ctx, u_point),
        Light::Triangle(t) => t.sample_li(ctx, u_point),
        _ => {
            return light_contribution(
                scene,
                si,
                bsdf,
                wo,
                &pick,
                light.sample_li(ctx, u_point),
                rays,
            )
        }
    };
    light_contribution(
        scene,
        si,
        bsdf,
        wo,
        &pick,
        ls.and_then(LightSample::usable),
        rays,
    )
}

/// The rest of [`sample_direct`], from the light's sample on: the BSDF, the shadow ray and
/// the MIS weight.
#[inline(always)]
fn light_contribution(
    scene: &Scene,
    si: &SurfaceInteraction,
    bsdf: &Bsdf,
    wo: Vec3,
    pick: &LightPick,
    ls: Option<LightSample>,
    rays: &mut u64,
) -> Vec3 {
    let mode = scene.settings.mis;
    let Some(ls) = ls else {
        return Vec3::ZERO;
    };
    let (f, bsdf_pdf) = bsdf.f_cos_pdf(wo, ls.wi);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    *rays += 1;
    let visible = if ls.distance.is_finite() {
        scene.unoccluded(si.p, si.ng, ls.p_light, ls.n_light)
    } else {
        scene.escapes(si.p, si.ng, ls.wi)
    };
    if !visible {
        return Vec3::ZERO;
    }
    // For RIS, `pick.pmf` is 1/W (the unbiased RIS weight) and `pick.mis_pmf` a tractable
    // surrogate of the pick probability; `emitter_weight` uses the same surrogate
    // (`LightSampler::pmf`), so the NEE and BSDF weights of any (light, direction) still
    // sum to one (see `light_sampler::ris`). For the other samplers the two are equal.
    let weight = match mode {
        _ if ls.is_delta => 1.0,
        MisMode::NeeOnly => 1.0,
        _ => mis_weight(mode, pick.mis_pmf * ls.pdf, bsdf_pdf),
    };
    f * ls.radiance * (weight / (pick.pmf * ls.pdf))
}
