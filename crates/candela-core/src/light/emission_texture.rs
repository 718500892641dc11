//! The texture of a textured area light's triangle, and where on the triangle its light
//! is: a piecewise-constant density over a grid of sub-triangles, so that next event
//! estimation draws points where the texture is bright.
//!
//! The grid cuts the triangle into k² equal sub-triangles (k rows of the barycentric
//! lattice, each row a strip of upright and inverted cells). Each cell's weight is the
//! texture's mean there, estimated at build; a point is drawn by picking a cell by its
//! weight and then a point uniformly in the cell. Unlike sampling the texture's image in
//! uv and mapping the point back onto the surface, this needs nothing of the uv mapping:
//! uvs that repeat a tile, mirror it or overlap are sampled as correctly as a one-to-one
//! unwrap, because every density is defined on the triangle itself.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::math::luminance;
use crate::sampling::{sample_uniform_triangle, Distribution1D};
use crate::texture::Texture;

/// Cells a side of a triangle's grid, at most: 1 024 cells, 8 KiB of density a triangle.
/// A triangle that covers more than 256 texels has cells larger than a quarter texel.
const MAX_CELLS_PER_SIDE: u32 = 32;

/// Lookups a side of a cell, at most (64 a cell): four lookups a texel for triangles of
/// up to 16 384 texels; beyond that they are spread thinner.
const MAX_LOOKUPS_PER_SIDE: u32 = 8;

/// The squared coefficient of variation of a triangle's cell weights below which its
/// points are drawn uniformly: a texture that varies so little over the triangle gains
/// less than the cells' lookups cost.
const MIN_SPREAD: f32 = 1.0 / 16.0;

/// The share of a triangle's samples spread over it uniformly by area, whatever the
/// texture: a defensive mixture. A cell whose lookups all missed its few bright texels
/// still gets at least a tenth of the uniform density, so that its samples weigh at most
/// ten times what uniform sampling would give them instead of without bound; it costs at
/// most a tenth of the samples on dark cells.
const DEFENSIVE: f32 = 0.1;

/// The texture of a textured area light's triangle, its corners' uvs, its mean over the
/// triangle, and where on the triangle its points are sampled.
#[derive(Clone, Debug)]
pub struct EmissionTexture {
    pub texture: Arc<Texture>,
    pub uv: [Vec2; 3],
    /// The texture's mean over the triangle's area, estimated at build (see
    /// [`EmissionTexture::new`]): what light selection sees in place of the texture.
    pub mean: Vec3,
    /// The density of sampled points over the triangle's cells, or `None` where it is
    /// uniform (a grid of one cell, or a texture that varies little over the triangle, see
    /// [`MIN_SPREAD`]).
    cells: Option<Arc<Cells>>,
}

/// A piecewise-constant density over the k² cells of a triangle, relative to the uniform
/// density 1/area: its values average to one over the cells.
#[derive(Debug)]
struct Cells {
    k: u32,
    density: Distribution1D,
}

