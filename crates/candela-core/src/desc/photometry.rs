//! Goniometric tables: luminous intensity (candela) over the whole sphere of directions,
//! as measured photometric files (IES LM-63) give it, in one canonical form that a light
//! can evaluate and sample.
//!
//! **Table frame.** Directions are in the table's own frame: the nadir (vertical angle
//! θ = 0) is local **+z**, the C0 plane (horizontal angle φ = 0) contains local **+x**
//! and the C90 plane local **+y**, so `dir = (sin θ cos φ, sin θ sin φ, cos θ)`. A light
//! that uses a table rotates +z onto its aim direction.
//!
//! **Canonical form.** The photometric file's angles are expanded to the full 0–360°
//! horizontal range by their symmetry ([`HorizontalSymmetry`]) and resampled once onto a
//! regular (θ, φ) grid of knots. The grid step is the coarsest step of at most 1° on which
//! every measured angle lies (so 5° or 2.5° data becomes a 1° or 0.5° grid and the table
//! reproduces the file's piecewise-bilinear interpolation exactly); files with angles off
//! any such grid fall back to 0.25° in θ and 0.5° in φ. Rotationally symmetric profiles
//! keep a single φ column. Outside the file's vertical range the intensity is 0 (it fades
//! to 0 over one grid step). Between knots the table interpolates bilinearly in (θ, φ),
//! which never overshoots: a value lies between the smallest and the largest of its four
//! knots.
//!
//! **Sampling.** Emission directions are drawn proportionally to a piecewise-constant
//! bound of the intensity: each grid cell weighs the largest of its four knots times its
//! solid angle, like an environment map's marginal (θ rows) and conditional (φ cells)
//! distributions (Pharr, Jakob, Humphreys, *PBRT* 4th ed., §12.5.2). Inside a cell the
//! direction is uniform in solid angle, so the density is constant per cell and positive
//! wherever the interpolated intensity is.

use std::f64::consts::PI;
use std::fmt;

use glam::{Vec2, Vec3};

use crate::sampling::Distribution1D;

/// A table that cannot be built from the given angles and values.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PhotometryError(pub String);

impl fmt::Display for PhotometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PhotometryError {}

/// How the measured horizontal (C-plane) angles cover the full 0–360° range, as LM-63
/// type C photometry encodes it in the first and last horizontal angle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HorizontalSymmetry {
    /// One horizontal angle: the same in every plane.
    Rotational,
    /// 0–90°: symmetric about both the C0–C180 and the C90–C270 planes.
    Quadrant,
    /// 0–180°: symmetric about the C0–C180 plane, I(φ) = I(360° − φ).
    BilateralC0,
    /// 90–270°: symmetric about the C90–C270 plane, I(φ) = I(180° − φ).
    BilateralC90,
    /// 0° up to more than 180° (usually 360°): no symmetry; the last plane wraps to 0°.
    None,
}

impl HorizontalSymmetry {
    /// The symmetry LM-63 implies for increasing horizontal angles (degrees).
    pub fn classify(horizontal_deg: &[f64]) -> Result<HorizontalSymmetry, PhotometryError> {
        let (Some(&first), Some(&last)) = (horizontal_deg.first(), horizontal_deg.last()) else {
            return Err(PhotometryError("no horizontal angles".into()));
        };
        let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
        Ok(match horizontal_deg.len() {
            1 => HorizontalSymmetry::Rotational,
            _ if near(first, 0.0) && near(last, 90.0) => HorizontalSymmetry::Quadrant,
            _ if near(first, 0.0) && near(last, 180.0) => HorizontalSymmetry::BilateralC0,
            _ if near(first, 90.0) && near(last, 270.0) => HorizontalSymmetry::BilateralC90,
            _ if near(first, 0.0) && last > 180.0 && last <= 360.0 + 1e-6 => {
                HorizontalSymmetry::None
            }
            _ => {
                return Err(PhotometryError(format!(
                    "horizontal angles {first}–{last}° are not one of the LM-63 ranges \
                     (a single angle, 0–90, 0–180, 90–270 or 0–360)"
                )))
            }
        })
    }
}

