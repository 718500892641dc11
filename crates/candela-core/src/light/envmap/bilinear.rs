//! A density on the unit square proportional to a function known at the vertices of a
//! grid and interpolated bilinearly between them, sampled exactly: the continuous
//! `Marginal2D` of Mitsuba 3 (`distr_2d.h`), with rows that need not be evenly spaced.
//!
//! The marginal density of y, ∫ f(x, y) dx, is linear between two vertex rows (the
//! integral of a bilinear function over x is linear in y), so y is drawn by inverting a
//! piecewise-linear CDF. Given y, f(·, y) is piecewise linear in x, and its running
//! integral is the same blend of the two vertex rows' running integrals, so x is drawn
//! the same way without building anything per sample. Both inversions are monotone, so
//! stratified numbers stay stratified.

use glam::Vec2;

use crate::sampling::{sample_linear, ONE_MINUS_EPSILON};

/// `n` as an `f32`: the value of `n as f32`, for the grid sizes here (below 2³²), by way
/// of `u32`, whose conversion on x86-64 is one instruction where `usize`'s tests the sign
/// bit and branches.
#[inline(always)]
fn size_f32(n: usize) -> f32 {
    debug_assert!(u32::try_from(n).is_ok());
    n as u32 as f32
}

/// `x as usize` for `x` below 2³² (the callers clamp it to a grid size; 0 for NaN and
/// negatives, as `as usize`), by way of `u32`: on x86-64 half the instructions of the
/// saturating conversion to `usize`, which also handles values past 2⁶³.
#[inline(always)]
pub(super) fn cell_index(x: f32) -> usize {
    x as u32 as usize
}

/// Where the vertices of one axis of a [`Bilinear2D`] grid lie on [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridAxis {
    /// `n` equal cells: vertices at k/n for k = 0..=n.
    Even(usize),
    /// The texel centres of an image `n` texels across, (k + ½)/n for k = 0..n, and the
    /// two edges 0 and 1: `n + 1` cells, the first and the last half as wide as the
    /// others. The cells of a bilinear lookup that clamps at the edges.
    Centred(usize),
}

impl GridAxis {
    /// Number of vertices along the axis.
    pub fn vertices(self) -> usize {
        match self {
            GridAxis::Even(n) => n + 1,
            GridAxis::Centred(n) => n + 2,
        }
    }

    /// Position of vertex `k` on [0, 1].
    #[inline]
    pub fn position(self, k: usize) -> f32 {
        match self {
            GridAxis::Even(n) => size_f32(k) / size_f32(n),
            GridAxis::Centred(n) => {
                if k == 0 {
                    0.0
                } else if k > n {
                    1.0
                } else {
                    (size_f32(k) - 0.5) / size_f32(n)
                }
            }
        }
    }

    /// The cell holding `x ∈ [0, 1]` (clamped) and where `x` lies within it, in [0, 1].
    #[inline]
    pub fn locate(self, x: f32) -> (usize, f32) {
        match self {
            GridAxis::Even(n) => {
                let s = (x * size_f32(n)).clamp(0.0, size_f32(n));
                let k = cell_index(s).min(n - 1);
                (k, (s - size_f32(k)).min(1.0))
            }
            GridAxis::Centred(n) => {
                let s = (x * size_f32(n) + 0.5).clamp(0.0, size_f32(n) + 1.0);
                let k = cell_index(s).min(n);
                let t = if k == 0 {
                    2.0 * s - 1.0
                } else if k == n {
                    2.0 * (s - size_f32(k))
                } else {
                    s - size_f32(k)
                };
                (k, t.clamp(0.0, 1.0))
            }
        }
    }
}

/// A piecewise-bilinear density on [0, 1]²: see the module documentation.
#[derive(Clone, Debug)]
pub struct Bilinear2D {
    x_axis: GridAxis,
    y_axis: GridAxis,
    /// Vertices per row.
    stride: usize,
    /// The function at the vertices, row-major (non-negative).
    values: Vec<f32>,
    /// For each vertex row, ∫₀^{x_k} f(x, y_row) dx at each vertex column k.
    row_cdf: Vec<f32>,
    /// ∫₀^{y_j} ∫₀¹ f dx dy at each vertex row j.
    marginal_cdf: Vec<f32>,
    /// Guide to `marginal_cdf`: one entry per row cell, and one more.
    marginal_guide: Vec<u32>,
    /// Guides to each vertex row's `row_cdf`: `ROW_GUIDE + 1` entries a row.
    row_guides: Vec<u32>,
    /// [`GridAxis::position`] of every vertex of each axis, looked up by the sampling
    /// rather than computed (a match on the axis, a conversion and a division each).
    x_positions: Vec<f32>,
    y_positions: Vec<f32>,
    integral: f32,
}

