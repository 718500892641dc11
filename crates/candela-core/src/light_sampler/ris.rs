//! Resampled importance sampling over lights (Talbot, Cline & Egbert 2005, "Importance
//! Resampling for Global Illumination").
//!
//! M candidates x₁…x_M are drawn independently from a source sampler with pmf p (the
//! light array or the light BVH); each gets the weight wᵢ = p̂(xᵢ)/p(xᵢ), where the target
//! p̂ is [`Light::importance`] at the shading point (solid angle × brightness × receiver
//! cosine: the BSDF is not known to the sampler, and for the diffuse BSDF the target is
//! then proportional to the unshadowed contribution). One candidate y is kept with
//! probability w_y / Σwᵢ (weighted reservoir sampling, one pass), and the estimate is
//! f(y) · W with
//!
//! W = (1 / p̂(y)) · (1/M) Σᵢ wᵢ.
//!
//! **Why this is unbiased.** With j the kept index,
//! E[f(y)W] = E[Σⱼ (wⱼ/Σw) f(xⱼ) (1/p̂(xⱼ)) (1/M) Σw] = (1/M) Σⱼ E[f(xⱼ)/p(xⱼ)] = Σ_y f(y)
//! over every light with p(y) > 0 and p̂(y) > 0 — and p̂ is zero only where the light
//! provably contributes nothing, so the sum covers every light that matters. Candidates
//! may repeat and the sum over them is still right. The notes' summary "probability =
//! I_coarse · I_resampled", i.e. dividing by p(y) · p̂(y)/Σp̂(xᵢ), is *not* this weight:
//! it is biased when candidates repeat (see the test `naive_weight_is_biased`).
//!
//! **MIS.** The exact probability that RIS picks a light is a sum over all candidate
//! tuples: intractable. MIS only needs weights w_nee(y, ω) + w_bsdf(y, ω) = 1 for every
//! light y and direction ω where the integrand is non-zero; they need not use the true
//! densities. Both strategies therefore use the same surrogate q(y) = p(y), the source's
//! tractable pmf: NEE weighs with h(q(y)·p_li(ω), p_bsdf(ω)) and a BSDF-sampled ray that
//! hits y with h(p_bsdf(ω), q(y)·p_li(ω)), h the balance or power heuristic, so the two
//! weights sum to one for every (y, ω). NEE then estimates ∫ w_nee f and BSDF sampling
//! ∫ w_bsdf f exactly (the RIS estimate is unbiased for any weight that is a function of
//! (y, ω)), and the sum is ∫ f.

use crate::light::{Light, LightId, ShadingCtx};
use crate::sampler::{mix64, Pcg32};

use super::{LightPick, LightSampler};

/// RIS over candidates from a source sampler.
#[derive(Clone, Debug)]
pub struct Ris {
    source: Box<LightSampler>,
    candidates: u32,
}

/// 1 / W for the kept candidate: the number the estimate divides by.
/// `target` is p̂(y), `sum_w` is Σᵢ p̂(xᵢ)/p(xᵢ), `m` the number of candidates.
pub fn ris_pick_pmf(target: f32, sum_w: f64, m: u32) -> f32 {
    (target as f64 * m as f64 / sum_w) as f32
}

impl Ris {
    pub fn new(source: LightSampler, candidates: u32) -> Ris {
        Ris {
            source: Box::new(source),
            candidates: candidates.max(1),
        }
    }

    pub fn candidates(&self) -> u32 {
        self.candidates
    }

    pub fn source(&self) -> &LightSampler {
        &self.source
    }

