//! A goniometric profile placed in the world: the shape of an emitter's intensity over
//! directions, as an IES file measures it.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::math::Frame;
use crate::photometry::GoniometricTable;

/// A [`GoniometricTable`] in a world frame: the table's nadir (+z) along `frame.n`, its C0
/// plane (+x) along `frame.s`, C90 along `frame.t`. Lights use it through the *relative*
/// intensity I(ω)/I_max ∈ [0, 1], so that the light's own amount sets the scale.
#[derive(Clone, Debug)]
pub struct LightProfile {
    pub table: Arc<GoniometricTable>,
    pub frame: Frame,
    inv_max: f32,
    /// ∫ I(ω)/I_max dω over the sphere (sr).
    solid_angle: f32,
}

impl LightProfile {
    /// A profile with its nadir along `nadir` and its C0 plane towards `c0` (the part of
    /// `c0` orthogonal to `nadir`; any orthogonal direction if `c0` is parallel to it).
    /// `None` for a dark table or a zero `nadir`.
    pub fn new(table: Arc<GoniometricTable>, nadir: Vec3, c0: Vec3) -> Option<LightProfile> {
        let n = nadir.normalize_or_zero();
        let max = table.max_intensity();
        if n == Vec3::ZERO || max <= 0.0 || !max.is_finite() {
            return None;
        }
        let s = (c0 - n * c0.dot(n)).normalize_or_zero();
        let s = if s == Vec3::ZERO {
            Frame::from_z(n).s
        } else {
            s
        };
        let frame = Frame {
            s,
            t: n.cross(s),
            n,
        };
        let solid_angle = (table.total_flux() / max as f64) as f32;
        Some(LightProfile {
            table,
            frame,
            inv_max: 1.0 / max,
            solid_angle,
        })
    }

    /// I(ω)/I_max towards the unit world direction `w`.
    pub fn relative(&self, w: Vec3) -> f32 {
        self.table.intensity(self.frame.to_local(w)) * self.inv_max
    }

    /// The peak of the table (cd, as the file states it).
    pub fn max_intensity(&self) -> f32 {
        1.0 / self.inv_max
    }

    /// ∫ I(ω)/I_max dω over the sphere: the solid angle that turns a peak intensity into
    /// a power, Φ = I_peak · Ω.
    pub fn solid_angle(&self) -> f32 {
        self.solid_angle
    }

    /// ∫ I(ω)/I_max · max(0, cos θ) dω over the hemisphere around the nadir, by a midpoint
    /// rule on a 256 × 512 grid in (cos θ, φ): the projected solid angle that gives an
    /// IES-shaped area light its power, Φ = A · L · this.
    pub fn projected_solid_angle(&self) -> f32 {
        const NT: usize = 256;
        const NP: usize = 512;
        let mut sum = 0.0f64;
        for i in 0..NT {
            let z = (i as f32 + 0.5) / NT as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            for j in 0..NP {
                let phi = 2.0 * PI * (j as f32 + 0.5) / NP as f32;
                let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                sum += (self.table.intensity(d) * self.inv_max * z) as f64;
            }
        }
        (sum * 2.0 * std::f64::consts::PI / (NT * NP) as f64) as f32
    }

    /// A world direction drawn by the table's emission sampling, and its solid-angle
    /// density.
    pub fn sample(&self, u: Vec2) -> (Vec3, f32) {
        let (d, pdf) = self.table.sample(u);
        (self.frame.to_world(d), pdf)
    }

    /// Density of [`Self::sample`] for the unit world direction `w`.
    pub fn pdf(&self, w: Vec3) -> f32 {
        self.table.pdf(self.frame.to_local(w))
    }
}
