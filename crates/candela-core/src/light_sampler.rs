//! Choosing the one light that next event estimation samples at a shading point.
//!
//! Any choice with non-zero probability for every light that can contribute is unbiased,
//! as long as the estimate is divided by the probability of the pick. MIS needs the same
//! probability for a light found by a BSDF-sampled ray, hence [`LightSampler::pmf`].

use crate::desc::LightSamplerKind;
use crate::light::{Light, LightId, ShadingCtx};
use crate::sampling::AliasTable;

#[derive(Clone, Debug)]
pub enum LightSampler {
    /// No lights to sample.
    Empty,
    /// Every light equally likely.
    Uniform { count: u32 },
    /// Proportional to each light's power Φ, in O(1) through an alias table.
    Power(AliasTable),
}

impl LightSampler {
    pub fn new(kind: LightSamplerKind, lights: &[Light]) -> LightSampler {
        if lights.is_empty() {
            return LightSampler::Empty;
        }
        let uniform = LightSampler::Uniform {
            count: lights.len() as u32,
        };
        match kind {
            LightSamplerKind::Uniform => uniform,
            LightSamplerKind::Power => {
                let powers: Vec<f32> = lights.iter().map(Light::power).collect();
                // Lights whose power cannot be estimated (zero everywhere) fall back to
                // uniform picks, so that nothing that might emit is ignored.
                AliasTable::new(&powers).map_or(uniform, LightSampler::Power)
            }
        }
    }

    /// Picks a light; returns it with the probability of the pick.
    pub fn sample(&self, _ctx: &ShadingCtx, u: f32) -> Option<(LightId, f32)> {
        match self {
            LightSampler::Empty => None,
            LightSampler::Uniform { count } => {
                let i = ((u * *count as f32) as u32).min(count - 1);
                Some((LightId(i), 1.0 / *count as f32))
            }
            LightSampler::Power(table) => {
                let (i, pmf) = table.sample(u);
                Some((LightId(i as u32), pmf))
            }
        }
    }

    /// Probability that [`Self::sample`] picks `light` at `ctx`.
    pub fn pmf(&self, _ctx: &ShadingCtx, light: LightId) -> f32 {
        match self {
            LightSampler::Empty => 0.0,
            LightSampler::Uniform { count } => 1.0 / *count as f32,
            LightSampler::Power(table) => table.pmf(light.0 as usize),
        }
    }
}
