//! The volumetric path tracer, chosen for scenes with participating media or null
//! surfaces (pbrt-v4's `VolPathIntegrator`, over RGB): delta tracking of the camera path
//! against each medium's majorant, next event estimation from surfaces and from medium
//! collisions with transmittance through media and null boundaries, and MIS between light
//! sampling and BSDF/phase sampling as the scene's [`MisMode`] says.
//!
//! The path keeps three vectors, as pbrt-v4 does: `beta`, the throughput divided by the
//! hero channel's path density; `r_u`, each channel's density of the path so far relative
//! to the hero's (so dividing by its mean is the balance heuristic over channels); and
//! `r_l`, the same for a path whose last vertex came from light sampling. A homogeneous
//! medium's transmittance has a closed form, so shadow rays take it exactly; its light
//! strategy then samples no distance, and the camera path's `r_l` through it is divided by
//! the hero's pass-through probability instead of multiplied by the channel's.
//! Heterogeneous media are crossed by ratio tracking with Russian roulette.
//!
//! With a hero channel drawn uniformly, a strategy's density of a path is the mean over
//! the channels of its per-channel densities (the balance heuristic over channels, which
//! keeps every channel unbiased); `r_u` and `r_l`, relative to the density the path was
//! drawn with, give it as `mean(r)`. The two strategies are then combined by the
//! [`MisMode`]'s heuristic on those means, as the path tracer combines its two
//! (`weighted`): balance, power, light sampling only (`none`: emitters found by phase or
//! BSDF sampling count only after a delta bounce) or BSDF/phase sampling only (`bsdf`:
//! shadow rays only towards delta lights).

use glam::Vec3;

use super::sky;
use crate::bsdf::Bsdf;
use crate::desc::MisMode;
use crate::geometry::Ray;
use crate::light::{LightSample, ShadingCtx};
use crate::math::{max_component, offset_ray_origin};
use crate::medium::tracking::MajorantTracker;
use crate::medium::{transmittance, HenyeyGreenstein, MediumId, MediumInterface, SceneMedia};
use crate::sampler::{mix64, Pcg32, Sampler};
use crate::scene::{Scene, SurfaceInteraction};

/// Null surfaces a path may cross between two scattering events, or a shadow ray in all,
/// before it is given up (a guard against a ray caught between coincident boundaries).
const MAX_CROSSINGS: u32 = 256;

#[inline]
fn mean(v: Vec3) -> f32 {
    (v.x + v.y + v.z) * (1.0 / 3.0)
}

/// The factor that turns a sample of one strategy into its MIS-weighted contribution: its
/// weight against the other strategy over its own density, each density given by its
/// ratios to the sampled one (`own` and `other`, see the module's notes) through their
/// mean over the channels. Light-only and BSDF-only modes give the strategy in use its
/// whole weight (callers drop the other).
#[inline]
fn weighted(mode: MisMode, own: Vec3, other: Vec3) -> f32 {
    let (p, q) = (mean(own), mean(other));
    match mode {
        MisMode::Balance => 1.0 / (p + q),
        MisMode::Power => p / (p * p + q * q),
        MisMode::NeeOnly | MisMode::BsdfOnly => 1.0 / p,
    }
}

/// Whether a throughput or density ratio can still carry light.
#[inline]
fn live(v: Vec3) -> bool {
    v != Vec3::ZERO && v.is_finite()
}

/// The generator for the collisions of one tracked segment: seeded by the sampler's
/// number and the ray, so that a render stays reproducible.
fn tracking_rng(u: f32, ray: &Ray) -> Pcg32 {
    let key = |v: Vec3| {
        ((v.x.to_bits() as u64) << 32 | v.y.to_bits() as u64) ^ (v.z.to_bits() as u64) << 16
    };
    Pcg32::new(mix64(u.to_bits() as u64 ^ key(ray.o)), mix64(key(ray.d)))
}

/// The state of a camera path.
struct Path {
    beta: Vec3,
    r_u: Vec3,
    r_l: Vec3,
    hero: usize,
}

impl Path {
    /// Radiance `le` found along the path: in full after a delta bounce, else weighted
    /// by `mode` against light sampling, whose density of the found point is `p_light`.
    #[inline]
    fn emitted(
        &self,
        mode: MisMode,
        le: Vec3,
        specular: bool,
        p_light: impl FnOnce() -> f32,
    ) -> Vec3 {
        let w = match mode {
            _ if specular => 1.0 / mean(self.r_u),
            MisMode::NeeOnly => return Vec3::ZERO,
            MisMode::BsdfOnly => 1.0 / mean(self.r_u),
            _ => weighted(mode, self.r_u, self.r_l * p_light()),
        };
        self.beta * le * w
    }
}

