//! The lanes integrator: eight paths at a time, one per SIMD lane, each lane refilled with
//! the band's next pixel sample as soon as its path ends (path regeneration, Novák et al.
//! 2010), so the lanes stay busy while paths of different lengths finish.
//!
//! It estimates what the path integrator ([`super::path`]) does, with the same numbers: each
//! lane has its own sampler, positioned at its pixel sample as the path integrator's is,
//! and draws the same dimensions in the same order (all lanes' at once where the sampler
//! can: [`Sampler::draw_bounce_lanes`]). Each bounce runs in two stages:
//! - per lane, scalar (`shade_lane`): the bounce's numbers, the closest hit (the busy
//!   lanes' rays traced together before this stage where the scene packs rays:
//!   [`Scene::intersect_coherent8`], each hit the single query's bit for bit), emission
//!   found, the BSDF at the hit, next event estimation up to its shadow ray, and the
//!   direction of every lobe but the Lambertian one; then, where the scene packs rays,
//!   the lanes' shadow rays, traced together ([`shadow`]);
//! - in lanes (`advance`): the Lambertian lobe's directions ([`diffuse`]), the throughput
//!   update and Russian roulette, for all eight paths at once.
//!
//! The radiance of each pixel sample is kept and handed to the sink in the band's order
//! once the band is done, so the image does not depend on the order in which lanes
//! finish; it equals the path integrator's wherever the lanes compute what the scalar code
//! does bit for bit. Scenes with media are not covered: they take the path integrator's
//! volumetric loop ([`lanes_fallback`] says so).
//!
//! One concern per file: `simd` (the lane types), `state` (the paths' state in lanes),
//! `diffuse` (the Lambertian lobe in lanes), `shadow` (the lanes' shadow rays), here the
//! bounce loop and its lane refill.

mod diffuse;
mod shadow;
mod simd;
mod state;

use glam::{UVec2, Vec2, Vec3};

use self::diffuse::DiffuseLanes;
use self::shadow::ShadowLanes;
#[cfg(target_arch = "x86_64")]
use self::simd::Avx2;
use self::simd::{F32x8, LaneIsa, Lanes32, M32x8, Portable, Vec3Lanes, Vec3x8, LANES};
use self::state::PathLanes;
use super::band::{camera_ray, Band, SampleSink};
use super::direct::ShadowedLight;
use super::path::{add_emitted, add_escaped, direct_out_of_line, hides_emitter, BounceSamples};
use super::RenderStats;
use crate::accel::Hit;
use crate::bsdf::Lobe;
use crate::light::ShadingCtx;
use crate::options::IntegratorKind;
use crate::sampler::{BounceDraws, Sampler};
use crate::scene::Scene;

/// Why the lanes integrator, where a scene asks for it, does not render it: `None` where
/// it does (or where the scene asks for the path integrator).
pub fn lanes_fallback(scene: &Scene) -> Option<&'static str> {
    (scene.settings.integrator == IntegratorKind::Lanes && scene.media.is_some())
        .then_some("scenes with participating media are not covered by the lanes integrator")
}

/// What one bounce's scalar stage leaves for the lane stage, lane by lane.
struct BounceLanes {
    /// Lanes whose vertex scatters: the path goes on if its direction is valid.
    shaded: [bool; LANES],
    /// Shaded lanes with a Lambertian BSDF: `lambert` holds them and the lane stage
    /// samples their direction from `u_dir`.
    diffuse: [bool; LANES],
    /// The BSDF's shading normal of every shaded lane, and the rest of the Lambertian
    /// lanes' BSDF.
    lambert: DiffuseLanes,
    u_dir: [Lanes32; 2],
    /// The direction, value and density the scalar code sampled in the other shaded
    /// lanes; after the lane stage, every shaded lane's direction and density.
    f: Vec3Lanes,
    wi: Vec3Lanes,
    pdf: Lanes32,
    /// Whether that direction came from a delta lobe.
    delta: [bool; LANES],
    /// η′² of the crossing (1 where the direction does not refract).
    eta_crossed_sq: Lanes32,
    /// Lanes where Russian roulette plays after this bounce, and their numbers.
    roulette: [bool; LANES],
    u_rr: Lanes32,
}