/// Luminous intensity over the sphere on a regular (θ, φ) grid, with emission sampling.
/// See the module documentation for the frame and the interpolation.
#[derive(Clone, Debug)]
pub struct GoniometricTable {
    n_theta: usize,
    n_phi: usize,
    /// Knots (n_theta + 1) × n_phi, row-major in θ; φ wraps around.
    values: Vec<f32>,
    max_value: f32,
    marginal: Distribution1D,
    conditional: Vec<Distribution1D>,
    /// Solid-angle density of each cell, n_theta × n_phi.
    cell_pdf: Vec<f32>,
}

impl GoniometricTable {
    /// A table from LM-63 type C data: increasing vertical angles (θ from nadir, degrees,
    /// within 0–180), increasing horizontal angles (φ, degrees, one of the ranges of
    /// [`HorizontalSymmetry`]) and `candela[h * vertical.len() + v]`, non-negative.
    pub fn new(
        vertical_deg: &[f64],
        horizontal_deg: &[f64],
        candela: &[f64],
    ) -> Result<GoniometricTable, PhotometryError> {
        let (nv, nh) = (vertical_deg.len(), horizontal_deg.len());
        if nv < 2 {
            return Err(PhotometryError("needs at least two vertical angles".into()));
        }
        if candela.len() != nv * nh {
            return Err(PhotometryError(format!(
                "{} candela values for {nv} × {nh} angles",
                candela.len()
            )));
        }
        check_increasing("vertical", vertical_deg, 0.0, 180.0)?;
        check_increasing("horizontal", horizontal_deg, 0.0, 360.0)?;
        if let Some(c) = candela.iter().find(|c| !c.is_finite() || **c < 0.0) {
            return Err(PhotometryError(format!("candela value {c} is not >= 0")));
        }
        let symmetry = HorizontalSymmetry::classify(horizontal_deg)?;
        let columns: Vec<&[f64]> = candela.chunks(nv).collect();
        // Identical planes (e.g. only 0° and 360°) are rotational symmetry in disguise.
        let rotational = columns.iter().all(|c| *c == columns[0]);
        let n_theta = grid_cells(vertical_deg, 180.0, 180, 720);
        let n_phi = if rotational {
            1
        } else {
            grid_cells(horizontal_deg, 360.0, 360, 720)
        };
        // For each φ knot: the two measured planes around it and the weight of the second.
        let phi_weights: Vec<(usize, usize, f64)> = (0..n_phi)
            .map(|j| {
                if rotational {
                    (0, 0, 0.0)
                } else {
                    plane_weights(horizontal_deg, symmetry, 360.0 * j as f64 / n_phi as f64)
                }
            })
            .collect();
        let mut values = Vec::with_capacity((n_theta + 1) * n_phi);
        for i in 0..=n_theta {
            let theta = 180.0 * i as f64 / n_theta as f64;
            let at_theta: Vec<f64> = columns
                .iter()
                .map(|c| interpolate_vertical(vertical_deg, c, theta))
                .collect();
            for &(h0, h1, t) in &phi_weights {
                values.push(((1.0 - t) * at_theta[h0] + t * at_theta[h1]) as f32);
            }
        }
        Ok(GoniometricTable::from_grid(n_theta, n_phi, values))
    }