/// Radiance arriving along `ray`, estimated by one path through `scene`'s media.
pub(crate) fn li<S: Sampler>(
    scene: &Scene,
    media: &SceneMedia,
    mut ray: Ray,
    sampler: &mut S,
    rays: &mut u64,
) -> Vec3 {
    let settings = &scene.settings;
    let mode = settings.mis;
    let hero = ((sampler.get_1d() * 3.0) as usize).min(2);
    let mut path = Path {
        beta: Vec3::ONE,
        r_u: Vec3::ONE,
        r_l: Vec3::ONE,
        hero,
    };
    let mut l = Vec3::ZERO;
    let mut medium = media.camera;
    let mut specular = true;
    let mut eta_scale = 1.0f32;
    let mut depth = 0u32;
    let mut crossings = 0u32;
    let mut prev_ctx = ShadingCtx {
        p: ray.o,
        n: Vec3::ZERO,
    };
    let hidden = |depth: u32| depth == 0 && settings.hide_emitters;
    loop {
        *rays += 1;
        let hit = scene.intersect(&ray, f32::INFINITY);
        if let Some(id) = medium {
            let m = media.medium(id);
            let t_max = hit.as_ref().map_or(f32::INFINITY, |h| h.t);
            let mut rng = tracking_rng(sampler.get_1d(), &ray);
            let mut tracker = MajorantTracker::new(m, &ray, t_max, hero);
            let mut scattered = false;
            while let Some(c) = tracker.next(rng.uniform_f32()) {
                let (sa, ss, sm) = (c.props.sigma_a, c.props.sigma_s, c.sigma_maj);
                let p_absorb = sa[hero] / sm[hero];
                let p_scatter = ss[hero] / sm[hero];
                let u = rng.uniform_f32();
                if u < p_absorb {
                    return l;
                }
                if u < p_absorb + p_scatter {
                    if depth >= settings.max_depth {
                        return l;
                    }
                    depth += 1;
                    let w = c.t_maj * ss / (c.t_maj[hero] * ss[hero]);
                    path.beta *= w;
                    path.r_u *= w;
                    if !(live(path.beta) && live(path.r_u)) {
                        return l;
                    }
                    let phase = m.phase();
                    let ctx = ShadingCtx {
                        p: c.p,
                        n: Vec3::ZERO,
                    };
                    let v = Vertex::Medium { phase, d: ray.d };
                    l += sample_ld(scene, media, &ctx, &v, medium, &path, sampler, rays);
                    // Exact sampling: the phase function's value over its density is 1.
                    let (wi, pdf) = phase.sample(ray.d, sampler.get_2d());
                    path.r_l = path.r_u / pdf;
                    crossings = 0;
                    prev_ctx = ctx;
                    specular = false;
                    ray = Ray::new(c.p, wi);
                    scattered = true;
                    break;
                }
                let sigma_n = (sm - sa - ss).max(Vec3::ZERO);
                let pdf = c.t_maj[hero] * sigma_n[hero];
                if pdf <= 0.0 {
                    return l;
                }
                path.beta *= c.t_maj * sigma_n / pdf;
                path.r_u *= c.t_maj * sigma_n / pdf;
                path.r_l *= c.t_maj * sm / pdf;
                if !(live(path.beta) && live(path.r_u)) {
                    return l;
                }
            }
            if scattered {
                if !roulette(settings, &mut path, eta_scale, depth, sampler) {
                    return l;
                }
                continue;
            }
            let t = tracker.t_maj_to_end();
            let th = t[hero];
            if th <= 0.0 {
                return l;
            }
            path.beta *= t / th;
            path.r_u *= t / th;
            // See the module's notes: shadow rays take a homogeneous medium's
            // transmittance exactly, so the light strategy has no distance density there.
            path.r_l *= if m.is_homogeneous() {
                Vec3::splat(1.0 / th)
            } else {
                t / th
            };
        }

        let Some(si) = hit else {
            if !hidden(depth) {
                for (id, le) in sky::escaped(scene, &ray, depth == 0) {
                    l += path.emitted(mode, le, specular, || {
                        let pdf = scene.light(id).pdf_li(&prev_ctx, ray.d);
                        scene.light_sampler.pmf(&prev_ctx, id) * pdf
                    });
                }
            }
            break;
        };
        let wo = -ray.d;
        if let Some(id) = si.light {
            let light = scene.light(id);
            let le = light.radiance(si.ng, si.uv, wo);
            if le != Vec3::ZERO && !hidden(depth) {
                l += path.emitted(mode, le, specular, || {
                    scene.light_sampler.pmf(&prev_ctx, id) * light.pdf_li(&prev_ctx, ray.d)
                });
            }
        }
        let surface = media.surface(si.material);
        if surface.null {
            if let Some(iface) = surface.interface {
                medium = iface.target(si.ng, ray.d);
            }
            crossings += 1;
            if crossings > MAX_CROSSINGS {
                break;
            }
            ray = si.spawn_ray(ray.d);
            continue;
        }
        if depth >= settings.max_depth {
            break;
        }
        depth += 1;
        crossings = 0;
        let bsdf = scene.materials[si.material.0 as usize].bsdf_at(&si);
        let ctx = ShadingCtx { p: si.p, n: si.ns };
        if !bsdf.is_delta() {
            let v = Vertex::Surface {
                si: &si,
                bsdf: &bsdf,
                wo,
                interface: surface.interface,
            };
            l += sample_ld(scene, media, &ctx, &v, medium, &path, sampler, rays);
        }
        let u_lobe = sampler.get_1d();
        let u_dir = sampler.get_2d();
        let Some(bs) = bsdf.sample(wo, u_lobe, u_dir) else {
            break;
        };
        path.beta *= bs.f * (bsdf.abs_cos(bs.wi) / bs.pdf);
        path.r_l = path.r_u / bs.pdf;
        specular = bs.flags.is_delta();
        prev_ctx = ctx;
        eta_scale *= bsdf.eta_crossed_sq(wo, &bs);
        if let Some(iface) = surface.interface {
            medium = iface.target(si.ng, bs.wi);
        }
        ray = si.spawn_ray(bs.wi);
        if !roulette(settings, &mut path, eta_scale, depth, sampler) {
            break;
        }
    }
    l
}