impl EmissionTexture {
    /// The texture on the triangle with corner uvs `uv`, emitting `tint` times the
    /// texture. The triangle's grid has k cells a side, 1 to 32, k² four times the
    /// texels (or checker quarters, see [`Texture::detail`]) it covers; each cell has
    /// 2² to 8² lookups at the centroids of its own finer grid, at least four a texel.
    /// The mean is the lookups' average, kept at least 10⁻³ of `floor` (the texture's
    /// [`Texture::mean`]) so that no triangle with light in it becomes unselectable
    /// because its lookups all fell on black. Cells are weighed by the luminance of
    /// `tint` × halfway between their mean and largest lookup, mixed with a tenth of
    /// uniform (see `DEFENSIVE`); where they vary little, points are drawn uniformly
    /// (see `MIN_SPREAD`).
    pub fn new(texture: Arc<Texture>, uv: [Vec2; 3], tint: Vec3, floor: Vec3) -> EmissionTexture {
        let uv_area = 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
        // Two cells a texel a side, as far as the grid goes; two lookups a cell a side,
        // or as many as keep two a texel a side.
        let side = 2.0 * (uv_area * texture.detail()).sqrt();
        let k = side.ceil().clamp(1.0, MAX_CELLS_PER_SIDE as f32) as u32;
        let m = (side / k as f32)
            .ceil()
            .clamp(2.0, MAX_LOOKUPS_PER_SIDE as f32) as u32;
        let at = |st: Vec2| uv[0] * (1.0 - st.x - st.y) + uv[1] * st.x + uv[2] * st.y;
        // Each cell's mean and largest lookup, at the centroids of its own m-a-side grid.
        let lookups: Vec<(Vec3, Vec3)> = (0..k * k)
            .map(|c| {
                (0..m * m)
                    .map(|q| {
                        let xy = cell_point(m, q, Vec2::splat(1.0 / 3.0));
                        texture.eval(at(cell_point(k, c, xy)))
                    })
                    .fold((Vec3::ZERO, Vec3::ZERO), |(sum, max), v| {
                        (sum + v, max.max(v))
                    })
            })
            .map(|(sum, max)| (sum / (m * m) as f32, max))
            .collect();
        let count = (k * k) as f32;
        let mean = lookups.iter().map(|(mean, _)| *mean).sum::<Vec3>() / count;
        // Halfway between the mean and the largest lookup: a cell's few bright texels
        // between the lookups are better overrated (a few samples too many there) than
        // missed (samples that weigh up to ten times uniform's).
        let weights: Vec<f32> = lookups
            .iter()
            .map(|(mean, max)| luminance(tint * (*mean + *max)) * 0.5)
            .collect();
        let mean_weight = weights.iter().sum::<f32>() / count;
        // Drawing points by the cells costs ≈ 25–30 ns a sample; it is worth it where uniform
        // sampling's relative variance of the emission, the weights' squared coefficient
        // of variation, is at least 1/16.
        let spread = weights
            .iter()
            .map(|w| (w / mean_weight - 1.0).powi(2))
            .sum::<f32>()
            / count;
        let cells =
            (mean_weight > 0.0 && mean_weight.is_finite() && spread >= MIN_SPREAD).then(|| {
                let func: Vec<f32> = weights
                    .iter()
                    .map(|w| (1.0 - DEFENSIVE) * w / mean_weight + DEFENSIVE)
                    .collect();
                Arc::new(Cells {
                    k,
                    density: Distribution1D::new(&func),
                })
            });
        EmissionTexture {
            texture,
            uv,
            mean: mean.max(floor * 1e-3),
            cells,
        }
    }

    /// The texture at barycentrics `b` (weights of the three corners).
    #[inline]
    pub(super) fn at(&self, b: Vec3) -> Vec3 {
        self.texture
            .eval(self.uv[0] * b.x + self.uv[1] * b.y + self.uv[2] * b.z)
    }

    /// A point of the triangle from `u`, as barycentrics, and its density relative to
    /// the uniform density 1/area.
    #[inline]
    pub(super) fn sample(&self, u: Vec2) -> (Vec3, f32) {
        let Some(cells) = &self.cells else {
            return (sample_uniform_triangle(u), 1.0);
        };
        let (c, du) = cells.density.sample_cell(u.x);
        let local = sample_uniform_triangle(Vec2::new(du, u.y));
        let st = cell_point(cells.k, c as u32, Vec2::new(local.y, local.z));
        let b = Vec3::new((1.0 - st.x - st.y).max(0.0), st.x, st.y);
        (b, cells.density.cell_pdf(c))
    }

    /// The density of [`Self::sample`] relative to uniform at the point whose
    /// barycentrics of corners 1 and 2 are `b1`, `b2`.
    #[inline]
    pub(super) fn density(&self, b1: f32, b2: f32) -> f32 {
        match &self.cells {
            None => 1.0,
            Some(cells) => cells.density.cell_pdf(cell_of(cells.k, Vec2::new(b1, b2))),
        }
    }
}

