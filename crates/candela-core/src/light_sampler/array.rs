//! The course notes' light array: M slots, each light holding a number of slots
//! proportional to its coarse contribution (power), so that a uniformly random slot gives
//! a light in O(1) with probability slots/M.

use crate::sampling::ONE_MINUS_EPSILON;

/// Slots per light on average, at least; more slots follow the powers more closely.
const SLOTS_PER_LIGHT: usize = 4;

/// A slot array over lights.
///
/// Size: M is the power of two at or above 4N. A slot is chosen from the 24 random bits of
/// one `f32` as ⌊u·M⌋, which hits every slot equally often only when M divides 2²⁴, so the
/// pick probabilities are exact for up to 2²² lights (beyond that, slots differ by one
/// part in 2²⁴/M).
///
/// Rounding: each light of power Φᵢ > 0 gets one slot, plus ⌊R·Φᵢ/ΣΦ⌋ of the R = M − n₊
/// remaining ones (n₊ the lights with power); the few slots this leaves over go one each
/// to the largest remainders. So no light that emits is left without a slot (a faint
/// light is over-sampled by at most one slot's worth), a light of zero power gets none,
/// Σ sᵢ = M, and the pick probability sᵢ/M is exact, not the rounded-away Φᵢ/ΣΦ.
#[derive(Clone, Debug)]
pub struct LightArray {
    slots: Vec<u32>,
    /// Slots held by each light.
    counts: Vec<u32>,
}

impl LightArray {
    /// An array over non-negative `powers`; `None` where none is positive or any is
    /// negative or not finite.
    pub fn new(powers: &[f32]) -> Option<LightArray> {
        if powers.iter().any(|p| !p.is_finite() || *p < 0.0) {
            return None;
        }
        let total: f64 = powers.iter().map(|&p| p as f64).sum();
        let emitting = powers.iter().filter(|&&p| p > 0.0).count();
        if total <= 0.0 || emitting == 0 {
            return None;
        }
        let m = (SLOTS_PER_LIGHT * powers.len()).next_power_of_two();
        let rest = (m - emitting) as f64;
        let mut counts = vec![0u32; powers.len()];
        let mut remainders = Vec::with_capacity(emitting);
        let mut used = 0usize;
        for (i, &p) in powers.iter().enumerate() {
            if p > 0.0 {
                let share = rest * p as f64 / total;
                counts[i] = 1 + share as u32;
                used += counts[i] as usize;
                remainders.push((share.fract(), i as u32));
            }
        }
        // Round-off in the shares can only leave slots over, never take too many.
        let left = m.saturating_sub(used).min(remainders.len());
        if left > 0 {
            remainders.select_nth_unstable_by(left - 1, |a, b| b.0.total_cmp(&a.0));
            for &(_, i) in &remainders[..left] {
                counts[i as usize] += 1;
            }
        }
        let mut slots = Vec::with_capacity(m);
        for (i, &c) in counts.iter().enumerate() {
            slots.extend(std::iter::repeat_n(i as u32, c as usize));
        }
        // Should round-off leave the sum off by a slot, M is what the slots say.
        Some(LightArray { slots, counts })
    }

    /// Number of slots M.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// A light and its probability, from one uniform number.
    pub fn sample(&self, u: f32) -> (u32, f32) {
        let m = self.slots.len();
        // Exact for u = j/2²⁴ when M is a power of two ≤ 2²⁴: slot j·M/2²⁴.
        let k = ((u.min(ONE_MINUS_EPSILON) as f64 * m as f64) as usize).min(m - 1);
        let i = self.slots[k];
        (i, self.pmf(i))
    }

    /// Probability of light `i`: its share of the slots.
    pub fn pmf(&self, i: u32) -> f32 {
        self.counts[i as usize] as f32 / self.slots.len() as f32
    }

    /// Bytes held, for the benchmark's memory note.
    pub fn memory_bytes(&self) -> usize {
        4 * (self.slots.len() + self.counts.len())
    }
}