impl BounceLanes {
    /// Forgets the last bounce: only the flags need it (the values are written for the
    /// lanes the flags select).
    #[inline(always)]
    fn clear(&mut self) {
        self.shaded = [false; LANES];
        self.diffuse = [false; LANES];
        self.roulette = [false; LANES];
    }

    fn new() -> BounceLanes {
        BounceLanes {
            shaded: [false; LANES],
            diffuse: [false; LANES],
            lambert: DiffuseLanes {
                ns: Vec3Lanes::ZERO,
                ng: Vec3Lanes::ZERO,
                wo: Vec3Lanes::ZERO,
                albedo: Vec3Lanes::ZERO,
                one_sided: [false; LANES],
            },
            u_dir: [[0.0; LANES]; 2],
            f: Vec3Lanes::ZERO,
            wi: Vec3Lanes::ZERO,
            pdf: [1.0; LANES],
            delta: [false; LANES],
            eta_crossed_sq: [1.0; LANES],
            roulette: [false; LANES],
            u_rr: [0.0; LANES],
        }
    }
}

/// Takes a band's samples with the lanes integrator; inlined into each copy of the render
/// loop, as [`super::band::render_pixels`]. `V3`: whether this is the x86-64-v3 copy.
#[inline(always)]
#[allow(clippy::needless_range_loop)]
pub(super) fn render_lanes<S: Sampler, K: SampleSink, const V3: bool>(
    scene: &Scene,
    sampler: &mut S,
    band: Band,
    sink: &mut K,
) -> RenderStats {
    let Band { rows, width, pass } = band;
    let total = rows.len() * width as usize * pass.len();
    // The band's pixel samples, pixel-major as `render_pixels` takes them, numbered.
    let mut pending = rows
        .flat_map(|y| (0..width).map(move |x| UVec2::new(x, y)))
        .flat_map(|p| pass.clone().map(move |index| (p, index)))
        .enumerate();
    let mut results = vec![(UVec2::ZERO, Vec2::ZERO, Vec3::ZERO); total];
    let mut stats = RenderStats {
        paths: total as u64,
        rays: 0,
    };
    let mut lanes = PathLanes::new(sampler);
    let mut refill = |lanes: &mut PathLanes<S>, i: usize| {
        let Some((slot, (p, index))) = pending.next() else {
            lanes.slot[i] = None;
            return;
        };
        let (film_pos, ray) = camera_ray(scene, &mut lanes.samplers[i], p, index, K::SPLATS);
        lanes.start(i, slot, p, film_pos, ray);
    };
    for i in 0..LANES {
        refill(&mut lanes, i);
    }
    let mut b = BounceLanes::new();
    // Whether the busy lanes' rays are traced together (else each lane traces its own).
    let packs = scene.packs_camera_rays();
    let mut traced = [None; LANES];
    let mut shadows = ShadowLanes::new();
    while lanes.slot.iter().any(Option::is_some) {
        b.clear();
        shadows.clear();
        // The bounce's numbers of all lanes at once where the sampler can (the independent
        // sampler in the v3 copy); idle lanes and lanes whose path ends here draw too,
        // which changes nothing: a lane's stream restarts with its next pixel sample.
        let drawn = S::draw_bounce_lanes(&mut lanes.samplers, V3);
        if packs {
            traced = scene.intersect_coherent8(&lanes.ray, lanes.busy());
        }
        for i in 0..LANES {
            if lanes.slot[i].is_some() {
                let drawn = drawn.as_ref();
                let hit = packs.then_some(traced[i]);
                b.shaded[i] = shade_lane::<S, V3>(
                    scene,
                    &mut lanes,
                    &mut b,
                    drawn,
                    hit,
                    &mut shadows,
                    i,
                    &mut stats.rays,
                );
            }
        }
        shadows.finish(scene, &mut lanes.l);
        let alive = match V3 {
            #[cfg(target_arch = "x86_64")]
            true => advance::<Avx2, S>(&mut lanes, &mut b),
            _ => advance::<Portable, S>(&mut lanes, &mut b),
        };
        for i in 0..LANES {
            let Some(slot) = lanes.slot[i] else {
                continue;
            };
            if alive & (1 << i) != 0 {
                let si = lanes.hit[i].as_ref().expect("a shaded lane has a hit");
                lanes.ray[i] = si.spawn_ray(b.wi.lane(i));
                lanes.specular[i] = b.delta[i];
                lanes.prev[i].bsdf_pdf = b.pdf[i];
                lanes.depth[i] += 1;
            } else {
                results[slot] = (lanes.pixel[i], lanes.film_pos[i], lanes.l[i]);
                refill(&mut lanes, i);
            }
        }
    }
    for &(p, film_pos, l) in &results {
        sink.add(p, film_pos, l);
    }
    stats
}

