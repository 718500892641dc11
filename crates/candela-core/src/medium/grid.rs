//! A heterogeneous medium on a voxel grid: σt = scale × a trilinearly interpolated grid,
//! σs = albedo × σt with the albedo constant or on a grid of its own, inside the unit cube
//! of the grid's local space (placed in the world by a transform), empty outside. Its
//! majorants are those of a coarse grid over the cube ([`MajorantGrid`]).

use glam::{Affine3A, Vec3};

use super::majorant::{MajorantGrid, MAJORANT_CELLS};
use super::{HenyeyGreenstein, Majorants, MediumProperties};
use crate::geometry::Ray;

/// Values on a 3D grid of `res` cells (x fastest, then y, then z), one or three channels
/// per cell, looked up trilinearly between cell centres with the edges clamped (the
/// convention of Mitsuba 3's `gridvolume` and of GPU textures).
#[derive(Clone, Debug, PartialEq)]
pub struct VoxelGrid {
    pub res: [u32; 3],
    /// 1 (grey) or 3 (RGB).
    pub channels: u32,
    pub data: Vec<f32>,
}

impl VoxelGrid {
    /// A grid, checking that `data` holds `res` cells of `channels` values.
    pub fn new(res: [u32; 3], channels: u32, data: Vec<f32>) -> Result<VoxelGrid, String> {
        let cells = res.iter().map(|&r| r as u64).product::<u64>();
        if cells == 0 {
            return Err(format!("grid resolution {res:?} is empty"));
        }
        if channels != 1 && channels != 3 {
            return Err(format!("a grid has 1 or 3 channels, not {channels}"));
        }
        if data.len() as u64 != cells * channels as u64 {
            return Err(format!(
                "grid {res:?} × {channels} needs {} values, has {}",
                cells * channels as u64,
                data.len()
            ));
        }
        if let Some(v) = data.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(format!("grid value {v} is not finite and non-negative"));
        }
        Ok(VoxelGrid {
            res,
            channels,
            data,
        })
    }

    /// The value of voxel (x, y, z), in range.
    #[inline]
    pub fn cell(&self, x: u32, y: u32, z: u32) -> Vec3 {
        let [nx, ny, _] = self.res;
        let i = ((z * ny + y) * nx + x) as usize;
        if self.channels == 1 {
            Vec3::splat(self.data[i])
        } else {
            Vec3::from_slice(&self.data[3 * i..3 * i + 3])
        }
    }

    /// The trilinear value at local point `p` ∈ [0, 1]³ (clamped at the edges).
    #[inline]
    pub fn lookup(&self, p: Vec3) -> Vec3 {
        let res = Vec3::new(self.res[0] as f32, self.res[1] as f32, self.res[2] as f32);
        let q = (p * res - 0.5).clamp(Vec3::ZERO, res - 1.0);
        let i = q.floor().min(res - 1.0);
        let f = q - i;
        let [x0, y0, z0] = [i.x as u32, i.y as u32, i.z as u32];
        let [x1, y1, z1] = [
            (x0 + 1).min(self.res[0] - 1),
            (y0 + 1).min(self.res[1] - 1),
            (z0 + 1).min(self.res[2] - 1),
        ];
        let lerp = |a: Vec3, b: Vec3, t: f32| a + (b - a) * t;
        let c00 = lerp(self.cell(x0, y0, z0), self.cell(x1, y0, z0), f.x);
        let c10 = lerp(self.cell(x0, y1, z0), self.cell(x1, y1, z0), f.x);
        let c01 = lerp(self.cell(x0, y0, z1), self.cell(x1, y0, z1), f.x);
        let c11 = lerp(self.cell(x0, y1, z1), self.cell(x1, y1, z1), f.x);
        lerp(lerp(c00, c10, f.y), lerp(c01, c11, f.y), f.z)
    }

    /// The largest value per channel: a bound of every trilinear lookup.
    pub fn max(&self) -> Vec3 {
        let mut m = Vec3::ZERO;
        for c in self.data.chunks_exact(self.channels as usize) {
            m = m.max(if self.channels == 1 {
                Vec3::splat(c[0])
            } else {
                Vec3::from_slice(c)
            });
        }
        m
    }
}

/// The single-scattering albedo of a grid medium.
#[derive(Clone, Debug, PartialEq)]
pub enum Albedo {
    Constant(Vec3),
    Grid(VoxelGrid),
}

/// A heterogeneous medium: σt(p) = `scale` × `sigma_t`(p), σs = albedo(p) × σt, inside the
/// unit cube of the local space that `world_to_local` maps to.
#[derive(Clone, Debug)]
pub struct GridMedium {
    pub sigma_t: VoxelGrid,
    pub albedo: Albedo,
    pub scale: f32,
    pub world_to_local: Affine3A,
    pub phase: HenyeyGreenstein,
    /// Bounds of σt over the cells of a coarse grid.
    majorants: MajorantGrid,
}