/// Russian roulette on the path's throughput (as the path tracer plays it, on the
/// throughput divided by the mean channel density); false where the path ends.
fn roulette<S: Sampler>(
    settings: &crate::options::RenderOptions,
    path: &mut Path,
    eta_scale: f32,
    depth: u32,
    sampler: &mut S,
) -> bool {
    if !(live(path.beta) && live(path.r_u)) {
        return false;
    }
    if depth < settings.rr_depth {
        return true;
    }
    let u = sampler.get_1d();
    let q = (1.0 - max_component(path.beta * eta_scale / mean(path.r_u))).max(0.0);
    if u < q {
        return false;
    }
    path.beta *= 1.0 / (1.0 - q);
    true
}

/// A vertex to estimate direct light at.
enum Vertex<'a> {
    Surface {
        si: &'a SurfaceInteraction,
        bsdf: &'a Bsdf,
        wo: Vec3,
        interface: Option<MediumInterface>,
    },
    /// A collision in a medium; `d` the direction the path arrived along.
    Medium { phase: HenyeyGreenstein, d: Vec3 },
}

/// Next event estimation at a vertex: one light picked by the light sampler, one point on
/// it, its transmittance through media and null surfaces, and the scene's MIS weight
/// against BSDF or phase sampling (see the module's notes).
#[allow(clippy::too_many_arguments)]
fn sample_ld<S: Sampler>(
    scene: &Scene,
    media: &SceneMedia,
    ctx: &ShadingCtx,
    v: &Vertex,
    medium: Option<MediumId>,
    path: &Path,
    sampler: &mut S,
    rays: &mut u64,
) -> Vec3 {
    let u_light = sampler.get_1d();
    let u_point = sampler.get_2d();
    let mode = scene.settings.mis;
    let Some(pick) = scene.light_sampler.sample(ctx, u_light, &scene.lights) else {
        return Vec3::ZERO;
    };
    let light = scene.light(pick.id);
    // BSDF-only estimation still needs NEE for delta lights, which no ray can hit.
    if mode == MisMode::BsdfOnly && !light.is_delta() {
        return Vec3::ZERO;
    }
    let Some(ls) = light.sample_li(ctx, u_point) else {
        return Vec3::ZERO;
    };
    let (f, scatter_pdf, origin, medium) = match *v {
        Vertex::Surface {
            si,
            bsdf,
            wo,
            interface,
        } => {
            let (f, pdf) = bsdf.f_cos_pdf(wo, ls.wi);
            let n = if ls.wi.dot(si.ng) >= 0.0 {
                si.ng
            } else {
                -si.ng
            };
            let medium = interface.map_or(medium, |i| i.target(si.ng, ls.wi));
            (f, pdf, offset_ray_origin(si.p, n), medium)
        }
        Vertex::Medium { phase, d } => {
            let p = phase.pdf(d, ls.wi);
            (Vec3::splat(p), p, ctx.p, medium)
        }
    };
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let Some(tr) = shadow_transmittance(scene, media, origin, &ls, medium, path.hero, rays) else {
        return Vec3::ZERO;
    };
    let (beta, r_p) = (path.beta, path.r_u);
    if ls.is_delta {
        let r_l = r_p * tr.r_l * (pick.pmf * ls.pdf);
        return beta * f * tr.t * ls.radiance / mean(r_l);
    }
    // For RIS `pick.pmf` is 1/W and `mis_pmf` the tractable pick density the emitter
    // weight also uses (see `integrator::light_contribution`).
    let r_l = r_p * tr.r_l * (pick.mis_pmf * ls.pdf);
    let r_u = r_p * tr.r_u * scatter_pdf;
    beta * f * tr.t * ls.radiance * (pick.mis_pmf / pick.pmf) * weighted(mode, r_l, r_u)
}

