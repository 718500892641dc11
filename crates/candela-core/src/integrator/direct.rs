//! Direct light at a path vertex: next event estimation towards one light picked by the
//! scene's light sampler, a shadow ray, and the multiple importance sampling weight
//! against BSDF sampling of the same direction (Veach 1997, ch. 9).

use glam::{Vec2, Vec3};

use crate::bsdf::Bsdf;
use crate::light::{Light, LightSample, LightSource, ShadingCtx};
use crate::light_sampler::LightPick;
use crate::options::MisMode;
use crate::sampling::{balance_heuristic, power_heuristic};
use crate::scene::{Scene, ShadowRay, SurfaceInteraction};

/// MIS weight of a strategy with density `pdf_f` against one with density `pdf_g`.
pub(super) fn mis_weight(mode: MisMode, pdf_f: f32, pdf_g: f32) -> f32 {
    match mode {
        MisMode::Power => power_heuristic(pdf_f, pdf_g),
        _ => balance_heuristic(pdf_f, pdf_g),
    }
}

/// What next event estimation at a path vertex takes.
#[derive(Clone, Copy)]
pub(super) struct NeeVertex<'a> {
    pub(super) si: &'a SurfaceInteraction,
    pub(super) ctx: &'a ShadingCtx,
    pub(super) bsdf: &'a Bsdf,
    pub(super) wo: Vec3,
    /// The light pick's number (see `BounceSamples::light` in `path`).
    pub(super) u_light: f32,
    /// The point on the light.
    pub(super) u_point: Vec2,
}

/// What next event estimation makes of a light sample: the path integrator's
/// contribution, its shadow ray traced at once (`Vec3`), or the lanes integrator's, its
/// shadow ray left to trace with other paths' ([`ShadowedLight`]).
pub(super) trait LightTerm {
    /// Nothing to add.
    const NONE: Self;
    /// The term of a light sample whose shadow ray is `shadow` and which adds `value()`
    /// where the shadow ray is unblocked.
    fn shadowed(scene: &Scene, shadow: ShadowRay, value: impl FnOnce() -> Vec3) -> Self;
}

impl LightTerm for Vec3 {
    const NONE: Vec3 = Vec3::ZERO;
    #[inline(always)]
    fn shadowed(scene: &Scene, shadow: ShadowRay, value: impl FnOnce() -> Vec3) -> Vec3 {
        if !scene.visible(&shadow) {
            return Vec3::ZERO;
        }
        value()
    }
}

/// A light sample's contribution before its shadow ray is traced: what it adds where
/// the shadow ray is unblocked.
#[derive(Clone, Copy, Debug)]
pub(super) struct ShadowedLight {
    pub(super) value: Vec3,
    pub(super) shadow: ShadowRay,
}

impl LightTerm for Option<ShadowedLight> {
    const NONE: Option<ShadowedLight> = None;
    #[inline(always)]
    fn shadowed(_: &Scene, shadow: ShadowRay, value: impl FnOnce() -> Vec3) -> Self {
        Some(ShadowedLight {
            value: value(),
            shadow,
        })
    }
}

/// Next event estimation: one light picked by the light sampler, one point on it, a
/// shadow ray, and the MIS weight against BSDF sampling of the same direction; the
/// contribution, or with the shadow ray not traced yet, as `T` says.
#[inline(always)]
pub(super) fn sample_direct<T: LightTerm>(scene: &Scene, v: &NeeVertex, rays: &mut u64) -> T {
    // The vertex's fields are read where they are used, from `v`, not copied out first:
    // copied, they lived in registers across the light sampler's call, so each was
    // stored to the stack before it and loaded back after it.
    let mode = scene.settings.mis;
    let ctx = v.ctx;
    let Some(pick) = scene.light_sampler.sample(ctx, v.u_light, &scene.lights) else {
        return T::NONE;
    };
    let NeeVertex {
        si,
        bsdf,
        wo,
        u_point,
        ..
    } = *v;
    let id = pick.id;
    let light = scene.light(id);
    // BSDF-only estimation still needs NEE for delta lights, which no ray can hit.
    if mode == MisMode::BsdfOnly && !light.is_delta() {
        return T::NONE;
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
fn light_contribution<T: LightTerm>(
    scene: &Scene,
    si: &SurfaceInteraction,
    bsdf: &Bsdf,
    wo: Vec3,
    pick: &LightPick,
    ls: Option<LightSample>,
    rays: &mut u64,
) -> T {
    let mode = scene.settings.mis;
    let Some(ls) = ls else {
        return T::NONE;
    };
    let (f, bsdf_pdf) = bsdf.f_cos_pdf(wo, ls.wi);
    if f == Vec3::ZERO {
        return T::NONE;
    }
    *rays += 1;
    let shadow = if ls.distance.is_finite() {
        ShadowRay::between(si.p, si.ng, ls.p_light, ls.n_light)
    } else {
        ShadowRay::leaving(si.p, si.ng, ls.wi)
    };
    T::shadowed(scene, shadow, || weighted(mode, pick, &ls, f, bsdf_pdf))
}

/// The contribution of light sample `ls` (of the light `pick` chose) whose BSDF value is
/// `f` and density `bsdf_pdf`, where its shadow ray is unblocked: with its MIS weight.
#[inline(always)]
fn weighted(mode: MisMode, pick: &LightPick, ls: &LightSample, f: Vec3, bsdf_pdf: f32) -> Vec3 {
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