    /// A table from its knots: `values` holds (n_theta + 1) rows of n_phi knots, row i at
    /// θ = 180° i / n_theta, knot j at φ = 360° j / n_phi.
    pub fn from_grid(n_theta: usize, n_phi: usize, values: Vec<f32>) -> GoniometricTable {
        assert!(n_theta >= 1 && n_phi >= 1 && values.len() == (n_theta + 1) * n_phi);
        let max_value = values.iter().fold(0.0f32, |m, &v| m.max(v));
        let d_phi = 2.0 * PI / n_phi as f64;
        let mut cell_max = Vec::with_capacity(n_theta * n_phi);
        let mut row_weight = Vec::with_capacity(n_theta);
        let mut total = 0.0f64;
        for i in 0..n_theta {
            let (c0, c1) = (theta_of(i, n_theta).cos(), theta_of(i + 1, n_theta).cos());
            let omega = (c0 - c1) * d_phi;
            let mut row = 0.0f64;
            for j in 0..n_phi {
                let j1 = (j + 1) % n_phi;
                let at = |r: usize, c: usize| values[r * n_phi + c];
                let m = at(i, j).max(at(i, j1)).max(at(i + 1, j)).max(at(i + 1, j1));
                cell_max.push(m);
                row += m as f64 * omega;
            }
            row_weight.push(row as f32);
            total += row;
        }
        let conditional = cell_max.chunks(n_phi).map(Distribution1D::new).collect();
        let cell_pdf = cell_max
            .iter()
            .map(|&m| {
                if total > 0.0 {
                    (m as f64 / total) as f32
                } else {
                    0.0
                }
            })
            .collect();
        GoniometricTable {
            n_theta,
            n_phi,
            values,
            max_value,
            marginal: Distribution1D::new(&row_weight),
            conditional,
            cell_pdf,
        }
    }

    /// Grid cells in θ (over 0–180°) and in φ (over 0–360°).
    pub fn resolution(&self) -> (usize, usize) {
        (self.n_theta, self.n_phi)
    }

    /// Luminous intensity (cd) towards the unit direction `dir` of the table frame.
    pub fn intensity(&self, dir: Vec3) -> f32 {
        let (theta, phi) = angles_of(dir);
        let u = theta / PI * self.n_theta as f64;
        let i = (u as usize).min(self.n_theta - 1);
        let s = (u - i as f64).clamp(0.0, 1.0) as f32;
        let v = phi / (2.0 * PI) * self.n_phi as f64;
        let j = (v as usize).min(self.n_phi - 1);
        let t = (v - j as f64).clamp(0.0, 1.0) as f32;
        let j1 = (j + 1) % self.n_phi;
        let at = |r: usize, c: usize| self.values[r * self.n_phi + c];
        let lo = (1.0 - t) * at(i, j) + t * at(i, j1);
        let hi = (1.0 - t) * at(i + 1, j) + t * at(i + 1, j1);
        (1.0 - s) * lo + s * hi
    }

    /// The largest intensity anywhere (cd); bilinear interpolation peaks at a knot.
    pub fn max_intensity(&self) -> f32 {
        self.max_value
    }

    /// Luminous flux (lm): ∫ I dω over the sphere, integrated exactly for the bilinear
    /// interpolant (the θ integral of a linear function times sin θ in closed form).
    pub fn total_flux(&self) -> f64 {
        let d_phi = 2.0 * PI / self.n_phi as f64;
        let mut flux = 0.0;
        for i in 0..self.n_theta {
            let (t0, t1) = (theta_of(i, self.n_theta), theta_of(i + 1, self.n_theta));
            // ∫ sin θ dθ and ∫ θ sin θ dθ over the cell; weights of the two knot rows.
            let a = t0.cos() - t1.cos();
            let b = (t1.sin() - t1 * t1.cos()) - (t0.sin() - t0 * t0.cos());
            let w1 = (b - t0 * a) / (t1 - t0);
            let w0 = a - w1;
            for j in 0..self.n_phi {
                let lo = self.values[i * self.n_phi + j] as f64;
                let hi = self.values[(i + 1) * self.n_phi + j] as f64;
                flux += d_phi * (w0 * lo + w1 * hi);
            }
        }
        flux
    }

    /// Beam angle (degrees): the full angle, within a vertical plane through the nadir,
    /// between the two directions either side of the plane's peak where the intensity has
    /// fallen to 50% of that peak (the IES/CIE definition), averaged over the C0–C180 and
    /// the C90–C270 planes. 360 where it never falls that low.
    pub fn beam_angle(&self) -> f64 {
        0.5 * (self.beam_angle_in_plane(0.0) + self.beam_angle_in_plane(90.0))
    }

