//! Choosing the one light that next event estimation samples at a shading point.
//!
//! Any choice with non-zero probability for every light that can contribute is unbiased,
//! as long as the estimate is divided by the probability of the pick. MIS needs the same
//! probability for a light found by a BSDF-sampled ray, hence [`LightSampler::pmf`].
//!
//! The samplers, from cheapest to most adaptive:
//! - `Uniform`, `Power` (alias table over Φ) and [`LightArray`] (the course notes' slot
//!   array) ignore the shading point;
//! - [`LightBvh`] (Conty Estevez & Kulla 2018) adapts to the point in O(log N);
//! - [`Ris`] draws a few candidates from the array or the BVH and resamples one by a
//!   finer importance (Talbot et al. 2005). Its exact pick probability is intractable:
//!   [`LightPick::pmf`] then holds the reciprocal of the unbiased RIS weight, and
//!   [`LightPick::mis_pmf`] / [`LightSampler::pmf`] a tractable surrogate that MIS uses
//!   for both strategies (see [`ris`]).

mod array;
mod bvh;
mod descent;
mod flat;
pub mod ris;

pub use array::LightArray;
pub use bvh::{LightBvh, FLAT_MAX};
pub use ris::Ris;

use crate::light::{Light, LightId, ShadingCtx};
use crate::options::LightSamplerKind;
use crate::sampling::AliasTable;

/// A light chosen for next event estimation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPick {
    pub id: LightId,
    /// What the estimate divides by: the probability of the pick, or for RIS the
    /// reciprocal of its weight W, which makes E[f(id) / pmf] = Σ f over lights.
    pub pmf: f32,
    /// The selection probability MIS weights use; equals [`LightSampler::pmf`] for `id`.
    pub mis_pmf: f32,
}

#[derive(Clone, Debug)]
pub enum LightSampler {
    /// No lights to sample.
    Empty,
    /// The one light there is, picked with probability 1: what every sampler gives for
    /// one light (the BVH and RIS where it can contribute), without their arithmetic.
    Single,
    /// Every light equally likely.
    Uniform { count: u32 },
    /// Proportional to each light's power Φ, in O(1) through an alias table.
    Power(AliasTable),
    /// Proportional to power in whole slots of an array, in O(1).
    Array(LightArray),
    /// Stochastic descent of a light BVH by each node's importance at the point.
    Bvh(LightBvh),
    /// Resampled importance sampling over candidates from the array or the BVH.
    Ris(Ris),
}

impl LightSampler {
    /// A sampler of `kind` over `lights`; `ris_candidates` is the number of candidates
    /// the RIS variants draw (at least 1).
    pub fn new(kind: LightSamplerKind, ris_candidates: u32, lights: &[Light]) -> LightSampler {
        if lights.is_empty() {
            return LightSampler::Empty;
        }
        let uniform = LightSampler::Uniform {
            count: lights.len() as u32,
        };
        let powers = || -> Vec<f32> { lights.iter().map(Light::power).collect() };
        // One light: every sampler picks it with probability 1 (the uniform sampler, the
        // alias table and the array exactly; the BVH and RIS wherever it can contribute),
        // which needs no arithmetic. The uniform pick's saturating float-to-integer
        // conversion and division were 23 of the Cornell box's ~320 instructions a light
        // sample; the BVH's importance at its one leaf, computed for the pick and again for
        // MIS, cost more (bench/RESULTS.md, light_sampler). Where the BVH would have refused
        // the light (its bounds say it cannot reach the point), the light's own sample or
        // the BSDF gives zero before any shadow ray, so the estimate is the same.
        if lights.len() == 1 {
            return LightSampler::Single;
        }
        // Where no power can be estimated (zero everywhere), every sampler falls back to
        // uniform picks so that nothing that might emit is ignored.
        match kind {
            LightSamplerKind::Uniform => uniform,
            LightSamplerKind::Power => {
                AliasTable::new(&powers()).map_or(uniform, LightSampler::Power)
            }
            LightSamplerKind::Array => LightArray::new(&powers()).map_or(uniform, Self::Array),
            LightSamplerKind::Bvh => LightBvh::new(lights).map_or(uniform, Self::Bvh),
            LightSamplerKind::Ris => match LightArray::new(&powers()) {
                Some(a) => Self::Ris(Ris::new(LightSampler::Array(a), ris_candidates)),
                None => uniform,
            },
            LightSamplerKind::RisBvh => match LightBvh::new(lights) {
                Some(b) => Self::Ris(Ris::new(LightSampler::Bvh(b), ris_candidates)),
                None => uniform,
            },
        }
    }

