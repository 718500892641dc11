//! Sample warps from the unit square, with their densities, and discrete distributions.
//!
//! Every `sample_*` maps uniform `u ∈ [0,1)²` to a point of its domain; the matching
//! `*_pdf` gives the density of that warp with respect to the domain's natural measure
//! (solid angle for directions, area for points). Each warp is checked by the chi-square
//! suite in `tests/chi2_sampling.rs`.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_4, PI};

use glam::{Vec2, Vec3, Vec4};

/// Shirley–Chiu concentric map from the square to the unit disk (area-preserving up to
/// the factor π).
#[inline]
pub fn sample_concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    // θ = a or π/2 − a with |a| ≤ π/4, so (cos θ, sin θ) is (cos a, sin a) or
    // (sin a, cos a): two short polynomials instead of a call to the library's sincos.
    if o.x.abs() > o.y.abs() {
        let (s, c) = sin_cos_quarter(FRAC_PI_4 * (o.y / o.x));
        o.x * Vec2::new(c, s)
    } else {
        let (s, c) = sin_cos_quarter(FRAC_PI_4 * (o.x / o.y));
        o.y * Vec2::new(s, c)
    }
}

/// The Taylor coefficients of sin a / a and cos a in a², after the leading 1: a²/3!,
/// a⁴/5!, … and a²/2!, a⁴/4!, … with their signs.
const SIN_TAYLOR: [f32; 4] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0];
const COS_TAYLOR: [f32; 4] = [-0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40_320.0];

/// (sin a, cos a) for |a| ≤ π/4, by their Taylor polynomials to degree 9 and 8: the
/// first omitted terms, a¹¹/11! and a¹⁰/10!, are below 1.8·10⁻⁹ and 2.5·10⁻⁸ there, under
/// half an f32 ulp of the result.
#[inline]
pub fn sin_cos_quarter(a: f32) -> (f32, f32) {
    let a2 = a * a;
    let [s1, s2, s3, s4] = SIN_TAYLOR;
    let [c1, c2, c3, c4] = COS_TAYLOR;
    let s = a * (1.0 + a2 * (s1 + a2 * (s2 + a2 * (s3 + a2 * s4))));
    let c = 1.0 + a2 * (c1 + a2 * (c2 + a2 * (c3 + a2 * c4)));
    (s, c)
}

/// 1.5·2²³: adding and subtracting it rounds an f32 of magnitude under 2²² to the nearest
/// integer.
const ROUND_TO_INTEGER: f32 = 12_582_912.0;

