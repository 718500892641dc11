//! What every light at a single point shares (spot, goniometric, projector): the delta
//! sample towards the point and the exact potential contribution. Each light supplies
//! only its intensity I(ω) in W/sr per channel.

use glam::Vec3;

use super::{receiver_cos, LightSample, ShadingCtx};
use crate::math::luminance;

/// The delta sample of a light at `position` whose intensity towards `w` (pointing away
/// from the light) is `intensity(w)`: radiance I(−ωᵢ)/d², pdf 1.
pub(super) fn sample_li(
    position: Vec3,
    ctx: &ShadingCtx,
    intensity: impl Fn(Vec3) -> Vec3,
) -> Option<LightSample> {
    let to = position - ctx.p;
    let d2 = to.length_squared();
    if d2 == 0.0 {
        return None;
    }
    let distance = d2.sqrt();
    let wi = to / distance;
    Some(LightSample {
        radiance: intensity(-wi) / d2,
        wi,
        distance,
        pdf: 1.0,
        is_delta: true,
        p_light: position,
        n_light: Vec3::ZERO,
    })
}

/// The exact potential contribution: luminance of I(ω)/d² towards `ctx` times the
/// receiver cosine; exactly 0 where the light is dark towards the point.
pub(super) fn importance(
    position: Vec3,
    ctx: &ShadingCtx,
    intensity: impl Fn(Vec3) -> Vec3,
) -> f32 {
    let to = ctx.p - position;
    let d2 = to.length_squared();
    if d2 == 0.0 {
        return 0.0;
    }
    let w = to / d2.sqrt();
    luminance(intensity(w)) / d2 * receiver_cos(ctx, -w)
}