/// Parts of a vertex row's mass its guide marks.
const ROW_GUIDE: usize = 64;

/// For a non-decreasing `cdf` over `cells` cells (`cells + 1` entries from 0), entry g
/// of `parts + 1` is the last cell k with cdf[k] ≤ g/parts of the total.
fn guide(cdf: &[f32], parts: usize) -> Vec<u32> {
    let cells = cdf.len() - 1;
    let total = cdf[cells];
    let mut k = 0;
    (0..=parts)
        .map(|g| {
            let threshold = total * (g as f32 / parts as f32);
            while k + 1 < cells && cdf[k + 1] <= threshold {
                k += 1;
            }
            k as u32
        })
        .collect()
}

/// The last cell k < `cells` with cdf(k) ≤ `target` (cdf(0) = 0 ≤ target), by binary
/// search between the guesses `lo` and `hi` (cdf(lo) ≤ target < cdf(hi)), widened to
/// the whole range where either does not hold.
#[inline]
fn last_at_or_below(
    cdf: impl Fn(usize) -> f32,
    target: f32,
    cells: usize,
    lo: usize,
    hi: usize,
) -> usize {
    let mut lo = if cdf(lo) <= target { lo } else { 0 };
    let mut hi = if hi > lo && hi < cells && cdf(hi) > target {
        hi
    } else {
        cells
    };
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if cdf(mid) <= target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

impl Bilinear2D {
    /// A density proportional to the bilinear interpolation of `values` (row-major,
    /// `x_axis.vertices()` a row, `y_axis.vertices()` rows; negative values count as 0).
    pub fn new(values: Vec<f32>, x_axis: GridAxis, y_axis: GridAxis) -> Bilinear2D {
        let (stride, rows) = (x_axis.vertices(), y_axis.vertices());
        assert_eq!(values.len(), stride * rows, "one value per vertex");
        let values: Vec<f32> = values.into_iter().map(|v| v.max(0.0)).collect();
        let mut row_cdf = Vec::with_capacity(values.len());
        let mut row_integrals = Vec::with_capacity(rows);
        for row in values.chunks_exact(stride) {
            let mut acc = 0.0f64;
            row_cdf.push(0.0);
            for k in 0..stride - 1 {
                let width = (x_axis.position(k + 1) - x_axis.position(k)) as f64;
                acc += 0.5 * (row[k] as f64 + row[k + 1] as f64) * width;
                row_cdf.push(acc as f32);
            }
            row_integrals.push(acc);
        }
        let mut marginal_cdf = Vec::with_capacity(rows);
        let mut acc = 0.0f64;
        marginal_cdf.push(0.0);
        for j in 0..rows - 1 {
            let height = (y_axis.position(j + 1) - y_axis.position(j)) as f64;
            acc += 0.5 * (row_integrals[j] + row_integrals[j + 1]) * height;
            marginal_cdf.push(acc as f32);
        }
        let marginal_guide = guide(&marginal_cdf, rows - 1);
        let row_guides = row_cdf
            .chunks_exact(stride)
            .flat_map(|row| guide(row, ROW_GUIDE))
            .collect();
        let positions = |axis: GridAxis| (0..axis.vertices()).map(|k| axis.position(k)).collect();
        Bilinear2D {
            x_axis,
            y_axis,
            stride,
            values,
            row_cdf,
            marginal_cdf,
            marginal_guide,
            row_guides,
            x_positions: positions(x_axis),
            y_positions: positions(y_axis),
            integral: acc as f32,
        }
    }

    /// ∫∫ f dx dy over the unit square (before normalisation).
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// The interpolated function at `p ∈ [0, 1]²` (not normalised).
    #[inline]
    pub fn value(&self, p: Vec2) -> f32 {
        let (k, s) = self.x_axis.locate(p.x);
        let (j, t) = self.y_axis.locate(p.y);
        self.value_in_cell(k, s, j, t)
    }

    /// The interpolated function at (`s`, `t`) within the cell of column `k`, row `j`.
    #[inline]
    pub fn value_in_cell(&self, k: usize, s: f32, j: usize, t: f32) -> f32 {
        let i = j * self.stride + k;
        let v = &self.values;
        let top = v[i] + s * (v[i + 1] - v[i]);
        let bottom = v[i + self.stride] + s * (v[i + self.stride + 1] - v[i + self.stride]);
        top + t * (bottom - top)
    }

    /// Density of [`Self::sample`] at `p ∈ [0, 1]²`.
    #[inline]
    pub fn pdf(&self, p: Vec2) -> f32 {
        if self.integral > 0.0 {
            self.value(p) / self.integral
        } else {
            0.0
        }
    }

    /// A point of [0, 1)² drawn with density ∝ f, and that density; `None` when f is
    /// zero everywhere.
    pub fn sample(&self, u: Vec2) -> Option<(Vec2, f32)> {
        if self.integral <= 0.0 {
            return None;
        }
        // The row cell, from the marginal: linear from one vertex row's integral to the
        // next's.
        let target = u.y * self.integral;
        let m = &self.marginal_cdf;
        let cells = m.len() - 1;
        let g = cell_index(u.y * size_f32(cells)).min(cells - 1);
        let (lo, hi) = (self.marginal_guide[g], self.marginal_guide[g + 1] + 1);
        let j = last_at_or_below(|j| m[j], target, cells, lo as usize, hi as usize);
        let xi = unit_within(m[j], m[j + 1], target);
        let row_integral = |j: usize| self.row_cdf[(j + 1) * self.stride - 1];
        let t = sample_linear(xi, row_integral(j), row_integral(j + 1));
        let (y0, y1) = (self.y_positions[j], self.y_positions[j + 1]);
        let y = (y0 + t * (y1 - y0)).min(ONE_MINUS_EPSILON);

        // The column cell, from f(·, y)'s running integral: the blend of the two vertex
        // rows' running integrals.
        let top = &self.row_cdf[j * self.stride..(j + 1) * self.stride];
        let bottom = &self.row_cdf[(j + 1) * self.stride..(j + 2) * self.stride];
        let cdf = |k: usize| top[k] + t * (bottom[k] - top[k]);
        let cells = self.stride - 1;
        let target = u.x * cdf(cells);
        let g = cell_index(u.x * ROW_GUIDE as f32).min(ROW_GUIDE - 1);
        let guides = &self.row_guides[j * (ROW_GUIDE + 1)..(j + 2) * (ROW_GUIDE + 1)];
        let (top_guide, bottom_guide) = guides.split_at(ROW_GUIDE + 1);
        let lo = top_guide[g].min(bottom_guide[g]) as usize;
        let hi = top_guide[g + 1].max(bottom_guide[g + 1]) as usize + 1;
        let k = last_at_or_below(cdf, target, cells, lo, hi);
        let xi = unit_within(cdf(k), cdf(k + 1), target);
        let i = j * self.stride + k;
        let v = &self.values;
        let f0 = v[i] + t * (v[i + self.stride] - v[i]);
        let f1 = v[i + 1] + t * (v[i + self.stride + 1] - v[i + 1]);
        let s = sample_linear(xi, f0, f1);
        let (x0, x1) = (self.x_positions[k], self.x_positions[k + 1]);
        let x = (x0 + s * (x1 - x0)).min(ONE_MINUS_EPSILON);
        let f = f0 + s * (f1 - f0);
        (f > 0.0).then(|| (Vec2::new(x, y), f / self.integral))
    }
}

/// Where `target` lies between `c0` and `c1`, in [0, 1); 0 for an empty interval.
#[inline]
fn unit_within(c0: f32, c1: f32, target: f32) -> f32 {
    if c1 > c0 {
        ((target - c0) / (c1 - c0)).clamp(0.0, ONE_MINUS_EPSILON)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_locate_their_cells() {
        let even = GridAxis::Even(4);
        assert_eq!(even.locate(0.0), (0, 0.0));
        assert_eq!(even.locate(0.625), (2, 0.5));
        assert_eq!(even.locate(1.0), (3, 1.0));
        let centred = GridAxis::Centred(4);
        assert_eq!(centred.vertices(), 6);
        assert_eq!(centred.position(1), 0.125);
        assert_eq!(centred.position(5), 1.0);
        assert_eq!(centred.locate(0.0), (0, 0.0));
        assert_eq!(centred.locate(0.0625), (0, 0.5)); // half of the first, half-width cell
        assert_eq!(centred.locate(0.25), (1, 0.5));
        assert_eq!(centred.locate(0.9375), (4, 0.5));
        assert_eq!(centred.locate(1.0), (4, 1.0));
        for i in 0..=100 {
            let x = i as f32 / 100.0;
            for axis in [even, centred] {
                let (k, t) = axis.locate(x);
                let (a, b) = (axis.position(k), axis.position(k + 1));
                assert!((a + t * (b - a) - x).abs() < 1e-6, "{axis:?} {x}");
            }
        }
    }

    #[test]
    fn integral_is_exact_for_bilinear_data() {
        // f(x, y) = 1 + 2x + 3y is bilinear: ∫∫ = 1 + 1 + 1.5 on any grid.
        for (xa, ya) in [
            (GridAxis::Even(3), GridAxis::Even(5)),
            (GridAxis::Centred(4), GridAxis::Centred(2)),
        ] {
            let mut values = Vec::new();
            for j in 0..ya.vertices() {
                for k in 0..xa.vertices() {
                    values.push(1.0 + 2.0 * xa.position(k) + 3.0 * ya.position(j));
                }
            }
            let d = Bilinear2D::new(values, xa, ya);
            assert!((d.integral() - 3.5).abs() < 1e-5, "{}", d.integral());
            let p = Vec2::new(0.3, 0.8);
            assert!((d.value(p) - (1.0 + 0.6 + 2.4)).abs() < 1e-5);
        }
    }

    #[test]
    fn samples_report_the_pdf_of_their_point() {
        let values: Vec<f32> = (0..6 * 5).map(|i| ((i * 7) % 5) as f32).collect();
        let d = Bilinear2D::new(values, GridAxis::Even(5), GridAxis::Centred(3));
        // Numbers off 0: u = (0, 0) lands on the edge of the support, where f = 0 (and
        // `sample` gives nothing).
        for i in 1..1000 {
            let u = Vec2::new(
                (i as f32 * 0.618_034).fract(),
                (i as f32 * 0.414_214).fract(),
            );
            let (p, pdf) = d.sample(u).expect("inside the support");
            assert!(pdf > 0.0 && (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
            assert!((d.pdf(p) - pdf).abs() <= 1e-4 * pdf.max(1.0), "{p} {pdf}");
        }
    }

    /// [`Bilinear2D::sample`]'s searches without the guides: plain binary searches.
    fn unguided_cells(d: &Bilinear2D, u: Vec2) -> (usize, usize) {
        let full = |cdf: &dyn Fn(usize) -> f32, target, cells| {
            last_at_or_below(cdf, target, cells, 0, cells)
        };
        let m = &d.marginal_cdf;
        let j = full(&|j| m[j], u.y * d.integral, m.len() - 1);
        let xi = unit_within(m[j], m[j + 1], u.y * d.integral);
        let row = |j: usize| d.row_cdf[(j + 1) * d.stride - 1];
        let t = sample_linear(xi, row(j), row(j + 1));
        let (top, bottom) = (&d.row_cdf[j * d.stride..], &d.row_cdf[(j + 1) * d.stride..]);
        let cdf = |k: usize| top[k] + t * (bottom[k] - top[k]);
        let cells = d.stride - 1;
        (j, full(&cdf, u.x * cdf(cells), cells))
    }

    #[test]
    fn guided_searches_find_the_cells_binary_searches_find() {
        // A 257 × 130 grid with a bright spot, empty stretches and a ramp, and 2·10⁵
        // samples: the guided sample's cells are the plain searches' cells.
        let (w, h) = (257, 130);
        let mut values = vec![0.0f32; w * h];
        for (i, v) in values.iter_mut().enumerate() {
            let (x, y) = (i % w, i / w);
            *v = match (x / 40, y / 30) {
                (1, _) | (_, 2) => 0.0,
                _ => 0.1 + (x as f32 / w as f32) * ((i * 7919) % 13) as f32,
            };
            if (120..124).contains(&x) && (60..63).contains(&y) {
                *v = 5e4;
            }
        }
        let d = Bilinear2D::new(values, GridAxis::Even(w - 1), GridAxis::Centred(h - 2));
        let mut state = 0x9e37_79b9u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        for _ in 0..200_000 {
            let u = Vec2::new(next(), next());
            let (p, _) = d.sample(u).expect("positive there");
            let (j, k) = unguided_cells(&d, u);
            let (x0, x1) = (d.x_axis.position(k), d.x_axis.position(k + 1));
            let (y0, y1) = (d.y_axis.position(j), d.y_axis.position(j + 1));
            assert!(
                (x0..=x1).contains(&p.x) && (y0..=y1).contains(&p.y),
                "{u}: {p}"
            );
        }
    }

    #[test]
    fn zero_function_cannot_be_sampled() {
        let d = Bilinear2D::new(vec![0.0; 9], GridAxis::Even(2), GridAxis::Even(2));
        assert_eq!(d.sample(Vec2::splat(0.5)), None);
        assert_eq!(d.pdf(Vec2::splat(0.5)), 0.0);
    }
}
