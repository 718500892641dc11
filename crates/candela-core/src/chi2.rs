//! Chi-square goodness-of-fit tests for sampling routines, after Mitsuba 3's
//! `ChiSquareTest`: draw many samples from a routine, histogram them, integrate the
//! routine's claimed density over each histogram cell, and ask whether the counts could
//! have come from that density.
//!
//! Two continuous domains are offered: the sphere of directions ([`ChiSquareTest::spherical`],
//! density in solid angle, cells in (φ, cos θ) where the solid-angle Jacobian is 1) and an
//! axis-aligned rectangle of the plane ([`ChiSquareTest::planar`], density in area; a disk
//! is tested on its bounding square). [`discrete`] tests a probability mass function.
//!
//! Beside the chi-square statistic each test also checks that the density integrates to
//! the fraction of samples that succeeded (a pdf off by a constant factor passes a
//! histogram shape test only if this is checked), that no sample lands where the density
//! is zero, and that sampled directions are unit vectors. A failed [`Chi2Report`] prints
//! the cells that contribute most to the statistic, observed against expected.
//!
//! The p-value comes from the regularized upper incomplete gamma function Q(k/2, χ²/2),
//! written here (Numerical Recipes §6.2: series below a+1, Lentz continued fraction
//! above) rather than taken from `statrs`, to keep the core free of a large dependency
//! for forty lines of well-known numerics; it is checked against closed forms below.

use std::f64::consts::TAU;
use std::fmt;

use glam::{Vec2, Vec3};

use crate::sampler::Pcg32;

/// Cells whose expected count is below this are pooled into one (the chi-square
/// approximation of the multinomial needs a handful of expected samples per cell).
pub const MIN_EXPECTED: f64 = 5.0;

/// Significance for one test out of `tests` so that the whole suite of independent tests
/// falsely fails with probability `significance` (Šidák correction):
/// α = 1 − (1 − significance)^(1/tests).
pub fn sidak_alpha(significance: f64, tests: usize) -> f64 {
    1.0 - (1.0 - significance).powf(1.0 / tests.max(1) as f64)
}

/// Settings of a continuous chi-square test. The defaults follow Mitsuba: 10⁶ samples,
/// α = 0.01 before correction.
#[derive(Clone, Debug)]
pub struct ChiSquareTest {
    /// Cells along the second axis (cos θ, or y); the first axis (φ, or x) gets
    /// `2·res` cells on the sphere and `res` cells in the plane.
    pub res: usize,
    pub sample_count: usize,
    pub seed: u64,
    /// Significance of this one test (already Šidák-corrected by the caller, see
    /// [`sidak_alpha`]).
    pub alpha: f64,
    /// Midpoint points per side of each square of the adaptive integration of the density
    /// (see `Quadrature`); a feature of the density smaller than 1/(2·k) of a cell may be
    /// missed entirely.
    pub integration_res: usize,
    /// Samples allowed where the density is zero, as a fraction of all samples: samples
    /// exactly on the edge of a density's support may fall on either side in floating
    /// point. Real bugs place far more samples outside the support.
    pub zero_pdf_tolerance: f64,
}

impl Default for ChiSquareTest {
    fn default() -> Self {
        ChiSquareTest {
            res: 32,
            sample_count: 1_000_000,
            seed: 0x5eed,
            alpha: 0.01,
            integration_res: 8,
            zero_pdf_tolerance: 1e-5,
        }
    }
}

/// The outcome of a chi-square test, with what is needed to find a problem.
#[derive(Clone, Debug)]
pub struct Chi2Report {
    pub name: String,
    pub statistic: f64,
    /// Degrees of freedom: pooled cells − 1.
    pub dof: usize,
    pub p_value: f64,
    pub alpha: f64,
    /// ∫ pdf over the domain (continuous tests), or Σ pmf (discrete).
    pub pdf_integral: f64,
    /// Fraction of sample calls that returned a sample.
    pub success_fraction: f64,
    /// Samples that landed where the density is zero.
    pub zero_pdf_samples: usize,
    /// Observed and expected counts per cell, row-major (`cols` per row).
    pub observed: Vec<f64>,
    pub expected: Vec<f64>,
    pub cols: usize,
    /// Reasons the test failed; empty if it passed.
    pub failures: Vec<String>,
    /// The cells with the largest contributions to the statistic, described.
    pub worst_cells: Vec<String>,
}