/// The point of cell `c` of a k-a-side grid at `xy` in the cell's own unit triangle
/// (x, y ≥ 0, x + y ≤ 1), as (s, t): the barycentrics of the triangle's corners 1 and 2.
///
/// The cells are numbered row by row, a row being the strip k·s ∈ [i, i + 1): row i holds
/// k − i upright cells (corners (i, j), (i + 1, j), (i, j + 1), over k) and k − i − 1
/// inverted ones between them, numbered 2j and 2j + 1 from the row's first number
/// k² − (k − i)².
fn cell_point(k: u32, c: u32, xy: Vec2) -> Vec2 {
    let (i, j, inverted) = cell_coords(k, c);
    let corner = Vec2::new(i as f32, j as f32);
    let local = if inverted { Vec2::ONE - xy } else { xy };
    (corner + local) / k as f32
}

/// Row, position in the row and orientation of cell `c` (see [`cell_point`]).
fn cell_coords(k: u32, c: u32) -> (u32, u32, bool) {
    // The row is the i for which k² − (k − i)² ≤ c < k² − (k − i − 1)²: k − i is the
    // ceiling of √(k² − c).
    let left = k * k - c;
    let mut r = (left as f32).sqrt() as u32;
    if r * r < left {
        r += 1;
    }
    let i = k - r;
    let within = c - (k * k - r * r);
    (i, within / 2, within % 2 == 1)
}

/// The cell of a k-a-side grid that holds the point (s, t) (see [`cell_point`]); points
/// on or past an edge go to the nearest cell.
fn cell_of(k: u32, st: Vec2) -> usize {
    let (a, b) = (st.x.max(0.0) * k as f32, st.y.max(0.0) * k as f32);
    let i = (a as u32).min(k - 1);
    let j = (b as u32).min(k - 1 - i);
    let inverted = (a - i as f32) + (b - j as f32) >= 1.0 && i + j + 2 <= k;
    (k * k - (k - i) * (k - i) + 2 * j + inverted as u32) as usize
}

#[cfg(test)]
pub(super) mod tests {
    use glam::Affine2;

    use super::*;
    use crate::chi2::ChiSquareTest;
    use crate::sampler::Pcg32;

    /// A grey checker of `a` and `b`, `scale` squares a unit of uv.
    pub(in crate::light) fn checker(a: f32, b: f32, scale: f32) -> Arc<Texture> {
        Arc::new(Texture::Checker {
            a: Vec3::splat(a),
            b: Vec3::splat(b),
            uv_transform: Affine2::from_scale(Vec2::splat(scale)),
        })
    }

    /// Every cell's points lie in that cell and nowhere else, for grids of 1 to 12 a
    /// side: the numbering and the point lookup invert each other, and the cells tile
    /// the triangle (their points stay inside it).
    #[test]
    fn each_cell_holds_its_own_points() {
        let mut rng = Pcg32::new(9, 1);
        for k in 1..=12 {
            for c in 0..k * k {
                let (i, j, inverted) = cell_coords(k, c);
                assert!(i < k && j + i < k, "k {k}, cell {c}: ({i}, {j})");
                assert!(!inverted || i + j + 2 <= k, "k {k}, cell {c}");
                for _ in 0..20 {
                    let b = sample_uniform_triangle(Vec2::new(
                        rng.uniform_f32() * 0.98 + 0.01,
                        rng.uniform_f32() * 0.98 + 0.01,
                    ));
                    // Keep off the cell's edges, where either cell may answer.
                    let xy = Vec2::new(b.y, b.z) * 0.96 + Vec2::splat(0.02);
                    let st = cell_point(k, c, xy);
                    assert!(st.min_element() >= 0.0 && st.x + st.y <= 1.0, "{st}");
                    assert_eq!(cell_of(k, st), c as usize, "k {k}, point {st}");
                }
            }
        }
    }

