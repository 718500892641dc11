//! A density on the unit square proportional to a function known at the vertices of a
//! grid and interpolated bilinearly between them, sampled exactly: the density of
//! Mitsuba 3's continuous `Marginal2D` (`distr_2d.h`), with rows that need not be evenly
//! spaced, drawn in two discrete steps and one continuous one.
//!
//! A grid cell's share of ∫ f is its area times the mean of its four corners (f is
//! bilinear within it). So the row of cells is drawn in proportion to the row's mass, the
//! cell within that row in proportion to its own mass (each by a guide table over the
//! discrete CDF, [`Distribution1D::sample_cell`]: a lookup and on average under two steps),
//! and the point within the cell with the bilinear density through its corners
//! ([`sample_bilinear`]). The product of the three is f / ∫ f everywhere, the same density
//! as inverting the continuous marginal and conditional CDFs, for a fraction of the work:
//! no blended CDFs, no second lookup. Every step is monotone (y in u.y, x in u.x within a
//! row), so stratified numbers stay stratified.

use glam::Vec2;

use crate::sampling::{cell_index, sample_bilinear, Distribution1D, ONE_MINUS_EPSILON};

/// `n` as an `f32`: the value of `n as f32`, for the grid sizes here (below 2³²), by way
/// of `u32`, whose conversion on x86-64 is one instruction where `usize`'s tests the sign
/// bit and branches.
#[inline(always)]
fn size_f32(n: usize) -> f32 {
    debug_assert!(u32::try_from(n).is_ok());
    n as u32 as f32
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
    /// The rows of cells, by each row's share of ∫ f.
    rows: Distribution1D,
    /// Per row of cells, its cells by their shares of the row's mass.
    cells: Vec<Distribution1D>,
    /// [`GridAxis::position`] of every vertex of each axis, looked up by the sampling
    /// rather than computed (a match on the axis, a conversion and a division each).
    x_positions: Vec<f32>,
    y_positions: Vec<f32>,
    integral: f32,
}

