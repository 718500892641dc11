//! The path loop for scenes without media: at each vertex the emission found, next event
//! estimation (see `direct`), a BSDF-sampled bounce and Russian roulette on the
//! throughput. Scenes with media go to `volpath` instead.

use glam::{Vec2, Vec3, Vec3A};

use super::copies::sample_direct_baseline;
#[cfg(target_arch = "x86_64")]
use super::copies::sample_direct_v3;
#[cfg(doc)]
use super::direct::ShadowedLight;
use super::direct::{mis_weight, sample_direct, LightTerm, NeeVertex};
use super::volpath;
use crate::accel::Hit;
use crate::bsdf::Bsdf;
use crate::geometry::Ray;
use crate::light::{LightId, ShadingCtx};
use crate::math::max_component;
use crate::options::MisMode;
use crate::sampler::Sampler;
use crate::scene::{Scene, SurfaceInteraction};

/// Radiance arriving along `ray`, estimated by one path; inlined into each copy of the
/// render loop (see `super::band::render_pixels`).
#[inline(always)]
pub fn li<S: Sampler>(scene: &Scene, ray: Ray, sampler: &mut S, rays: &mut u64) -> Vec3 {
    if let Some(media) = scene.media.as_deref() {
        return volpath::li(scene, media, ray, sampler, rays);
    }
    li_surfaces::<S, false>(scene, ray, None, sampler, rays)
}

/// [`li`] of a camera ray whose closest hit `first` is already known (traced with
/// others in a packet: [`Scene::intersect_coherent8`]), in a scene without media: the
/// same numbers drawn in the same order, the same radiance.
#[inline(always)]
pub(super) fn li_from_hit<S: Sampler>(
    scene: &Scene,
    ray: Ray,
    first: Option<Hit>,
    sampler: &mut S,
    rays: &mut u64,
) -> Vec3 {
    debug_assert!(scene.media.is_none());
    li_surfaces::<S, true>(scene, ray, first, sampler, rays)
}

/// The path loop; with `KNOWN`, the camera ray's closest hit is `first` instead of a
/// query.
#[inline(always)]
fn li_surfaces<S: Sampler, const KNOWN: bool>(
    scene: &Scene,
    mut ray: Ray,
    first: Option<Hit>,
    sampler: &mut S,
    rays: &mut u64,
) -> Vec3 {
    let mut l = Vec3::ZERO;
    let mut beta = Vec3::ONE;
    // The product of η′² over the refractions so far (see `Bsdf::eta_crossed_sq`).
    let mut eta_scale = 1.0f32;
    let mut depth = 0u32;
    // Whether the path's last bounce was a delta lobe (or the path just left the camera):
    // then no light sampling could have found what the ray hits, so it counts in full.
    let mut specular = true;
    let mut prev = PrevVertex {
        ctx: ShadingCtx {
            p: ray.o,
            n: Vec3::ZERO,
        },
        bsdf_pdf: 0.0,
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
        let hit = if KNOWN && depth == 0 {
            scene.interaction_of(&ray, first)
        } else {
            scene.intersect_for_shading(&ray, f32::INFINITY)
        };
        if hides_emitter(scene, depth, hit.as_ref()) {
            break;
        }
        let Some(si) = hit.as_ref() else {
            add_escaped(scene, &ray, depth, specular, &prev, beta, &mut l);
            break;
        };
        let wo = -ray.d;
        add_emitted(scene, si, &ray, specular, &prev, beta, &mut l);
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
            l += beta * direct::<S>(scene, si, &ctx, &bsdf, wo, &u, rays);
        }
        let Some(bs) = bs else {
            break;
        };
        beta *= bs.f * (bsdf.abs_cos(bs.wi) / bs.pdf);
        specular = bs.flags.is_delta();
        prev = PrevVertex {
            ctx,
            bsdf_pdf: bs.pdf,
        };
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
        if is_spent(beta) {
            break;
        }
    }
    l
}