impl Chi2Report {
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }

    /// Panics with the full report unless the test passed.
    #[track_caller]
    pub fn assert_passed(&self) {
        assert!(self.passed(), "{self}");
    }

    /// Both histograms as text (one row of cells per line), to compare by eye or plot.
    pub fn histogram_dump(&self) -> String {
        let mut s = String::new();
        for (title, h) in [("observed", &self.observed), ("expected", &self.expected)] {
            s += &format!("# {title} ({} columns)\n", self.cols);
            for row in h.chunks(self.cols.max(1)) {
                let cells: Vec<String> = row.iter().map(|v| format!("{v:.1}")).collect();
                s += &cells.join(" ");
                s.push('\n');
            }
        }
        s
    }
}

impl fmt::Display for Chi2Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "chi-square test \"{}\": {}; χ² = {:.1}, dof = {}, p = {:.3e}, α = {:.3e}, \
             ∫pdf = {:.5}, success fraction = {:.5}, samples where pdf = 0: {}",
            self.name,
            if self.passed() { "passed" } else { "FAILED" },
            self.statistic,
            self.dof,
            self.p_value,
            self.alpha,
            self.pdf_integral,
            self.success_fraction,
            self.zero_pdf_samples
        )?;
        for r in &self.failures {
            writeln!(f, "  failure: {r}")?;
        }
        writeln!(f, "  worst cells (observed vs expected):")?;
        for c in &self.worst_cells {
            writeln!(f, "    {c}")?;
        }
        Ok(())
    }
}

impl ChiSquareTest {
    /// Tests a direction sampler against its solid-angle density. `sample` maps a uniform
    /// point of [0,1)² to a unit direction (`None` when sampling fails); `pdf` is the
    /// density of a direction.
    pub fn spherical(
        &self,
        name: &str,
        mut sample: impl FnMut(Vec2) -> Option<Vec3>,
        pdf: impl Fn(Vec3) -> f32,
    ) -> Chi2Report {
        let (cols, rows) = (2 * self.res, self.res);
        let to_dir = |phi: f64, z: f64| {
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
        };
        let mut extra = Vec::new();
        let mut non_unit = 0usize;
        let (observed, successes, zero_pdf) = self.histogram(cols * rows, |u| {
            let d = sample(u)?;
            if !d.is_finite() || (d.length() - 1.0).abs() > 1e-3 {
                non_unit += 1;
                return None;
            }
            let phi = (d.y as f64).atan2(d.x as f64).rem_euclid(TAU);
            let z = (d.z as f64).clamp(-1.0, 1.0);
            let ix = ((phi / TAU * cols as f64) as usize).min(cols - 1);
            let iy = (((z + 1.0) / 2.0 * rows as f64) as usize).min(rows - 1);
            Some((iy * cols + ix, pdf(d) == 0.0))
        });
        if non_unit > 0 {
            extra.push(format!("{non_unit} samples were not finite unit vectors"));
        }
        let (dphi, dz) = (TAU / cols as f64, 2.0 / rows as f64);
        let expected = self.integrate(cols, rows, &observed, |x, y| {
            pdf(to_dir(x * dphi, -1.0 + y * dz)) as f64 * dphi * dz
        });
        let label = |i: usize| {
            let (ix, iy) = (i % cols, i / cols);
            format!(
                "φ ∈ [{:.3}, {:.3}), cos θ ∈ [{:.3}, {:.3})",
                ix as f64 * dphi,
                (ix + 1) as f64 * dphi,
                -1.0 + iy as f64 * dz,
                -1.0 + (iy + 1) as f64 * dz
            )
        };
        let mut report = self.finish(name, observed, expected, cols, successes, zero_pdf, label);
        report.failures.extend(extra);
        report
    }