    /// The triangle uv (0, 0), (1, 0), (0, 1) over a checker of thirds holds 2.5 cells of
    /// `a` (the three on its diagonal are half inside) and 2 of `b`: mean (2.5a + 2b)/4.5.
    /// The estimate takes 2² lookups in each of 9² cells (the centroids of an 18-a-side
    /// grid), so it is only close; 5 % is what those points miss of the squares cut by
    /// the diagonal.
    #[test]
    fn the_mean_of_an_emission_texture_weighs_its_area() {
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let t = EmissionTexture::new(checker(4.0, 1.0, 3.0), uv, Vec3::ONE, Vec3::ZERO);
        let exact = (2.5 * 4.0 + 2.0 * 1.0) / 4.5;
        assert!(
            (t.mean.x / exact - 1.0).abs() < 0.05,
            "{} vs {exact}",
            t.mean.x
        );
        // Inside one square of `b`: exactly `b`, whatever the number of lookups, and
        // sampled uniformly.
        let small = [
            Vec2::new(0.4, 0.1),
            Vec2::new(0.5, 0.1),
            Vec2::new(0.4, 0.2),
        ];
        let t = EmissionTexture::new(checker(4.0, 1.0, 3.0), small, Vec3::ONE, Vec3::ZERO);
        assert_eq!(t.mean, Vec3::ONE);
        assert!(t.cells.is_none());
        // All black: the floor keeps it selectable.
        let t = EmissionTexture::new(checker(0.0, 0.0, 3.0), uv, Vec3::ONE, Vec3::splat(2.0));
        assert_eq!(t.mean, Vec3::splat(2e-3));
        assert!(t.cells.is_none());
    }

    /// The density over the cells is the defensive mix of the cells' weights: relative
    /// densities average to one, bright cells get (0.9 · w/w̄ + 0.1), and black ones
    /// exactly the tenth. A red tint weighs the cells by the red channel's luminance.
    #[test]
    fn cells_are_weighed_by_their_tinted_luminance() {
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let t = EmissionTexture::new(
            checker(1.0, 0.0, 4.0),
            uv,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::ZERO,
        );
        let cells = t.cells.as_ref().expect("a checker varies");
        let n = cells.k * cells.k;
        let densities: Vec<f32> = (0..n as usize).map(|c| cells.density.cell_pdf(c)).collect();
        let average = densities.iter().sum::<f32>() / n as f32;
        assert!((average - 1.0).abs() < 1e-5, "{average}");
        let low = densities.iter().cloned().fold(f32::INFINITY, f32::min);
        assert!((low - DEFENSIVE).abs() < 1e-6, "{low}");
        // A bright cell's weight is the tint's luminance, the mean weight the tint's
        // luminance times the mean (a grey checker's channels are equal).
        let high = densities.iter().cloned().fold(0.0, f32::max);
        let want = (1.0 - DEFENSIVE) / t.mean.x + DEFENSIVE;
        assert!((high / want - 1.0).abs() < 1e-4, "{high} vs {want}");
    }

    /// Points are drawn with the density the cells claim: a chi-square test (10⁶
    /// samples, α = 0.01, the defaults) of the sampled (s, t) over [0, 1]² against
    /// 2 · ρ(s, t) (2 is the uniform density of the unit triangle), on a checker of
    /// quarters whose squares the 12-a-side grid cuts in three. Each sample's reported density is
    /// the one its point's cell gives, but for points on a cell's edge, where the two
    /// sides may round either way (allowed: 10⁻⁴ of the samples).
    #[test]
    fn points_are_drawn_by_the_cells_density() {
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let t = EmissionTexture::new(checker(8.0, 0.5, 4.0), uv, Vec3::ONE, Vec3::ZERO);
        assert_eq!(t.cells.as_ref().map(|c| c.k), Some(12));
        let mut mismatches = 0;
        ChiSquareTest::default()
            .planar(
                "emission texture cells",
                Vec2::ZERO,
                Vec2::ONE,
                |u| {
                    let (b, density) = t.sample(u);
                    assert!((b.element_sum() - 1.0).abs() < 1e-5 && b.min_element() >= 0.0);
                    mismatches += (t.density(b.y, b.z) != density) as usize;
                    Some(Vec2::new(b.y, b.z))
                },
                |st| {
                    if st.x + st.y <= 1.0 {
                        2.0 * t.density(st.x, st.y)
                    } else {
                        0.0
                    }
                },
            )
            .assert_passed();
        assert!(mismatches <= 100, "{mismatches} samples' densities differ");
    }
}