/// Whether the throughput `beta` ends the path: every channel zero, or one not finite.
/// In SIMD lanes (|β| < ∞ is false for ∞ and NaN), where `is_finite` was integer tests on
/// each channel's bits: the same answer for a few instructions.
#[inline(always)]
fn is_spent(beta: Vec3) -> bool {
    let b = Vec3A::from(beta);
    b == Vec3A::ZERO || !b.abs().cmplt(Vec3A::INFINITY).all()
}

/// What emission found by BSDF sampling is weighed against: where the path left its last
/// scattering vertex, and the density of the BSDF sample that left it.
#[derive(Clone, Copy, Debug)]
pub(super) struct PrevVertex {
    pub ctx: ShadingCtx,
    pub bsdf_pdf: f32,
}

/// Whether a camera ray's hit (or miss, `None`) returns nothing because the scene hides
/// emitters seen directly.
#[inline(always)]
pub(super) fn hides_emitter(scene: &Scene, depth: u32, hit: Option<&SurfaceInteraction>) -> bool {
    depth == 0 && scene.settings.hide_emitters && hit.is_none_or(|si| si.light.is_some())
}

/// Weight of emission found by BSDF sampling, against NEE having found it.
#[inline(always)]
fn emitter_weight(scene: &Scene, specular: bool, prev: &PrevVertex, id: LightId, d: Vec3) -> f32 {
    let mode = scene.settings.mis;
    match mode {
        _ if specular => 1.0,
        MisMode::BsdfOnly => 1.0,
        MisMode::NeeOnly => 0.0,
        MisMode::Balance | MisMode::Power => {
            let light_pdf =
                scene.light_sampler.pmf(&prev.ctx, id) * scene.light(id).pdf_li(&prev.ctx, d);
            mis_weight(mode, prev.bsdf_pdf, light_pdf)
        }
    }
}

/// Adds to `l` the light of the infinite lights that `ray`, which escaped, sees, weighed
/// by the path throughput `beta` and by MIS against NEE at the previous vertex.
#[inline(always)]
pub(super) fn add_escaped(
    scene: &Scene,
    ray: &Ray,
    depth: u32,
    specular: bool,
    prev: &PrevVertex,
    beta: Vec3,
    l: &mut Vec3,
) {
    let mode = scene.settings.mis;
    for &id in &scene.infinite_lights {
        let light = scene.light(id);
        let (le, weight) = if depth == 0 {
            (light.le_camera(ray), 1.0)
        } else if !specular && matches!(mode, MisMode::Balance | MisMode::Power) {
            // The radiance and the density MIS weighs it by, from one lookup.
            let (le, pdf) = light.le_pdf(&prev.ctx, ray);
            let light_pdf = scene.light_sampler.pmf(&prev.ctx, id) * pdf;
            (le, mis_weight(mode, prev.bsdf_pdf, light_pdf))
        } else {
            let weight = emitter_weight(scene, specular, prev, id, ray.d);
            (light.le(ray), weight)
        };
        if le != Vec3::ZERO {
            *l += beta * le * weight;
        }
    }
}

/// Adds to `l` the emission of the surface `ray` hit at `si` (if it is a light), weighed
/// as in [`add_escaped`].
#[inline(always)]
pub(super) fn add_emitted(
    scene: &Scene,
    si: &SurfaceInteraction,
    ray: &Ray,
    specular: bool,
    prev: &PrevVertex,
    beta: Vec3,
    l: &mut Vec3,
) {
    if let Some(id) = si.light {
        let le = scene.light(id).radiance(si.ng, si.uv, -ray.d);
        if le != Vec3::ZERO {
            *l += beta * le * emitter_weight(scene, specular, prev, id, ray.d);
        }
    }
}