    /// Tests a sampler of points of the rectangle [`min`, `max`] against its density in
    /// area measure (e.g. a disk on its bounding square, with pdf 0 outside the disk).
    pub fn planar(
        &self,
        name: &str,
        min: Vec2,
        max: Vec2,
        mut sample: impl FnMut(Vec2) -> Option<Vec2>,
        pdf: impl Fn(Vec2) -> f32,
    ) -> Chi2Report {
        let (cols, rows) = (self.res, self.res);
        let size = (max - min).as_dvec2();
        let mut outside = 0usize;
        let (observed, successes, zero_pdf) = self.histogram(cols * rows, |u| {
            let p = sample(u)?;
            let t = (p - min).as_dvec2() / size;
            if !(0.0..=1.0).contains(&t.x) || !(0.0..=1.0).contains(&t.y) {
                outside += 1;
                return None;
            }
            let ix = ((t.x * cols as f64) as usize).min(cols - 1);
            let iy = ((t.y * rows as f64) as usize).min(rows - 1);
            Some((iy * cols + ix, pdf(p) == 0.0))
        });
        let (dx, dy) = (size.x / cols as f64, size.y / rows as f64);
        let expected = self.integrate(cols, rows, &observed, |x, y| {
            let p = Vec2::new(
                (min.x as f64 + x * dx) as f32,
                (min.y as f64 + y * dy) as f32,
            );
            pdf(p) as f64 * dx * dy
        });
        let label = |i: usize| {
            let (ix, iy) = (i % cols, i / cols);
            format!(
                "x ∈ [{:.3}, {:.3}), y ∈ [{:.3}, {:.3})",
                min.x as f64 + ix as f64 * dx,
                min.x as f64 + (ix + 1) as f64 * dx,
                min.y as f64 + iy as f64 * dy,
                min.y as f64 + (iy + 1) as f64 * dy
            )
        };
        let mut report = self.finish(name, observed, expected, cols, successes, zero_pdf, label);
        if outside > 0 {
            report
                .failures
                .push(format!("{outside} samples fell outside the domain"));
        }
        report
    }

    /// Draws the samples; `bin` gives a sample's cell and whether its pdf is zero.
    fn histogram(
        &self,
        cells: usize,
        mut bin: impl FnMut(Vec2) -> Option<(usize, bool)>,
    ) -> (Vec<f64>, usize, usize) {
        let mut rng = Pcg32::new(self.seed, 0xc41_5e7);
        let mut observed = vec![0.0; cells];
        let (mut successes, mut zero_pdf) = (0, 0);
        for _ in 0..self.sample_count {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            if let Some((cell, zero)) = bin(u) {
                observed[cell] += 1.0;
                successes += 1;
                zero_pdf += zero as usize;
            }
        }
        (observed, successes, zero_pdf)
    }

    /// Expected counts: `density(x, y)` (at cell coordinates, already times the measure of
    /// a unit cell) integrated over each cell adaptively, times the sample count.
    ///
    /// Cells that received samples are refined at least [`MIN_REFINE_SAMPLED`] levels
    /// before the adaptive test may stop: near the poles of (φ, cos θ) a band of
    /// directions a few degrees wide (a light seen edge-on) is a sliver thinner than the
    /// coarse grid, which would otherwise find the density zero all over the cell.
    fn integrate(
        &self,
        cols: usize,
        rows: usize,
        observed: &[f64],
        density: impl Fn(f64, f64) -> f64,
    ) -> Vec<f64> {
        let n = self.sample_count as f64;
        let k = self.integration_res.max(1);
        let mut expected = vec![0.0; cols * rows];
        for iy in 0..rows {
            for ix in 0..cols {
                let (x, y) = (ix as f64, iy as f64);
                let i = iy * cols + ix;
                let coarse = midpoint(&density, x, y, 1.0, k);
                let mut min_depth = if observed[i] > 0.0 {
                    MIN_REFINE_SAMPLED
                } else {
                    0
                };
                expected[i] = loop {
                    let q = Quadrature { k, n, min_depth };
                    let e = n * q.adaptive(&density, x, y, 1.0, coarse, 0);
                    // Samples but no density found: look closer before calling it zero.
                    if e > 0.0 || observed[i] == 0.0 || min_depth >= MAX_FORCED_REFINE {
                        break e;
                    }
                    min_depth += 1;
                };
            }
        }
        expected
    }