/// The scalar stage of lane `i`'s bounce, as the path integrator's loop body up to the
/// throughput update: draws the bounce's numbers, traces the lane's ray, adds the emission
/// found to its radiance, holds next event estimation's light and shadow ray in
/// `shadows`, and leaves in `b` what the lane stage needs to continue the path. Returns whether the path scatters here (else it ends).
/// `drawn`: the bounce's numbers of every lane, where the sampler drew them at once; else
/// the lane draws its own. `traced`: the ray's closest hit, where the lanes' rays are
/// traced together ([`Scene::intersect_coherent8`]; their shadow rays are then held in
/// `shadows`, to be traced together too); else the lane traces its own rays.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn shade_lane<S: Sampler, const V3: bool>(
    scene: &Scene,
    lanes: &mut PathLanes<S>,
    b: &mut BounceLanes,
    drawn: Option<&BounceDraws<S::Deferred1d>>,
    traced: Option<Option<Hit>>,
    shadows: &mut ShadowLanes,
    i: usize,
    rays: &mut u64,
) -> bool {
    *rays += 1;
    let depth = lanes.depth[i];
    let sampler = &mut lanes.samplers[i];
    let u = (depth < scene.settings.max_depth).then(
        #[inline(always)]
        || match drawn {
            // As `BounceSamples::draw`: the light pick is 0.5 where there is one light.
            Some(d) => BounceSamples {
                light: if scene.lights.len() > 1 {
                    d.light[i]
                } else {
                    0.5
                },
                point: Vec2::new(d.point[0][i], d.point[1][i]),
                lobe: d.lobe[i],
                dir: Vec2::new(d.dir[0][i], d.dir[1][i]),
            },
            None => BounceSamples::<S>::draw(scene, sampler),
        },
    );
    let ray = lanes.ray[i];
    lanes.hit[i] = match traced {
        Some(hit) => scene.interaction_of(&ray, hit),
        None => scene.intersect_for_shading(&ray, f32::INFINITY),
    };
    let hit = lanes.hit[i].as_ref();
    if hides_emitter(scene, depth, hit) {
        return false;
    }
    let (specular, prev, beta) = (lanes.specular[i], &lanes.prev[i], lanes.beta.lane(i));
    let l = &mut lanes.l[i];
    let Some(si) = hit else {
        add_escaped(scene, &ray, depth, specular, prev, beta, l);
        return false;
    };
    let wo = -ray.d;
    add_emitted(scene, si, &ray, specular, prev, beta, l);
    let Some(u) = u else {
        return false;
    };

    let bsdf = scene.materials[si.material.0 as usize].bsdf_at(si);
    let ctx = ShadingCtx { p: si.p, n: si.ns };
    b.lambert.ns.set_lane(i, bsdf.frame.n);
    let sampled = match bsdf.lobe {
        Lobe::Diffuse(d) => {
            b.diffuse[i] = true;
            b.delta[i] = false;
            b.eta_crossed_sq[i] = 1.0;
            b.lambert.ng.set_lane(i, bsdf.ng);
            b.lambert.wo.set_lane(i, wo);
            b.lambert.albedo.set_lane(i, d.albedo);
            b.lambert.one_sided[i] = bsdf.one_sided;
            (b.u_dir[0][i], b.u_dir[1][i]) = (u.dir.x, u.dir.y);
            None
        }
        _ => {
            let u_lobe = if bsdf.lobe.takes_lobe_sample() {
                sampler.resolve_1d(u.lobe)
            } else {
                0.5
            };
            Some(bsdf.sample(wo, u_lobe, u.dir))
        }
    };
    if !bsdf.is_delta() {
        // The shadow ray held for the lanes' query where their rays are traced together,
        // else traced at once.
        if traced.is_some() {
            let light: Option<ShadowedLight> =
                direct_out_of_line::<S, V3, _>(scene, si, &ctx, &bsdf, wo, &u, rays);
            if let Some(light) = light {
                shadows.hold(i, beta * light.value, light.shadow);
            }
        } else {
            let light: Vec3 = direct_out_of_line::<S, V3, _>(scene, si, &ctx, &bsdf, wo, &u, rays);
            *l += beta * light;
        }
    }
    match sampled {
        None => {}
        Some(None) => return false,
        Some(Some(bs)) => {
            b.f.set_lane(i, bs.f);
            b.wi.set_lane(i, bs.wi);
            b.pdf[i] = bs.pdf;
            b.delta[i] = bs.flags.is_delta();
            b.eta_crossed_sq[i] = bsdf.eta_crossed_sq(wo, &bs);
        }
    }
    lanes.prev[i].ctx = ctx;
    if depth + 1 < scene.settings.rr_depth {
        if drawn.is_none() {
            sampler.skip_1d();
        }
    } else {
        b.roulette[i] = true;
        b.u_rr[i] = match drawn {
            Some(d) => d.roulette[i],
            None => sampler.get_1d(),
        };
    }
    true
}