/// Next event estimation at the hit `si` (shading context `ctx`, BSDF `bsdf`, towards
/// `wo`) with the bounce's light numbers in `u`, inlined into the path loop. Out of line
/// (as it was, and still is for the lanes integrator: [`direct_out_of_line`]) the call
/// cost the loop about 50 instructions a bounce: the vertex record written to the stack,
/// the callee's saves and restores, and the loop's values spilled around the call.
#[inline(always)]
pub(super) fn direct<S: Sampler>(
    scene: &Scene,
    si: &SurfaceInteraction,
    ctx: &ShadingCtx,
    bsdf: &Bsdf,
    wo: Vec3,
    u: &BounceSamples<S>,
    rays: &mut u64,
) -> Vec3 {
    sample_direct(scene, &NeeVertex::new(si, ctx, bsdf, wo, u), rays)
}

/// [`direct`] out of line, in the copy of the render loop `V3` says: the lanes
/// integrator's, whose shading of one lane at a time keeps it there. `T`: the
/// contribution (`Vec3`), or with its shadow ray left to trace, where the lanes' shadow
/// rays are traced together ([`ShadowedLight`]).
#[inline(always)]
pub(super) fn direct_out_of_line<S: Sampler, const V3: bool, T: LightTerm>(
    scene: &Scene,
    si: &SurfaceInteraction,
    ctx: &ShadingCtx,
    bsdf: &Bsdf,
    wo: Vec3,
    u: &BounceSamples<S>,
    rays: &mut u64,
) -> T {
    let v = NeeVertex::new(si, ctx, bsdf, wo, u);
    match V3 {
        // SAFETY: only the v3 copy of the render loop has `V3`, and `render_with` asserted
        // that the CPU runs it.
        #[cfg(target_arch = "x86_64")]
        true => unsafe { sample_direct_v3(scene, &v, rays) },
        _ => sample_direct_baseline(scene, &v, rays),
    }
}

impl<'a> NeeVertex<'a> {
    /// The vertex of the hit `si` with the bounce's light numbers in `u`.
    #[inline(always)]
    fn new<S: Sampler>(
        si: &'a SurfaceInteraction,
        ctx: &'a ShadingCtx,
        bsdf: &'a Bsdf,
        wo: Vec3,
        u: &BounceSamples<S>,
    ) -> NeeVertex<'a> {
        NeeVertex {
            si,
            ctx,
            bsdf,
            wo,
            u_light: u.light,
            u_point: u.point,
        }
    }
}

/// The numbers one bounce takes, in the order of their dimensions.
pub(super) struct BounceSamples<S: Sampler> {
    /// The light pick (0.5, its dimension skipped, where there is one light).
    pub light: f32,
    /// The point on the light.
    pub point: Vec2,
    /// The BSDF's lobe choice, deferred: the hit is not known yet, and most BSDFs (one
    /// lobe) do not read it.
    pub lobe: S::Deferred1d,
    /// The BSDF direction.
    pub dir: Vec2,
}

impl<S: Sampler> BounceSamples<S> {
    #[inline(always)]
    pub(super) fn draw(scene: &Scene, sampler: &mut S) -> BounceSamples<S> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `is_spent` answers as `beta == Vec3::ZERO || !beta.is_finite()`, channel by channel:
    /// zeros of either sign, infinities and NaN in each position.
    #[test]
    fn a_path_is_spent_where_its_throughput_is_zero_or_not_finite() {
        let values = [
            0.0,
            -0.0,
            1e-38,
            0.5,
            -2.0,
            3e38,
            f32::INFINITY,
            -f32::INFINITY,
            f32::NAN,
        ];
        let mut spent = 0;
        for &x in &values {
            for &y in &values {
                for &z in &values {
                    let beta = Vec3::new(x, y, z);
                    let expected = beta == Vec3::ZERO || !beta.is_finite();
                    assert_eq!(is_spent(beta), expected, "{beta:?}");
                    spent += expected as u32;
                }
            }
        }
        // 8 all-zero triples, 9³ − 6³ with an infinity or NaN.
        assert_eq!(spent, 8 + 729 - 216);
    }
}
