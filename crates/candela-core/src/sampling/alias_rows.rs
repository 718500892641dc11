//! Many equal-length discrete distributions in one flat alias table, each sampled in O(1)
//! with what is left of its uniform number handed back for further use.
//!
//! For a choice followed by a continuous warp (an environment map's cell, then the point
//! within it): the cell comes from the integer part of `u·n` and the alias test, and the
//! fraction that the test did not use is rescaled to [0, 1) for the warp. Not monotone in
//! `u` (the alias method never is), so stratified numbers do not stay stratified across
//! cells; within a cell they do.

/// One bin of Walker's alias method: keep the bin's own index with probability `q`, take
/// `alias` otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AliasBin {
    pub q: f32,
    pub alias: u32,
}

/// Vose's stable construction of the alias bins for probabilities scaled by their count,
/// `scaled[i] = p_i · n` (consumed). Bins below 1 take an alias from a bin above 1; what
/// remains at the end is full up to round-off.
pub(crate) fn vose_bins(scaled: &mut [f64]) -> Vec<AliasBin> {
    let n = scaled.len();
    let mut bins = vec![AliasBin { q: 0.0, alias: 0 }; n];
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    // Peek at both lists before taking from either: popping `small` first would lose its
    // last entry (with q = 0) whenever round-off empties `large` first.
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        bins[s] = AliasBin {
            q: scaled[s] as f32,
            alias: l as u32,
        };
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    for i in small.into_iter().chain(large) {
        bins[i] = AliasBin {
            q: 1.0,
            alias: i as u32,
        };
    }
    bins
}

/// Rows of `n` weights each, every row an alias table of its own (a row of zeros picks
/// uniformly; its caller gives it no mass).
#[derive(Clone, Debug)]
pub struct AliasRows {
    n: usize,
    bins: Vec<AliasBin>,
}

impl AliasRows {
    /// Alias tables over each `n`-long row of `weights` (non-negative, finite).
    pub fn new(weights: &[f64], n: usize) -> AliasRows {
        assert!(
            n > 0 && weights.len().is_multiple_of(n),
            "whole rows of {n}"
        );
        assert!(u32::try_from(n).is_ok(), "row of {n} bins");
        let bins = weights
            .chunks_exact(n)
            .flat_map(|row| {
                let total: f64 = row.iter().sum();
                let mut scaled: Vec<f64> = if total > 0.0 {
                    row.iter().map(|&w| w / total * n as f64).collect()
                } else {
                    vec![1.0; n]
                };
                vose_bins(&mut scaled)
            })
            .collect();
        AliasRows { n, bins }
    }

    /// Bins per row.
    pub fn row_len(&self) -> usize {
        self.n
    }

    /// An index of row `row` with probability ∝ its weight, and the part of `u` that the
    /// choice left, rescaled to [0, 1): uniform and independent of the index (to the
    /// resolution of `u·n`'s fraction).
    #[inline]
    pub fn sample(&self, row: usize, u: f32) -> (usize, f32) {
        let n = self.n;
        let scaled = u * n as u32 as f32;
        let i = (scaled as u32 as usize).min(n - 1);
        let up = (scaled - i as u32 as f32).min(super::ONE_MINUS_EPSILON);
        let bin = self.bins[row * n + i];
        let (index, rest) = if up < bin.q {
            (i, up / bin.q)
        } else {
            (bin.alias as usize, (up - bin.q) / (1.0 - bin.q))
        };
        (index, rest.min(super::ONE_MINUS_EPSILON))
    }

    /// Probability of `index` in row `row`, as the table holds it: its own bin's `q` and
    /// the shares of the bins that alias to it, over `n`. For tests.
    pub fn pmf(&self, row: usize, index: usize) -> f64 {
        let bins = &self.bins[row * self.n..(row + 1) * self.n];
        let own = bins[index].q as f64;
        let borrowed: f64 = bins
            .iter()
            .enumerate()
            .filter(|&(i, b)| i != index && b.alias as usize == index)
            .map(|(_, b)| 1.0 - b.q as f64)
            .sum();
        (own + borrowed) / self.n as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_reproduce_their_weights() {
        // Three rows: uneven with zeros, one heavy bin, all zero (uniform).
        let w = [
            1.0, 0.0, 3.0, 0.5, 10.0, //
            0.0, 0.0, 1e6, 0.0, 1e-3, //
            0.0, 0.0, 0.0, 0.0, 0.0,
        ];
        let t = AliasRows::new(&w, 5);
        for (r, row) in w.chunks_exact(5).enumerate() {
            let total: f64 = row.iter().sum();
            for (i, &wi) in row.iter().enumerate() {
                let expect = if total > 0.0 { wi / total } else { 0.2 };
                assert!((t.pmf(r, i) - expect).abs() < 1e-6, "row {r} bin {i}");
            }
        }
    }

    #[test]
    fn samples_follow_the_weights_and_leave_a_uniform_rest() {
        // A sweep of u over 5·10⁵ even steps: each index's share is its weight (to the
        // sweep's resolution), zero weights are never picked, and the rest numbers of each
        // index are spread evenly over [0, 1) (mean ½, within the sweep's resolution).
        let w = [2.0, 0.0, 1.0, 5.0, 0.25, 0.75];
        let t = AliasRows::new(&w, w.len());
        let steps = 500_000;
        let mut count = [0usize; 6];
        let mut rest_sum = [0.0f64; 6];
        for k in 0..steps {
            let (i, rest) = t.sample(0, (k as f32 + 0.5) / steps as f32);
            assert!((0.0..1.0).contains(&rest));
            count[i] += 1;
            rest_sum[i] += rest as f64;
        }
        let total: f64 = w.iter().sum();
        for i in 0..w.len() {
            let share = count[i] as f64 / steps as f64;
            assert!((share - w[i] / total).abs() < 1e-4, "{i}: {share}");
            if count[i] > 0 {
                let mean = rest_sum[i] / count[i] as f64;
                assert!((mean - 0.5).abs() < 1e-3, "{i}: mean rest {mean}");
            }
        }
        assert_eq!(count[1], 0);
    }
}