/// The lane stage of a bounce on backend `I`: the Lambertian lanes' directions, then for
/// every shaded lane the throughput update and Russian roulette, as the path integrator's
/// loop does them. Leaves every shaded lane's direction and density in `b` and returns the
/// lanes whose paths go on (bit `i` for lane `i`). `I` is [`Avx2`] only in the v3 copy of
/// the render loop.
#[inline(always)]
fn advance<I: LaneIsa, S>(lanes: &mut PathLanes<S>, b: &mut BounceLanes) -> u8 {
    let diffuse = M32x8::<I>::from_bools(b.diffuse);
    let lambert = diffuse::sample::<I>(&b.lambert, &b.u_dir);
    let f = Vec3x8::select(diffuse, &lambert.f, &Vec3x8::load(&b.f));
    let wi = Vec3x8::select(diffuse, &lambert.wi, &Vec3x8::load(&b.wi));
    let pdf = diffuse.select(lambert.pdf, F32x8::load(&b.pdf));
    let sampled = M32x8::from_bools(b.shaded).and(diffuse.not().or(lambert.ok));

    let cos = wi.dot(&Vec3x8::load(&b.lambert.ns)).abs();
    let old_beta = Vec3x8::load(&lanes.beta);
    let beta = old_beta.mul(&f.scale(cos / pdf));
    let old_eta_scale = F32x8::load(&lanes.eta_scale);
    let eta_scale = old_eta_scale * F32x8::load(&b.eta_crossed_sq);
    // Survival in proportion to the throughput (see `path::li`).
    let one = F32x8::splat(1.0);
    let q = (one - beta.max_component() * eta_scale).max(F32x8::splat(0.0));
    let roulette = M32x8::from_bools(b.roulette);
    let killed = roulette.and(F32x8::load(&b.u_rr).lt(q));
    let beta = Vec3x8::select(roulette, &beta.scale(one / (one - q)), &beta);
    let alive = sampled
        .and(killed.not())
        .and(beta.is_zero().not())
        .and(beta.is_finite());
    lanes.beta = Vec3x8::select(sampled, &beta, &old_beta).store();
    lanes.eta_scale = sampled.select(eta_scale, old_eta_scale).store();
    b.wi = wi.store();
    b.pdf = pdf.store();
    alive.bits()
}
