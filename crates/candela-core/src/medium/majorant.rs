//! A coarse grid of majorants over a voxel grid, and the ray's walk through its cells
//! (pbrt-v4's `MajorantGrid` and `DDAMajorantIterator`, PBR 4th ed. §11.4.3).
//!
//! One majorant for a whole grid makes delta and ratio tracking take a step at the
//! densest voxel's rate everywhere: in sparse smoke most of them are null collisions
//! through nearly empty space. Each cell of the coarse grid (16³ at most) instead holds the
//! largest value any trilinear lookup inside it can take, and a ray crosses the cells
//! one by one with a 3D DDA (Amanatides and Woo 1987), each stretch with its own majorant.

use glam::Vec3;

use super::grid::VoxelGrid;
use super::MajorantSegment;

/// Cells per axis of the coarse grid, at most (as pbrt-v4's grid media).
pub const MAJORANT_CELLS: u32 = 16;

/// Per-cell bounds of a grid's trilinear values over the unit cube of its local space.
#[derive(Clone, Debug, PartialEq)]
pub struct MajorantGrid {
    /// Cells per axis.
    pub res: [u32; 3],
    /// The bound of each cell (x fastest, then y, then z), per channel.
    cells: Vec<Vec3>,
}

impl MajorantGrid {
    /// The bounds of `grid` × `scale` on `cells` cells per axis (each at most the grid's
    /// own resolution on that axis, and at least 1).
    pub fn new(grid: &VoxelGrid, scale: f32, cells: [u32; 3]) -> MajorantGrid {
        let res: [u32; 3] = std::array::from_fn(|a| cells[a].clamp(1, grid.res[a]));
        // The voxels a trilinear lookup in local [lo, hi] reads on one axis: those of the
        // cell centres around lo·n − ½ … hi·n − ½ (see `VoxelGrid::lookup`), widened by a
        // thousandth of a voxel for points that rounding puts just past a cell's face.
        let span = |a: usize, c: u32| {
            let n = grid.res[a] as f32;
            let (lo, hi) = (c as f32 / res[a] as f32, (c + 1) as f32 / res[a] as f32);
            let first = (lo * n - 0.5 - 1e-3).floor().max(0.0) as u32;
            let last = ((hi * n - 0.5 + 1e-3).floor() + 1.0).clamp(0.0, n - 1.0) as u32;
            first.min(grid.res[a] - 1)..=last
        };
        let mut out = Vec::with_capacity((res[0] * res[1] * res[2]) as usize);
        for z in 0..res[2] {
            for y in 0..res[1] {
                for x in 0..res[0] {
                    let mut m = Vec3::ZERO;
                    for k in span(2, z) {
                        for j in span(1, y) {
                            for i in span(0, x) {
                                m = m.max(grid.cell(i, j, k));
                            }
                        }
                    }
                    out.push(m * scale);
                }
            }
        }
        MajorantGrid { res, cells: out }
    }

    #[inline]
    fn at(&self, v: [u32; 3]) -> Vec3 {
        self.cells[((v[2] * self.res[1] + v[1]) * self.res[0] + v[0]) as usize]
    }

    /// The cells along a ray of local origin `o` and direction `d` between its parameters
    /// `t0 < t1`, where the ray is inside the unit cube.
    #[inline]
    pub fn walk(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> MajorantWalk<'_> {
        let p = o + d * t0;
        let mut voxel = [0u32; 3];
        let mut next = [f32::INFINITY; 3];
        let mut delta = [f32::INFINITY; 3];
        let mut step = [0i32; 3];
        for a in 0..3 {
            let n = self.res[a] as f32;
            let v = (p[a] * n).floor().clamp(0.0, n - 1.0);
            voxel[a] = v as u32;
            if d[a] > 0.0 {
                next[a] = t0 + ((v + 1.0) / n - p[a]) / d[a];
                delta[a] = 1.0 / (d[a] * n);
                step[a] = 1;
            } else if d[a] < 0.0 {
                next[a] = t0 + (v / n - p[a]) / d[a];
                delta[a] = -1.0 / (d[a] * n);
                step[a] = -1;
            }
        }
        MajorantWalk {
            grid: self,
            t: t0,
            t_end: t1,
            voxel,
            next,
            delta,
            step,
        }
    }
}

/// The stretches of a ray through the cells of a [`MajorantGrid`], in order.
#[derive(Clone, Debug)]
pub struct MajorantWalk<'a> {
    grid: &'a MajorantGrid,
    /// Where the next stretch starts.
    t: f32,
    t_end: f32,
    voxel: [u32; 3],
    /// The parameter at which the ray crosses into the next cell along each axis.
    next: [f32; 3],
    /// The parameter the ray takes to cross one cell along each axis.
    delta: [f32; 3],
    step: [i32; 3],
}