    /// Beam angle (degrees) in the plane C`c_deg`–C`c_deg + 180`.
    pub fn beam_angle_in_plane(&self, c_deg: f64) -> f64 {
        // Signed angle s in (-180°, 180°]: θ = |s| on the C`c` side for s ≥ 0, else on
        // the opposite half-plane.
        const STEPS: i64 = 3600;
        let at = |k: i64| self.intensity(plane_dir(c_deg, 180.0 * k as f64 / STEPS as f64)) as f64;
        let samples: Vec<f64> = (-STEPS..=STEPS).map(at).collect();
        let (peak_k, peak) =
            samples.iter().enumerate().fold(
                (0, 0.0),
                |(bk, bv), (k, &v)| if v > bv { (k, v) } else { (bk, bv) },
            );
        if peak <= 0.0 {
            return 0.0;
        }
        let half = 0.5 * peak;
        let deg = |k: f64| 180.0 * k / STEPS as f64;
        let crossing = |dir: i64| -> Option<f64> {
            let mut k = peak_k as i64;
            loop {
                let next = k + dir;
                if !(0..=2 * STEPS).contains(&next) {
                    return None;
                }
                let (a, b) = (samples[k as usize], samples[next as usize]);
                if b <= half {
                    let t = (a - half) / (a - b);
                    return Some(deg(k as f64 + dir as f64 * t - STEPS as f64));
                }
                k = next;
            }
        };
        match (crossing(1), crossing(-1)) {
            (Some(hi), Some(lo)) => (hi - lo).min(360.0),
            _ => 360.0,
        }
    }

    /// A direction drawn with density proportional to the cell-wise bound of the
    /// intensity, and its solid-angle density. The density is 0 only for a dark table.
    pub fn sample(&self, u: Vec2) -> (Vec3, f32) {
        let (x, _, i) = self.marginal.sample_continuous(u.x);
        let t = (x as f64 * self.n_theta as f64 - i as f64).clamp(0.0, 1.0);
        let (c0, c1) = (
            theta_of(i, self.n_theta).cos(),
            theta_of(i + 1, self.n_theta).cos(),
        );
        let cos_theta = (c0 + t * (c1 - c0)).clamp(-1.0, 1.0);
        let (y, _, j) = self.conditional[i].sample_continuous(u.y);
        let phi = 2.0 * PI * y as f64;
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let dir = Vec3::new(
            (sin_theta * phi.cos()) as f32,
            (sin_theta * phi.sin()) as f32,
            cos_theta as f32,
        );
        (dir, self.cell_pdf[i * self.n_phi + j])
    }

    /// Solid-angle density with which [`Self::sample`] picks the unit direction `dir`.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let (theta, phi) = angles_of(dir);
        let i = ((theta / PI * self.n_theta as f64) as usize).min(self.n_theta - 1);
        let j = ((phi / (2.0 * PI) * self.n_phi as f64) as usize).min(self.n_phi - 1);
        self.cell_pdf[i * self.n_phi + j]
    }
}

/// θ of knot row `i` (radians).
fn theta_of(i: usize, n_theta: usize) -> f64 {
    PI * i as f64 / n_theta as f64
}

