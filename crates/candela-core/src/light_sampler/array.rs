//! The course notes' light array: M slots, each light holding a number of slots
//! proportional to its coarse contribution (power), so that a uniformly random slot gives
//! a light in O(1) with probability slots/M.

use crate::sampling::ONE_MINUS_EPSILON;

/// Slots per light on average; more slots follow the powers more closely.
const SLOTS_PER_LIGHT: f64 = 4.0;

/// A slot array over lights.
///
/// Rounding: a light of power Φᵢ > 0 gets sᵢ = max(1, round(4N · Φᵢ / ΣΦ)) slots, so no
/// light that emits is left without a slot (a faint light is over-sampled by at most one
/// slot's worth); a light of zero power gets none. M = Σ sᵢ, and the pick probability
/// sᵢ / M is exact, not the rounded-away Φᵢ / ΣΦ.
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
        if total <= 0.0 {
            return None;
        }
        let target = SLOTS_PER_LIGHT * powers.len() as f64;
        let counts: Vec<u32> = powers
            .iter()
            .map(|&p| {
                if p > 0.0 {
                    ((p as f64 / total * target).round() as u32).max(1)
                } else {
                    0
                }
            })
            .collect();
        let mut slots = Vec::with_capacity(counts.iter().map(|&c| c as usize).sum());
        for (i, &c) in counts.iter().enumerate() {
            slots.extend(std::iter::repeat_n(i as u32, c as usize));
        }
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