/// (s, c) = (sin r, cos r) turned by `q` quarter turns: (sin, cos) of r + q·π/2.
#[inline]
fn quarter_turned(q: f32, s: f32, c: f32) -> (f32, f32) {
    // q is a whole number of magnitude under 2²², so the fast truncation is exact.
    match truncate_to_i32(q) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// (sin, cos) of t·π/2 for |t| ≤ 2²²: t split into the nearest integer q (by the
/// 1.5·2²³ rounding trick, no library call) and a rest r with |r| ≤ ½, then
/// [`sin_cos_quarter`] of r·π/2 turned by q quarter turns. Taking the angle in quarter
/// turns keeps π out of the reduction, so the error stays within an ulp or two of the
/// result where libm's `sincosf` of a product with π is also off by that product's
/// rounding.
#[inline]
pub fn sin_cos_quarter_turns(t: f32) -> (f32, f32) {
    let q = (t + ROUND_TO_INTEGER) - ROUND_TO_INTEGER;
    let (s, c) = sin_cos_quarter(std::f32::consts::FRAC_PI_2 * (t - q));
    quarter_turned(q, s, c)
}

/// [`sin_cos_quarter_turns`] of `t.x` and `t.y`, bit for bit, with the four polynomials
/// (two sines, two cosines) evaluated together in SIMD lanes: the same operations in the
/// same order in every lane (a cosine's final product with 1 is exact).
#[inline]
pub fn sin_cos_quarter_turns_pair(t: Vec2) -> [(f32, f32); 2] {
    let t = Vec4::new(t.x, t.x, t.y, t.y);
    let q = (t + ROUND_TO_INTEGER) - ROUND_TO_INTEGER;
    let a = std::f32::consts::FRAC_PI_2 * (t - q);
    let a2 = a * a;
    // Lanes: sin and cos of the first angle, then of the second.
    let coefficient =
        |i: usize| Vec4::new(SIN_TAYLOR[i], COS_TAYLOR[i], SIN_TAYLOR[i], COS_TAYLOR[i]);
    let mut p = coefficient(2) + a2 * coefficient(3);
    p = coefficient(1) + a2 * p;
    p = coefficient(0) + a2 * p;
    p = Vec4::new(a.x, 1.0, a.z, 1.0) * (1.0 + a2 * p);
    [quarter_turned(q.x, p.x, p.y), quarter_turned(q.z, p.z, p.w)]
}

/// Cosine-weighted direction on the hemisphere around +z (Malley's method).
#[inline]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = sample_concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Density of [`sample_cosine_hemisphere`] in solid angle.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Uniform direction on the unit sphere.
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_sphere`] in solid angle.
pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Uniform direction in the cone around +z with half-angle `acos(cos_max)`.
pub fn sample_uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_theta = (1.0 - u.x) + u.x * cos_max;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// Density of [`sample_uniform_cone`] in solid angle.
pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * (1.0 - cos_max))
}

/// Uniform barycentric coordinates `(b0, b1, b2)` on a triangle (Heitz 2019, "A Low-
/// Distortion Map Between Triangle and Square").
pub fn sample_uniform_triangle(u: Vec2) -> Vec3 {
    let (b0, b1) = if u.x < u.y {
        let b0 = u.x / 2.0;
        (b0, u.y - b0)
    } else {
        let b1 = u.y / 2.0;
        (u.x - b1, b1)
    };
    Vec3::new(b0, b1, 1.0 - b0 - b1)
}

/// A point of [0, 1) drawn with density ∝ (1 − x)·a + x·b, a, b ≥ 0 not both zero: the
/// root of its quadratic CDF, in the form that stays exact where a ≈ b.
#[inline]
pub fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + ((1.0 - u) * a * a + u * b * b).sqrt());
    x.min(ONE_MINUS_EPSILON)
}

/// A point of the unit square drawn with the bilinear density through the corner weights
/// `w` at (0, 0), (1, 0), (0, 1) and (1, 1) (non-negative, not all zero): y from its
/// marginal, then x given y, each linear. Monotone in each coordinate, so stratified
/// numbers stay stratified.
#[inline]
pub fn sample_bilinear(u: Vec2, w: [f32; 4]) -> Vec2 {
    let y = sample_linear(u.y, w[0] + w[1], w[2] + w[3]);
    let x = sample_linear(u.x, w[0] + (w[2] - w[0]) * y, w[1] + (w[3] - w[1]) * y);
    Vec2::new(x, y)
}

/// Density of [`sample_bilinear`] at `p` with respect to area.
#[inline]
pub fn bilinear_pdf(p: Vec2, w: [f32; 4]) -> f32 {
    let (x, y) = (p.x, p.y);
    let f =
        (1.0 - x) * (1.0 - y) * w[0] + x * (1.0 - y) * w[1] + (1.0 - x) * y * w[2] + x * y * w[3];
    4.0 * f / (w[0] + w[1] + w[2] + w[3])
}

/// Balance heuristic weight of strategy `f` against strategy `g` (one sample each).
#[inline]
pub fn balance_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    if pdf_f == 0.0 {
        return 0.0;
    }
    pdf_f / (pdf_f + pdf_g)
}

/// Power heuristic (β = 2) weight of strategy `f` against strategy `g`.
#[inline]
pub fn power_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    if pdf_f == 0.0 {
        return 0.0;
    }
    let (f, g) = (pdf_f * pdf_f, pdf_g * pdf_g);
    if f.is_infinite() {
        return 1.0;
    }
    f / (f + g)
}

/// `x` truncated towards zero, as `x as i32` for |x| < 2³¹. On x86-64 by SSE2's one
/// truncating conversion, where `as` adds the saturation's tests and moves (five or six
/// instructions): NaN and values out of range give −2³¹ there (`as` saturates; other
/// targets use `as`).
#[inline(always)]
pub(crate) fn truncate_to_i32(x: f32) -> i32 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvttss_si32, _mm_set_ss};
        // SAFETY: SSE2 is part of x86-64.
        unsafe { _mm_cvttss_si32(_mm_set_ss(x)) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        x as i32
    }
}

/// `x as usize` for `x` in [0, 2³¹) (the callers clamp it to a table's size), by
/// [`truncate_to_i32`]: NaN, negatives and values past 2³¹ − 1 give 2³¹ on x86-64, which
/// the callers' `min` with the last cell keeps in bounds.
#[inline(always)]
pub(crate) fn cell_index(x: f32) -> usize {
    truncate_to_i32(x) as u32 as usize
}

/// Walker's alias method, built with Vose's stable algorithm: O(n) build, O(1) sample.
#[derive(Clone, Debug, Default)]
pub struct AliasTable {
    bins: Vec<AliasBin>,
    total: f64,
}

#[derive(Clone, Copy, Debug)]
struct AliasBin {
    /// Probability of keeping this bin's own index.
    q: f32,
    alias: u32,
    /// Normalized probability of this index.
    pmf: f32,
}

impl AliasTable {
    /// A table over non-negative `weights`. Returns `None` if no weight is positive or any
    /// is negative or not finite.
    pub fn new(weights: &[f32]) -> Option<AliasTable> {
        if weights.iter().any(|w| !w.is_finite() || *w < 0.0) {
            return None;
        }
        let total: f64 = weights.iter().map(|&w| w as f64).sum();
        if total <= 0.0 {
            return None;
        }
        let n = weights.len();
        let mut bins: Vec<AliasBin> = weights
            .iter()
            .map(|&w| AliasBin {
                q: 0.0,
                alias: 0,
                pmf: (w as f64 / total) as f32,
            })
            .collect();
        // Scaled probabilities p·n: below 1 the bin is under-full and takes an alias.
        let mut scaled: Vec<f64> = weights
            .iter()
            .map(|&w| w as f64 / total * n as f64)
            .collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&i| scaled[i] < 1.0);
        // Peek at both lists before taking from either: popping `small` first would lose
        // its last entry (with q = 0) whenever round-off empties `large` first.
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            bins[s].q = scaled[s] as f32;
            bins[s].alias = l as u32;
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What remains is full up to round-off.
        for i in small.into_iter().chain(large) {
            bins[i].q = 1.0;
            bins[i].alias = i as u32;
        }
        Some(AliasTable { bins, total })
    }

    pub fn len(&self) -> usize {
        self.bins.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// Sum of the weights the table was built from.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Probability of index `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        self.bins[i].pmf
    }

    /// An index with probability `pmf(index)`, from one uniform number.
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let n = self.bins.len();
        let scaled = u * n as f32;
        let i = (scaled as usize).min(n - 1);
        let up = (scaled - i as f32).min(ONE_MINUS_EPSILON);
        let bin = &self.bins[i];
        let index = if up < bin.q { i } else { bin.alias as usize };
        (index, self.bins[index].pmf)
    }
}