/// (θ, φ) in radians of a unit direction in the table frame, φ in [0, 2π).
fn angles_of(dir: Vec3) -> (f64, f64) {
    let d = dir.as_dvec3();
    let theta = d.z.clamp(-1.0, 1.0).acos();
    let mut phi = d.y.atan2(d.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    (theta, phi.min(2.0 * PI))
}

/// The unit direction at signed angle `s_deg` from the nadir in plane C`c_deg`.
pub fn plane_dir(c_deg: f64, s_deg: f64) -> Vec3 {
    let (c, s) = (c_deg.to_radians(), s_deg.to_radians());
    Vec3::new(
        (s.sin() * c.cos()) as f32,
        (s.sin() * c.sin()) as f32,
        s.cos() as f32,
    )
}

fn check_increasing(what: &str, angles: &[f64], lo: f64, hi: f64) -> Result<(), PhotometryError> {
    if let Some(a) = angles.iter().find(|a| !(lo..=hi).contains(*a)) {
        return Err(PhotometryError(format!(
            "{what} angle {a} is outside {lo}–{hi}°"
        )));
    }
    if let Some(w) = angles.windows(2).find(|w| w[1] <= w[0]) {
        return Err(PhotometryError(format!(
            "{what} angles are not increasing: {} after {}",
            w[1], w[0]
        )));
    }
    Ok(())
}

/// Grid cells over `range` degrees: the smallest multiple of `base` (1° steps) up to `max`
/// that puts every angle on a knot, else `max`.
fn grid_cells(angles: &[f64], range: f64, base: usize, max: usize) -> usize {
    (base..=max)
        .step_by(base)
        .find(|&n| {
            let step = range / n as f64;
            angles
                .iter()
                .all(|a| ((a / step) - (a / step).round()).abs() < 1e-4)
        })
        .unwrap_or(max)
}

/// Piecewise-linear intensity at vertical angle `theta` (degrees); 0 outside the range.
fn interpolate_vertical(vertical: &[f64], column: &[f64], theta: f64) -> f64 {
    let (first, last) = (vertical[0], vertical[vertical.len() - 1]);
    if theta < first - 1e-9 || theta > last + 1e-9 {
        return 0.0;
    }
    let k = vertical
        .partition_point(|&a| a < theta)
        .clamp(1, vertical.len() - 1);
    let (a0, a1) = (vertical[k - 1], vertical[k]);
    let t = ((theta - a0) / (a1 - a0)).clamp(0.0, 1.0);
    (1.0 - t) * column[k - 1] + t * column[k]
}

/// The measured planes around the horizontal angle `phi` (degrees, 0–360) and the weight
/// of the second: `phi` is folded by the symmetry into the measured range, where the
/// intensity is linear between planes. Folding, rather than mirroring the planes over the
/// circle, keeps the data's interpolation across a mirror plane the file did not measure
/// (e.g. 180° of a 90–270° file in 20° steps, where I(0°) = I(180°) lies halfway between
/// the 170° and 190° planes).
fn plane_weights(
    horizontal: &[f64],
    symmetry: HorizontalSymmetry,
    phi: f64,
) -> (usize, usize, f64) {
    let n = horizontal.len();
    let a = match symmetry {
        HorizontalSymmetry::Rotational => return (0, 0, 0.0),
        HorizontalSymmetry::Quadrant => match phi {
            p if p <= 90.0 => p,
            p if p <= 180.0 => 180.0 - p,
            p if p <= 270.0 => p - 180.0,
            p => 360.0 - p,
        },
        HorizontalSymmetry::BilateralC0 => phi.min(360.0 - phi),
        // I(φ) = I(180° − φ), taken into 90–270°.
        HorizontalSymmetry::BilateralC90 => match phi {
            p if p < 90.0 => 180.0 - p,
            p if p > 270.0 => 540.0 - p,
            p => p,
        },
        HorizontalSymmetry::None => {
            let last = horizontal[n - 1];
            if phi > last {
                // Past the last plane the circle closes on the first (0° = 360°).
                let t = if last < 360.0 {
                    (phi - last) / (360.0 - last)
                } else {
                    0.0
                };
                return (n - 1, 0, t.clamp(0.0, 1.0));
            }
            phi
        }
    };
    let k = horizontal.partition_point(|&h| h < a).clamp(1, n - 1);
    let (h0, h1) = (horizontal[k - 1], horizontal[k]);
    (k - 1, k, ((a - h0) / (h1 - h0)).clamp(0.0, 1.0))
}