impl Bilinear2D {
    /// A density proportional to the bilinear interpolation of `values` (row-major,
    /// `x_axis.vertices()` a row, `y_axis.vertices()` rows; negative values count as 0).
    pub fn new(values: Vec<f32>, x_axis: GridAxis, y_axis: GridAxis) -> Bilinear2D {
        let (stride, rows) = (x_axis.vertices(), y_axis.vertices());
        assert_eq!(values.len(), stride * rows, "one value per vertex");
        let values: Vec<f32> = values.into_iter().map(|v| v.max(0.0)).collect();
        // Each cell's mass: its area times the mean of its corners.
        let (columns, cell_rows) = (stride - 1, rows - 1);
        let mut cell_mass = Vec::with_capacity(columns * cell_rows);
        for j in 0..cell_rows {
            let height = (y_axis.position(j + 1) - y_axis.position(j)) as f64;
            for k in 0..columns {
                let width = (x_axis.position(k + 1) - x_axis.position(k)) as f64;
                let i = j * stride + k;
                let corners = [i, i + 1, i + stride, i + stride + 1]
                    .map(|i| values[i] as f64)
                    .iter()
                    .sum::<f64>();
                cell_mass.push(0.25 * corners * width * height);
            }
        }
        let row_mass: Vec<f64> = cell_mass
            .chunks_exact(columns)
            .map(|row| row.iter().sum())
            .collect();
        let positions = |axis: GridAxis| (0..axis.vertices()).map(|k| axis.position(k)).collect();
        Bilinear2D {
            x_axis,
            y_axis,
            stride,
            values,
            rows: Distribution1D::new(&row_mass.iter().map(|&m| m as f32).collect::<Vec<_>>()),
            cells: cell_mass
                .chunks_exact(columns)
                .map(|row| Distribution1D::new(&row.iter().map(|&m| m as f32).collect::<Vec<_>>()))
                .collect(),
            x_positions: positions(x_axis),
            y_positions: positions(y_axis),
            integral: row_mass.iter().sum::<f64>() as f32,
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

    /// A cell drawn with probability ∝ its share of ∫ f, as (column k, row j), and two
    /// numbers uniform on [0, 1)² left for placing the point within it; `None` when f is
    /// zero everywhere. Always inlined: out of line, its result went back through memory.
    #[inline(always)]
    pub fn sample_cell(&self, u: Vec2) -> Option<(usize, usize, Vec2)> {
        if self.integral <= 0.0 {
            return None;
        }
        let (j, rest_y) = self.rows.sample_cell(u.y);
        let (k, rest_x) = self.cells[j].sample_cell(u.x);
        Some((k, j, Vec2::new(rest_x, rest_y)))
    }

    /// The point at (`st.x`, `st.y`) within the cell of column `k`, row `j`, in [0, 1)².
    #[inline]
    pub fn cell_point(&self, k: usize, j: usize, st: Vec2) -> Vec2 {
        let (x0, x1) = (self.x_positions[k], self.x_positions[k + 1]);
        let (y0, y1) = (self.y_positions[j], self.y_positions[j + 1]);
        Vec2::new(
            (x0 + st.x * (x1 - x0)).min(ONE_MINUS_EPSILON),
            (y0 + st.y * (y1 - y0)).min(ONE_MINUS_EPSILON),
        )
    }

    /// A point of [0, 1)² drawn with density ∝ f, and that density; `None` when f is
    /// zero everywhere.
    pub fn sample(&self, u: Vec2) -> Option<(Vec2, f32)> {
        let (k, j, rest) = self.sample_cell(u)?;
        let i = j * self.stride + k;
        let v = &self.values;
        let st = sample_bilinear(
            rest,
            [v[i], v[i + 1], v[i + self.stride], v[i + self.stride + 1]],
        );
        let f = self.value_in_cell(k, st.x, j, st.y);
        (f > 0.0).then(|| (self.cell_point(k, j, st), f / self.integral))
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

    #[test]
    fn cells_are_drawn_in_proportion_to_their_mass() {
        // A 9 × 7 grid with zeros, a spike and uneven rows: the tables' probability of
        // each cell (row times cell within the row) is the cell's exact mass over ∫ f.
        let (xa, ya) = (GridAxis::Even(8), GridAxis::Centred(5));
        let values: Vec<f32> = (0..xa.vertices() * ya.vertices())
            .map(|i| [0.0, 1.0, 4.0, 0.5, 0.0, 2.5, 9.0, 300.0][i * 5 % 8])
            .collect();
        let d = Bilinear2D::new(values.clone(), xa, ya);
        let stride = xa.vertices();
        let mut total = 0.0;
        for j in 0..ya.vertices() - 1 {
            for k in 0..stride - 1 {
                let i = j * stride + k;
                let mean = (values[i] + values[i + 1] + values[i + stride] + values[i + stride + 1])
                    as f64
                    / 4.0;
                let area = ((xa.position(k + 1) - xa.position(k))
                    * (ya.position(j + 1) - ya.position(j))) as f64;
                let exact = mean * area / d.integral() as f64;
                let (rows, cells) = (d.rows.len() as f64, d.cells[j].len() as f64);
                let table =
                    d.rows.cell_pdf(j) as f64 / rows * d.cells[j].cell_pdf(k) as f64 / cells;
                assert!(
                    (table - exact).abs() < 1e-6,
                    "cell ({k}, {j}): {table} vs {exact}"
                );
                total += table;
            }
        }
        assert!((total - 1.0).abs() < 1e-6);
    }

    #[test]
    fn zero_function_cannot_be_sampled() {
        let d = Bilinear2D::new(vec![0.0; 9], GridAxis::Even(2), GridAxis::Even(2));
        assert_eq!(d.sample(Vec2::splat(0.5)), None);
        assert_eq!(d.pdf(Vec2::splat(0.5)), 0.0);
    }
}