/// The largest float below one, so that `u < 1` is kept after scaling.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A piecewise-constant density on [0, 1) with `n` equal cells, sampled by inverting its
/// CDF. The inversion starts from a guide table (Chen & Asau's cutpoint method): entry g
/// holds the cell where u = g/n falls, so that finding u's cell is a lookup and, on
/// average, under two steps along the CDF, not the dozen dependent, unpredictable loads
/// of a binary search over a thousand cells.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f32>,
    cdf: Vec<f32>,
    integral: f32,
    guide: Vec<u32>,
}

impl Distribution1D {
    /// A distribution proportional to `func` (non-negative). Where all values are zero the
    /// distribution is uniform, so that it can still be sampled.
    pub fn new(func: &[f32]) -> Distribution1D {
        assert!(!func.is_empty(), "Distribution1D needs at least one cell");
        let n = func.len();
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0f32);
        let mut acc = 0.0f64;
        for &f in func {
            acc += f.max(0.0) as f64 / n as f64;
            cdf.push(acc as f32);
        }
        let integral = acc as f32;
        let func: Vec<f32> = if integral > 0.0 {
            for c in cdf.iter_mut() {
                *c /= integral;
            }
            func.iter().map(|f| f.max(0.0)).collect()
        } else {
            for (i, c) in cdf.iter_mut().enumerate() {
                *c = i as f32 / n as f32;
            }
            vec![1.0; n]
        };
        let integral = if integral > 0.0 { integral } else { 1.0 };
        // The last cell whose start is at or below g/n, for each g.
        let mut guide = Vec::with_capacity(n);
        let mut i = 0;
        for g in 0..n {
            let u = g as f32 / n as f32;
            while i + 1 < n && cdf[i + 1] <= u {
                i += 1;
            }
            guide.push(i as u32);
        }
        Distribution1D {
            func,
            cdf,
            integral,
            guide,
        }
    }

    pub fn len(&self) -> usize {
        self.func.len()
    }

    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// The integral of the function over [0, 1).
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// Samples a continuous x ∈ [0,1); returns (x, density at x, cell index).
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, du) = self.sample_cell(u);
        let n = self.func.len();
        let x = ((i as f32 + du) / n as f32).min(ONE_MINUS_EPSILON);
        (x, self.cell_pdf(i), i)
    }

    /// Samples a cell; returns its index and where `u` fell within the cell's share of the
    /// CDF, in [0, 1): a uniform number again, for sampling within the cell. The cell's
    /// probability is its density (as [`Self::pdf`] gives it) over the number of cells.
    ///
    /// Always inlined (the environment's two steps called it out of line, ~15 of its ~70
    /// instructions the call); the guide's index by `cell_index`, one instruction where
    /// the saturating `f32 → usize` takes several, the same index for tables under 2³¹
    /// cells. The tables are read without bounds checks (one or two compares and a branch
    /// each, six or more a call): `new` makes every index here provably in bounds.
    #[inline(always)]
    pub fn sample_cell(&self, u: f32) -> (usize, f32) {
        let n = self.func.len();
        // SAFETY: `new` builds `guide` with n entries, each below n, and `cdf` with n + 1,
        // and nothing changes them after. So the guide's index (below n by the `min`; n ≥ 1)
        // and every i below (below n: from the guide, then only decreased to 0 or increased
        // while i + 1 < n) are in bounds, and so is i + 1 ≤ n in `cdf`.
        let (guide, cdf) = (&self.guide, &self.cdf);
        let at = |i: usize| unsafe { *cdf.get_unchecked(i) };
        // The last cell whose CDF start is <= u, from the guide's cell for u's n-th of
        // [0, 1). The step back is for the rounding of u·n up to the next entry.
        let mut i = unsafe { *guide.get_unchecked(cell_index(u * n as f32).min(n - 1)) } as usize;
        while i > 0 && at(i) > u {
            i -= 1;
        }
        while i + 1 < n && at(i + 1) <= u {
            i += 1;
        }
        let (start, end) = (at(i), at(i + 1));
        let width = end - start;
        let du = if width > 0.0 {
            ((u - start) / width).clamp(0.0, ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (i, du)
    }

    /// Density of cell `i` (constant over the cell): the function's value there over its
    /// integral.
    #[inline]
    pub fn cell_pdf(&self, i: usize) -> f32 {
        self.func[i] / self.integral
    }

    /// Density at `x ∈ [0,1)` of [`Self::sample_continuous`].
    pub fn pdf(&self, x: f32) -> f32 {
        let n = self.func.len();
        self.cell_pdf(((x * n as f32) as usize).min(n - 1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_cos_quarter_matches_the_library_to_an_ulp() {
        // Over |a| ≤ π/4 at 10⁵ + 1 points, ends included, against f64's sin and cos.
        let mut worst = 0.0f64;
        for i in 0..=100_000 {
            let a = FRAC_PI_4 * (i as f32 / 50_000.0 - 1.0);
            let (s, c) = sin_cos_quarter(a);
            let (ws, wc) = (a as f64).sin_cos();
            worst = worst.max((s as f64 - ws).abs()).max((c as f64 - wc).abs());
        }
        // One f32 ulp of values in [0.7, 1] is 6·10⁻⁸ (the Taylor remainder is below it).
        assert!(worst < 1.2e-7, "worst error {worst:e}");
    }

    #[test]
    fn sin_cos_quarter_turns_matches_the_exact_values_over_two_turns() {
        // t·π/2 for t over [−2, 2] and [0, 2] at 2·10⁵ + 1 points, against f64.
        let mut worst = 0.0f64;
        for i in 0..=200_000 {
            let t = i as f32 / 50_000.0 - 2.0;
            let (s, c) = sin_cos_quarter_turns(t);
            let (ws, wc) = (t as f64 * std::f64::consts::FRAC_PI_2).sin_cos();
            worst = worst.max((s as f64 - ws).abs()).max((c as f64 - wc).abs());
        }
        assert!(worst < 1.2e-7, "worst error {worst:e}");
        assert_eq!(sin_cos_quarter_turns(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_quarter_turns(1.0), (1.0, -0.0));
        assert_eq!(sin_cos_quarter_turns(-2.0), (0.0, -1.0));
    }

    #[test]
    fn sin_cos_quarter_turns_pair_gives_the_scalar_bits() {
        // Two different angles a call, over [−2, 2] quarter turns (quadrant edges, zeros
        // of either sign, half-way points included).
        let mut ts = vec![0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 1.5, 2.0, -2.0, 0.25];
        ts.extend((0..=40_000).map(|i| i as f32 / 10_000.0 - 2.0));
        for (i, &t0) in ts.iter().enumerate() {
            let t1 = ts[(i * 7919 + 13) % ts.len()];
            let pair = sin_cos_quarter_turns_pair(Vec2::new(t0, t1));
            for (t, (s, c)) in [(t0, pair[0]), (t1, pair[1])] {
                let (ws, wc) = sin_cos_quarter_turns(t);
                assert_eq!(
                    (s.to_bits(), c.to_bits()),
                    (ws.to_bits(), wc.to_bits()),
                    "t = {t}"
                );
            }
        }
    }

    #[test]
    fn concentric_disk_keeps_the_square_s_edges_on_the_circle() {
        for i in 0..=64 {
            let t = i as f32 / 64.0;
            for u in [
                Vec2::new(t, 0.0),
                Vec2::new(t, 1.0),
                Vec2::new(0.0, t),
                Vec2::new(1.0, t),
            ] {
                let d = sample_concentric_disk(u);
                assert!((d.length() - 1.0).abs() < 2e-7, "{u} -> {d}");
            }
        }
        assert_eq!(sample_concentric_disk(Vec2::splat(0.5)), Vec2::ZERO);
    }

    #[test]
    fn alias_table_pmf_matches_weights_and_sums_to_one() {
        let w = [1.0, 0.0, 3.0, 0.5, 10.0];
        let t = AliasTable::new(&w).unwrap();
        let total: f32 = w.iter().sum();
        let sum: f32 = (0..w.len()).map(|i| t.pmf(i)).sum();
        assert!((sum - 1.0).abs() < 1e-6);
        for (i, wi) in w.iter().enumerate() {
            assert!((t.pmf(i) - wi / total).abs() < 1e-6);
        }
        // A zero-weight entry is never returned, whatever u is.
        for k in 0..10_000 {
            let (i, _) = t.sample(k as f32 / 10_000.0);
            assert_ne!(i, 1);
        }
    }

    #[test]
    fn alias_table_rejects_degenerate_weights() {
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[0.0, 0.0]).is_none());
        assert!(AliasTable::new(&[1.0, f32::NAN]).is_none());
        assert!(AliasTable::new(&[1.0, -1.0]).is_none());
    }

    /// The guide table finds the cell a binary search over the CDF finds (the last whose
    /// start is at or below u), for every u tried: 10⁵ random ones and every cell's own
    /// start and its neighbouring floats, over distributions of 1 to 2 000 cells with
    /// runs of empty cells and a spike holding most of the mass.
    #[test]
    fn the_guide_table_finds_the_binary_searchs_cell() {
        let mut rng = crate::sampler::Pcg32::new(17, 5);
        for n in [1usize, 2, 3, 7, 64, 1000, 2000] {
            let func: Vec<f32> = (0..n)
                .map(|i| match rng.uniform_f32() {
                    r if r < 0.3 => 0.0,
                    r if r < 0.31 => 1e4,
                    _ => (i % 5) as f32 + rng.uniform_f32(),
                })
                .collect();
            let d = Distribution1D::new(&func);
            let searched = |u: f32| {
                d.cdf
                    .partition_point(|&c| c <= u)
                    .saturating_sub(1)
                    .min(n - 1)
            };
            let edges = d.cdf.iter().flat_map(|&c| {
                [
                    c,
                    f32::from_bits(c.to_bits().saturating_sub(1)),
                    c.next_up(),
                ]
            });
            let random = (0..100_000).map(|_| rng.uniform_f32());
            for u in edges.chain(random).filter(|u| (0.0..1.0).contains(u)) {
                assert_eq!(d.sample_cell(u).0, searched(u), "n {n}, u {u}");
            }
        }
    }

    #[test]
    fn distribution_1d_inverts_its_cdf() {
        let d = Distribution1D::new(&[0.0, 1.0, 3.0, 0.0]);
        assert!((d.integral() - 1.0).abs() < 1e-6);
        let (x, pdf, i) = d.sample_continuous(0.5);
        assert_eq!(i, 2);
        assert!((pdf - 3.0).abs() < 1e-5);
        assert!((0.5..0.75).contains(&x));
        assert_eq!(d.pdf(0.1), 0.0);
        // Zero cells are never sampled, even at the CDF's flat ends.
        for u in [0.0, 1e-7, 0.25, 0.9999999] {
            let (_, pdf, _) = d.sample_continuous(u);
            assert!(pdf > 0.0, "u = {u}");
        }
    }
}