    #[allow(clippy::too_many_arguments)]
    fn finish(
        &self,
        name: &str,
        observed: Vec<f64>,
        expected: Vec<f64>,
        cols: usize,
        successes: usize,
        zero_pdf: usize,
        label: impl Fn(usize) -> String,
    ) -> Chi2Report {
        let n = self.sample_count as f64;
        let mut report = chi2_core(name, observed, expected, cols, self.alpha, n, label);
        report.success_fraction = successes as f64 / n;
        report.zero_pdf_samples = zero_pdf;
        // The success fraction is binomial: 5 standard deviations of it, plus 10⁻³ for
        // the error of the adaptive integration (its relative tolerance per square).
        let f = report.success_fraction;
        let tol = 5.0 * (f * (1.0 - f) / n).sqrt() + 1e-3;
        if (report.pdf_integral - f).abs() > tol {
            report.failures.push(format!(
                "the pdf integrates to {:.5} but {:.5} of the samples succeeded (tolerance {:.1e})",
                report.pdf_integral, f, tol
            ));
        }
        if zero_pdf as f64 > self.zero_pdf_tolerance * n {
            report
                .failures
                .push(format!("{zero_pdf} samples landed where the pdf is 0"));
        }
        report
    }
}

/// Tests observed counts of the outcomes of a discrete distribution against its pmf
/// (which should sum to one over outcomes that can occur).
pub fn discrete(name: &str, counts: &[u64], pmf: &[f64], alpha: f64) -> Chi2Report {
    assert_eq!(counts.len(), pmf.len(), "one pmf value per outcome");
    let n: f64 = counts.iter().map(|&c| c as f64).sum();
    let observed: Vec<f64> = counts.iter().map(|&c| c as f64).collect();
    let expected: Vec<f64> = pmf.iter().map(|&p| p * n).collect();
    let mut report = chi2_core(name, observed, expected, pmf.len(), alpha, n, |i| {
        format!("outcome {i}")
    });
    report.success_fraction = 1.0;
    report.zero_pdf_samples = counts
        .iter()
        .zip(pmf)
        .filter(|(&c, &p)| p == 0.0 && c > 0)
        .map(|(&c, _)| c as usize)
        .sum();
    if report.zero_pdf_samples > 0 {
        report.failures.push(format!(
            "{} samples hit outcomes of probability 0",
            report.zero_pdf_samples
        ));
    }
    if (report.pdf_integral - 1.0).abs() > 1e-5 {
        report
            .failures
            .push(format!("the pmf sums to {:.7}", report.pdf_integral));
    }
    report
}

/// Levels of refinement below a cell in [`adaptive`]: a discontinuity is resolved to
/// 1/(k·2¹⁰) of a cell.
const MAX_REFINE: u32 = 10;

/// Midpoint rule with k×k points over the square of side `w` at (x, y).
fn midpoint(density: &impl Fn(f64, f64) -> f64, x: f64, y: f64, w: f64, k: usize) -> f64 {
    let h = w / k as f64;
    let mut sum = 0.0;
    for j in 0..k {
        for i in 0..k {
            sum += density(x + (i as f64 + 0.5) * h, y + (j as f64 + 0.5) * h);
        }
    }
    sum * h * h
}

/// Refinement levels forced on a cell that received samples (see
/// [`ChiSquareTest::integrate`]).
const MIN_REFINE_SAMPLED: u32 = 2;

/// Deepest uniform refinement tried on a cell that received samples where the density
/// seemed zero everywhere (4⁶ squares of k² points).
const MAX_FORCED_REFINE: u32 = 6;

/// Adaptive midpoint quadrature over squares of cell coordinates.
struct Quadrature {
    /// Points per side of a square.
    k: usize,
    /// Samples in all, to express tolerances in expected samples.
    n: f64,
    min_depth: u32,
}