impl Iterator for MajorantWalk<'_> {
    type Item = MajorantSegment;

    #[inline]
    fn next(&mut self) -> Option<MajorantSegment> {
        if self.t >= self.t_end {
            return None;
        }
        let n = self.next;
        let axis = if n[0] < n[1] {
            if n[0] < n[2] {
                0
            } else {
                2
            }
        } else if n[1] < n[2] {
            1
        } else {
            2
        };
        // The last cell runs to the end of the ray's stretch in the cube, also where
        // rounding has the walk leave the grid a little before it.
        let v = self.voxel[axis] as i32 + self.step[axis];
        let last = n[axis] >= self.t_end || v < 0 || v >= self.grid.res[axis] as i32;
        let exit = if last {
            self.t_end
        } else {
            n[axis].max(self.t)
        };
        let seg = MajorantSegment {
            t0: self.t,
            t1: exit,
            sigma_maj: self.grid.at(self.voxel),
        };
        self.t = exit;
        if !last {
            self.voxel[axis] = v as u32;
            self.next[axis] += self.delta[axis];
        }
        Some(seg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Pcg32;

    fn hashed_grid(res: [u32; 3]) -> VoxelGrid {
        let n = (res[0] * res[1] * res[2]) as u64;
        let data = (0..n)
            .map(|i| (crate::sampler::mix64(i ^ 77) >> 40) as f32 / (1u64 << 24) as f32)
            .map(|v| v.powi(4) * 5.0)
            .collect();
        VoxelGrid::new(res, 1, data).unwrap()
    }

    /// Every trilinear value bounded by its cell's majorant, at random points and at
    /// points on and just past the cells' faces.
    #[test]
    fn each_cell_bounds_every_lookup_inside_it() {
        let grid = hashed_grid([24, 7, 31]);
        let m = MajorantGrid::new(&grid, 2.0, [MAJORANT_CELLS; 3]);
        assert_eq!(m.res, [16, 7, 16]);
        let mut rng = Pcg32::new(3, 5);
        for i in 0..200_000 {
            let mut p = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
            if i % 2 == 0 {
                // Onto a cell face of one axis, give or take rounding.
                let a = i / 2 % 3;
                let n = m.res[a] as f32;
                let face = (p[a] * n).round() / n;
                p[a] = (face + (rng.uniform_f32() - 0.5) * 1e-6).clamp(0.0, 1.0);
            }
            let v: [u32; 3] =
                std::array::from_fn(|a| ((p[a] * m.res[a] as f32) as u32).min(m.res[a] - 1));
            let value = grid.lookup(p) * 2.0;
            assert!(
                value.cmple(m.at(v) * (1.0 + 1e-6)).all(),
                "{value} above the majorant {} of cell {v:?} at {p}",
                m.at(v)
            );
        }
    }

    /// The walk's stretches tile [t0, t1] without gaps, each in the cell that holds its
    /// midpoint; rays along and across the axes, from inside and outside the cube.
    #[test]
    fn the_walk_tiles_the_ray_cell_by_cell() {
        let grid = hashed_grid([20, 20, 20]);
        let m = MajorantGrid::new(&grid, 1.0, [10, 5, 20]);
        let mut rng = Pcg32::new(9, 1);
        let mut rays: Vec<(Vec3, Vec3)> = vec![
            (Vec3::new(-0.5, 0.25, 0.5), Vec3::X),
            (Vec3::new(0.3, 1.5, 0.7), -Vec3::Y),
            (Vec3::new(0.5, 0.5, 0.5), Vec3::new(0.0, 0.0, -1.0)),
            (
                Vec3::new(0.1, 0.2, 0.0),
                Vec3::new(1.0, 1.0, 1.0).normalize(),
            ),
        ];
        for _ in 0..2000 {
            let o = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 3.0 - 1.0;
            let d = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) - 0.5;
            rays.push((o, d.normalize()));
        }
        let mut segments = 0;
        for (o, d) in rays {
            let inv = d.recip();
            let (a, b) = ((Vec3::ZERO - o) * inv, (Vec3::ONE - o) * inv);
            let t0 = a.min(b).max_element().max(0.0);
            let t1 = a.max(b).min_element();
            if t0 >= t1 || t0.is_nan() || t1.is_nan() {
                continue;
            }
            let mut t = t0;
            for s in m.walk(o, d, t0, t1) {
                assert_eq!(s.t0, t, "a gap before the stretch");
                assert!(s.t1 >= s.t0);
                let mid = o + d * (0.5 * (s.t0 + s.t1));
                let v: [u32; 3] = std::array::from_fn(|k| {
                    ((mid[k] * m.res[k] as f32).max(0.0) as u32).min(m.res[k] - 1)
                });
                if s.t1 - s.t0 > 1e-4 {
                    assert_eq!(s.sigma_maj, m.at(v), "stretch {s:?} of {o} + t {d}");
                }
                t = s.t1;
                segments += 1;
            }
            assert_eq!(t, t1, "the walk stops short of the cube's far side");
        }
        assert!(segments > 2000, "{segments} stretches");
    }
}