/// A shadow ray's transmittance estimate and the density ratios of its two strategies.
struct ShadowTransmittance {
    t: Vec3,
    r_l: Vec3,
    r_u: Vec3,
}

/// The transmittance from `origin` (in `medium`) to the light sample, through null
/// surfaces (which may change the medium) and media: closed form in homogeneous media,
/// ratio tracking in others. `None` where an opaque surface blocks the way or the
/// estimate is zero.
fn shadow_transmittance(
    scene: &Scene,
    media: &SceneMedia,
    origin: Vec3,
    ls: &LightSample,
    mut medium: Option<MediumId>,
    hero: usize,
    rays: &mut u64,
) -> Option<ShadowTransmittance> {
    let finite = ls.distance.is_finite();
    let target = if !finite || ls.n_light == Vec3::ZERO {
        ls.p_light
    } else {
        let n = if (origin - ls.p_light).dot(ls.n_light) >= 0.0 {
            ls.n_light
        } else {
            -ls.n_light
        };
        offset_ray_origin(ls.p_light, n)
    };
    let mut tr = ShadowTransmittance {
        t: Vec3::ONE,
        r_l: Vec3::ONE,
        r_u: Vec3::ONE,
    };
    let mut o = origin;
    let mut rng = tracking_rng(0.0, &Ray::new(origin, ls.wi));
    for _ in 0..MAX_CROSSINGS {
        let (d, t_max) = if finite {
            let d = target - o;
            let dist = d.length();
            if dist.is_nan() || dist <= 0.0 {
                return Some(tr);
            }
            // A relative margin keeps the far end from blocking itself.
            (d / dist, dist * (1.0 - 1e-4))
        } else {
            (ls.wi, f32::INFINITY)
        };
        let ray = Ray::new(o, d);
        *rays += 1;
        let hit = scene.intersect(&ray, t_max);
        if let Some(h) = &hit {
            if !media.surface(h.material).null {
                return None;
            }
        }
        if let Some(id) = medium {
            let m = media.medium(id);
            let t_end = hit.as_ref().map_or(t_max, |h| h.t);
            if m.is_homogeneous() {
                let p = m.properties(o);
                let t = transmittance(p.sigma_a + p.sigma_s, t_end);
                tr.t *= t;
                tr.r_u *= t;
            } else {
                ratio_track(m, &ray, t_end, hero, &mut rng, &mut tr)?;
            }
            if tr.t == Vec3::ZERO {
                return None;
            }
        }
        let Some(h) = hit else {
            return Some(tr);
        };
        if let Some(iface) = media.surface(h.material).interface {
            medium = iface.target(h.ng, d);
        }
        o = h.spawn_ray(d).o;
    }
    None
}

/// Ratio tracking through a heterogeneous medium (pbrt-v4's `TraceTransmittance`), with
/// Russian roulette once the estimate falls below 0.05; `None` where it reaches zero.
fn ratio_track(
    m: &crate::medium::Medium,
    ray: &Ray,
    t_end: f32,
    hero: usize,
    rng: &mut Pcg32,
    tr: &mut ShadowTransmittance,
) -> Option<()> {
    let mut tracker = MajorantTracker::new(m, ray, t_end, hero);
    while let Some(c) = tracker.next(rng.uniform_f32()) {
        let sm = c.sigma_maj;
        let sigma_n = (sm - c.props.sigma_a - c.props.sigma_s).max(Vec3::ZERO);
        let pdf = c.t_maj[hero] * sm[hero];
        tr.t *= c.t_maj * sigma_n / pdf;
        tr.r_l *= c.t_maj * sm / pdf;
        tr.r_u *= c.t_maj * sigma_n / pdf;
        if max_component(tr.t / mean(tr.r_l + tr.r_u)) < 0.05 {
            if rng.uniform_f32() < 0.75 {
                return None;
            }
            tr.t *= 4.0;
        }
        if !live(tr.t) {
            return None;
        }
    }
    let t = tracker.t_maj_to_end();
    let th = t[hero];
    if th <= 0.0 {
        return None;
    }
    tr.t *= t / th;
    tr.r_l *= t / th;
    tr.r_u *= t / th;
    Some(())
}