impl GridMedium {
    /// The medium, with majorants on a grid of up to [`MAJORANT_CELLS`]³ cells.
    pub fn new(
        sigma_t: VoxelGrid,
        albedo: Albedo,
        scale: f32,
        world_to_local: Affine3A,
        phase: HenyeyGreenstein,
    ) -> GridMedium {
        let majorants = MajorantGrid::new(&sigma_t, scale, [MAJORANT_CELLS; 3]);
        GridMedium {
            sigma_t,
            albedo,
            scale,
            world_to_local,
            phase,
            majorants,
        }
    }

    /// The same medium with majorants on `cells` cells per axis (each at most the grid's
    /// resolution): `[1, 1, 1]` gives the grid's maximum everywhere, which tests compare
    /// the coarse grid against.
    pub fn with_majorant_cells(mut self, cells: [u32; 3]) -> GridMedium {
        self.majorants = MajorantGrid::new(&self.sigma_t, self.scale, cells);
        self
    }

    /// The coefficients at world point `p` (zero outside the cube).
    #[inline]
    pub fn properties(&self, p: Vec3) -> MediumProperties {
        let q = self.world_to_local.transform_point3(p);
        if q.min_element() < 0.0 || q.max_element() > 1.0 {
            return MediumProperties {
                sigma_a: Vec3::ZERO,
                sigma_s: Vec3::ZERO,
            };
        }
        let sigma_t = self.sigma_t.lookup(q) * self.scale;
        let albedo = match &self.albedo {
            Albedo::Constant(a) => *a,
            Albedo::Grid(g) => g.lookup(q),
        }
        .clamp(Vec3::ZERO, Vec3::ONE);
        let sigma_s = sigma_t * albedo;
        MediumProperties {
            sigma_a: sigma_t - sigma_s,
            sigma_s,
        }
    }

    /// The stretch of the ray inside the cube, clipped to (0, t_max), cell by cell of the
    /// majorant grid.
    #[inline]
    pub fn majorants(&self, ray: &Ray, t_max: f32) -> Majorants<'_> {
        // An affine map keeps the ray's parameter: t in local space is t in the world.
        let o = self.world_to_local.transform_point3(ray.o);
        let d = self.world_to_local.transform_vector3(ray.d);
        let inv = d.recip();
        let a = (Vec3::ZERO - o) * inv;
        let b = (Vec3::ONE - o) * inv;
        let (lo, hi) = (a.min(b), a.max(b));
        // NaN (a zero direction component with the origin on a face) falls back to the
        // other axes through max/min.
        let t0 = lo.max_element().max(0.0);
        let t1 = hi.min_element().min(t_max);
        if t0 < t1 {
            Majorants::Walk(self.majorants.walk(o, d, t0, t1))
        } else {
            Majorants::One(None)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_is_exact_at_cell_centres_and_linear_between() {
        let g = VoxelGrid::new([2, 1, 1], 1, vec![1.0, 3.0]).unwrap();
        assert_eq!(g.lookup(Vec3::new(0.25, 0.5, 0.5)), Vec3::splat(1.0));
        assert_eq!(g.lookup(Vec3::new(0.75, 0.5, 0.5)), Vec3::splat(3.0));
        assert_eq!(g.lookup(Vec3::new(0.5, 0.5, 0.5)), Vec3::splat(2.0));
        // Clamped beyond the outer centres.
        assert_eq!(g.lookup(Vec3::new(0.0, 0.0, 1.0)), Vec3::splat(1.0));
        assert_eq!(g.max(), Vec3::splat(3.0));
    }

    #[test]
    fn bad_grids_are_refused() {
        assert!(VoxelGrid::new([2, 2, 2], 1, vec![0.0; 7]).is_err());
        assert!(VoxelGrid::new([0, 2, 2], 1, vec![]).is_err());
        assert!(VoxelGrid::new([1, 1, 1], 2, vec![0.0; 2]).is_err());
        assert!(VoxelGrid::new([1, 1, 1], 1, vec![f32::NAN]).is_err());
    }

    #[test]
    fn the_majorant_segment_is_the_ray_inside_the_placed_cube() {
        // The cube [−1, 1]³ in the world: local = (world + 1) / 2.
        let to_local =
            Affine3A::from_scale(Vec3::splat(0.5)) * Affine3A::from_translation(Vec3::ONE);
        let g = VoxelGrid::new([1, 1, 1], 1, vec![2.0]).unwrap();
        let m = GridMedium::new(
            g,
            Albedo::Constant(Vec3::ONE),
            3.0,
            to_local,
            HenyeyGreenstein::ISOTROPIC,
        );
        let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
        let s: Vec<_> = m.majorants(&ray, 100.0).collect();
        assert_eq!(s.len(), 1);
        assert!((s[0].t0 - 4.0).abs() < 1e-5 && (s[0].t1 - 6.0).abs() < 1e-5);
        assert_eq!(s[0].sigma_maj, Vec3::splat(6.0));
        assert!(m.majorants(&ray, 3.0).next().is_none());
        assert!(m
            .majorants(&Ray::new(Vec3::new(-5.0, 2.0, 0.0), Vec3::X), 100.0)
            .next()
            .is_none());
        assert_eq!(
            m.properties(Vec3::new(0.5, 0.5, 0.5)).sigma_s,
            Vec3::splat(6.0)
        );
        assert_eq!(m.properties(Vec3::new(1.5, 0.0, 0.0)).sigma_s, Vec3::ZERO);
    }
}