    /// The random numbers for the candidates and the reservoir come from a generator
    /// seeded by `u` and the shading point, so the sampler keeps the one-number interface
    /// (and the fixed order of sample dimensions) of the other samplers.
    pub fn sample(&self, ctx: &ShadingCtx, u: f32, lights: &[Light]) -> Option<LightPick> {
        let p = ctx.p.to_array().map(f32::to_bits);
        let key = mix64(((p[0] as u64) << 32) | p[1] as u64) ^ ((p[2] as u64) << 32);
        let mut rng = Pcg32::new(mix64(key ^ u.to_bits() as u64), 0x5249_5321);
        let mut sum_w = 0.0f64;
        let mut kept: Option<(LightPick, f32)> = None;
        for _ in 0..self.candidates {
            let u_cand = rng.uniform_f32();
            let u_keep = rng.uniform_f32();
            let Some(c) = self.source.sample(ctx, u_cand, lights) else {
                continue;
            };
            let target = lights[c.id.0 as usize].importance(ctx);
            if !(target > 0.0 && target.is_finite()) {
                continue;
            }
            let w = target as f64 / c.pmf as f64;
            sum_w += w;
            if (u_keep as f64) * sum_w < w {
                kept = Some((c, target));
            }
        }
        let (c, target) = kept?;
        Some(LightPick {
            id: c.id,
            pmf: ris_pick_pmf(target, sum_w, self.candidates),
            mis_pmf: c.mis_pmf,
        })
    }

    /// The MIS surrogate q(y): the source's pmf (see the module docs).
    pub fn mis_pmf(&self, ctx: &ShadingCtx, light: LightId) -> f32 {
        self.source.pmf(ctx, light)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// E[f(y) / pmf] over all candidate tuples of a small case, computed exactly, for
    /// the Talbot weight (`ris_pick_pmf`), for the notes' literal "I_coarse · I_resampled"
    /// = p(y) · p̂(y) / Σ p̂(xᵢ), and for the same with I_coarse = M·p(y) (the chance of
    /// being among the candidates, exact only without repeats).
    fn exact_expectations(p: &[f64], target: &[f64], f: &[f64], m: u32) -> [f64; 3] {
        let n = p.len();
        let (mut talbot, mut naive, mut naive_m) = (0.0, 0.0, 0.0);
        for tuple in 0..n.pow(m) {
            let xs: Vec<usize> = (0..m).map(|k| tuple / n.pow(k) % n).collect();
            let prob: f64 = xs.iter().map(|&x| p[x]).product();
            let ws: Vec<f64> = xs.iter().map(|&x| target[x] / p[x]).collect();
            let sum_w: f64 = ws.iter().sum();
            let sum_target: f64 = xs.iter().map(|&x| target[x]).sum();
            for (j, &y) in xs.iter().enumerate() {
                let keep = prob * ws[j] / sum_w;
                talbot += keep * f[y] / ris_pick_pmf(target[y] as f32, sum_w, m) as f64;
                naive += keep * f[y] / (p[y] * target[y] / sum_target);
                naive_m += keep * f[y] / (m as f64 * p[y] * target[y] / sum_target);
            }
        }
        [talbot, naive, naive_m]
    }

    #[test]
    fn talbot_weight_is_unbiased_and_naive_weight_is_biased() {
        // Three lights, a coarse pmf that disagrees with the target, an integrand that
        // differs from the target; two candidates, so repeats happen with probability
        // Σp² = 0.54.
        let p = [0.7, 0.2, 0.1];
        let target = [1.0, 6.0, 30.0];
        let f = [2.0, 3.0, 5.0];
        let truth: f64 = f.iter().sum();
        for m in [1, 2, 3, 4] {
            let [talbot, naive, naive_m] = exact_expectations(&p, &target, &f, m);
            eprintln!("M={m}: truth {truth}, Talbot {talbot:.6}, naive {naive:.6}, M-scaled naive {naive_m:.6}");
            // Exact enumeration: only f32 rounding of the weight separates it from truth.
            assert!(
                (talbot / truth - 1.0).abs() < 1e-5,
                "M={m}: {talbot} vs {truth}"
            );
            if m >= 2 {
                // The naive weights miss by over 1% here (by 0 only at M = 1,
                // where it coincides with the correct one).
                assert!((naive / truth - 1.0).abs() > 0.02, "M={m}: naive {naive}");
                assert!(
                    (naive_m / truth - 1.0).abs() > 0.01,
                    "M={m}: naive {naive_m}"
                );
            }
        }
    }
}
