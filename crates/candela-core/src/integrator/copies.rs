//! The compiled copies of the render loop: one for the build's target (baseline) and,
//! on x86-64, one for x86-64-v3 (AVX2, FMA, BMI1/2), chosen per render by
//! [`crate::options::Isa`] (see [`crate::isa`]). A copy is the band loop and everything it
//! inlines. The lanes integrator keeps next event estimation out of line, with a copy of
//! its own for each; the path loop inlines it.

use super::band::{render_pixels, Band, SampleSink};
use super::direct::{sample_direct, LightTerm, NeeVertex};
use super::lanes::render_lanes;
use super::RenderStats;
use crate::options::{IntegratorKind, Isa};
use crate::sampler::Sampler;
use crate::scene::Scene;

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

v3_fn! {
    /// [`render_lanes`] compiled for x86-64-v3.
    fn render_lanes_v3<S: Sampler, K: SampleSink>(
        scene: &Scene,
        sampler: &mut S,
        band: Band,
        sink: &mut K,
    ) -> RenderStats {
        render_lanes::<S, K, true>(scene, sampler, band, sink)
    }
}

/// Takes a work item's samples with the render loop's copy `isa`, which the CPU must run,
/// and the integrator the scene asks for (the path integrator where the lanes integrator
/// does not cover the scene: see [`super::lanes_fallback`]).
pub(crate) fn render_band<S: Sampler, K: SampleSink>(
    scene: &Scene,
    isa: crate::options::Isa,
    sampler: &mut S,
    band: Band,
    sink: &mut K,
) -> RenderStats {
    debug_assert!(isa.is_supported());
    let lanes = scene.settings.integrator == IntegratorKind::Lanes && scene.media.is_none();
    match (isa, lanes) {
        // SAFETY (both v3 arms): `render_with` asserted that the CPU has the resolved ISA.
        #[cfg(target_arch = "x86_64")]
        (Isa::V3, false) => unsafe { render_pixels_v3(scene, sampler, band, sink) },
        #[cfg(target_arch = "x86_64")]
        (Isa::V3, true) => unsafe { render_lanes_v3(scene, sampler, band, sink) },
        (_, false) => render_pixels::<S, K, false>(scene, sampler, band, sink),
        (_, true) => render_lanes::<S, K, false>(scene, sampler, band, sink),
    }
}

/// [`sample_direct`] for the baseline target, out of line: the lanes integrator's (see
/// `path::direct_out_of_line`).
#[inline(never)]
pub(super) fn sample_direct_baseline<T: LightTerm>(
    scene: &Scene,
    v: &NeeVertex,
    rays: &mut u64,
) -> T {
    sample_direct(scene, v, rays)
}

v3_fn! {
    /// [`sample_direct`] compiled for x86-64-v3, out of line, called by the v3 copy of the
    /// lanes loop.
    #[inline(never)]
    pub(super) fn sample_direct_v3<T: LightTerm>(
        scene: &Scene,
        v: &NeeVertex,
        rays: &mut u64,
    ) -> T {
        sample_direct(scene, v, rays)
    }
}