impl Quadrature {
    /// Compares the square's estimate `coarse` with the sum over its four quadrants and
    /// recurses where they differ by more than 10⁻³ of the value or 10⁻² of an expected
    /// sample. The densities tested are discontinuous (cones, triangles) and steep near a
    /// light's horizon, where a fixed grid is off by more than the noise of 10⁶ samples.
    #[allow(clippy::too_many_arguments)]
    fn adaptive(
        &self,
        density: &impl Fn(f64, f64) -> f64,
        x: f64,
        y: f64,
        w: f64,
        coarse: f64,
        depth: u32,
    ) -> f64 {
        let (k, n) = (self.k, self.n);
        let h = 0.5 * w;
        let quads = [(x, y), (x + h, y), (x, y + h), (x + h, y + h)];
        let fine = quads.map(|(qx, qy)| midpoint(density, qx, qy, h, k));
        let sum: f64 = fine.iter().sum();
        // The coarse estimate passed down was taken on a grid nested in the fine one; they
        // can agree by coincidence at a discontinuity. A second coarse estimate on a grid
        // of k−1 points per side does not nest with it.
        let coarse_odd = midpoint(density, x, y, w, k.saturating_sub(1).max(1));
        let err = (sum - coarse).abs().max((sum - coarse_odd).abs()) * n;
        let converged = depth >= self.min_depth && err <= (1e-3 * sum.abs() * n).max(1e-2);
        if depth >= MAX_REFINE || converged {
            return sum;
        }
        quads
            .iter()
            .zip(fine)
            .map(|(&(qx, qy), c)| self.adaptive(density, qx, qy, h, c, depth + 1))
            .sum()
    }
}

/// Pools small cells, computes χ² and its p-value, and lists the worst cells.
fn chi2_core(
    name: &str,
    observed: Vec<f64>,
    expected: Vec<f64>,
    cols: usize,
    alpha: f64,
    n: f64,
    label: impl Fn(usize) -> String,
) -> Chi2Report {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pool_obs, mut pool_exp, mut pooled) = (0.0, 0.0, 0usize);
    let mut statistic = 0.0;
    let mut cells = 0usize;
    let mut contributions = Vec::new();
    for &i in &order {
        let (o, e) = (observed[i], expected[i]);
        // Small cells go to the pool, and so does the next cell while the pool is small.
        if e < MIN_EXPECTED || (pooled > 0 && pool_exp < MIN_EXPECTED) {
            pool_obs += o;
            pool_exp += e;
            pooled += 1;
            continue;
        }
        let c = (o - e) * (o - e) / e;
        statistic += c;
        cells += 1;
        contributions.push((c, label(i), o, e));
    }
    let mut failures = Vec::new();
    if pooled > 0 {
        if pool_exp > 0.0 {
            let c = (pool_obs - pool_exp).powi(2) / pool_exp;
            statistic += c;
            cells += 1;
            contributions.push((c, format!("{pooled} pooled cells"), pool_obs, pool_exp));
        } else if pool_obs > 0.0 {
            failures.push(format!(
                "{pool_obs} samples in cells where the pdf integrates to 0"
            ));
        }
    }
    let dof = cells.saturating_sub(1);
    let p_value = if dof == 0 {
        1.0
    } else {
        chi2_survival(statistic, dof as f64)
    };
    if p_value < alpha {
        failures.push(format!(
            "the histogram does not match the pdf: p = {p_value:.3e} < α = {alpha:.3e}"
        ));
    }
    contributions.sort_by(|a, b| b.0.total_cmp(&a.0));
    let worst_cells = contributions
        .iter()
        .take(8)
        .map(|(c, l, o, e)| format!("{l}: observed {o:.0}, expected {e:.1}, contributes {c:.1}"))
        .collect();
    let pdf_integral = expected.iter().sum::<f64>() / n.max(1.0);
    Chi2Report {
        name: name.to_string(),
        statistic,
        dof,
        p_value,
        alpha,
        pdf_integral,
        success_fraction: 0.0,
        zero_pdf_samples: 0,
        observed,
        expected,
        cols,
        failures,
        worst_cells,
    }
}

mod special;
mod welch;

pub use special::{chi2_survival, gamma_q, ln_gamma};
pub use welch::{student_t_two_sided, welch_p, welch_p_samples};

#[cfg(test)]
mod tests;