    /// Picks a light at `ctx` from one uniform number `u`; `None` where no light can
    /// contribute. `lights` must be the slice the sampler was built from. Always inlined
    /// (the samplers' own searches stay out of line): in next event estimation's v3 copy
    /// LLVM had left it a call.
    #[inline(always)]
    pub fn sample(&self, ctx: &ShadingCtx, u: f32, lights: &[Light]) -> Option<LightPick> {
        let pick = |id: u32, pmf: f32| LightPick {
            id: LightId(id),
            pmf,
            mis_pmf: pmf,
        };
        match self {
            LightSampler::Empty => None,
            LightSampler::Single => Some(pick(0, 1.0)),
            LightSampler::Uniform { count } => {
                let i = ((u * *count as f32) as u32).min(count - 1);
                Some(pick(i, 1.0 / *count as f32))
            }
            LightSampler::Power(table) => {
                let (i, pmf) = table.sample(u);
                Some(pick(i as u32, pmf))
            }
            LightSampler::Array(a) => {
                let (i, pmf) = a.sample(u);
                Some(pick(i, pmf))
            }
            LightSampler::Bvh(b) => b.sample(ctx, u).map(|(i, pmf)| pick(i, pmf)),
            LightSampler::Ris(r) => r.sample(ctx, u, lights),
        }
    }

    /// Probability that [`Self::sample`] picks `light` at `ctx`, as MIS uses it: exact
    /// for every sampler but RIS, whose surrogate is explained in [`ris`].
    #[inline]
    pub fn pmf(&self, ctx: &ShadingCtx, light: LightId) -> f32 {
        match self {
            LightSampler::Empty => 0.0,
            LightSampler::Single => 1.0,
            LightSampler::Uniform { count } => 1.0 / *count as f32,
            LightSampler::Power(table) => table.pmf(light.0 as usize),
            LightSampler::Array(a) => a.pmf(light.0),
            LightSampler::Bvh(b) => b.pmf(ctx, light.0),
            LightSampler::Ris(r) => r.mis_pmf(ctx, light),
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::light::ParallelogramLight;

    #[test]
    fn one_light_is_picked_with_probability_one_by_every_sampler() {
        let lamp = ParallelogramLight::new(Vec3::ZERO, Vec3::X, Vec3::Z, -Vec3::Y, Vec3::ONE)
            .map(Light::Parallelogram)
            .unwrap();
        let lights = [lamp];
        let ctx = ShadingCtx {
            p: Vec3::new(0.5, -1.0, 0.5),
            n: Vec3::Y,
        };
        // What the alias table and the array would give: the whole probability.
        let table = AliasTable::new(&[lights[0].power()]).unwrap();
        let array = LightArray::new(&[lights[0].power()]).unwrap();
        let uniform = LightSampler::Uniform { count: 1 };
        for kind in [
            LightSamplerKind::Uniform,
            LightSamplerKind::Power,
            LightSamplerKind::Array,
            LightSamplerKind::Bvh,
            LightSamplerKind::Ris,
            LightSamplerKind::RisBvh,
        ] {
            let s = LightSampler::new(kind, 4, &lights);
            assert!(matches!(s, LightSampler::Single), "{kind:?}");
            for u in [0.0, 0.3, 0.999_999] {
                let pick = s.sample(&ctx, u, &lights).unwrap();
                assert_eq!(pick.id, LightId(0));
                assert_eq!(Some(pick), uniform.sample(&ctx, u, &lights));
                assert_eq!(pick.pmf, table.sample(u).1);
                assert_eq!(pick.pmf, array.sample(u).1);
                assert_eq!(pick.mis_pmf, 1.0);
            }
            assert_eq!(s.pmf(&ctx, LightId(0)), 1.0);
        }
    }
}
