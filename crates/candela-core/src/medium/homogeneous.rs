//! A homogeneous medium: the same σa and σs everywhere.

use glam::Vec3;

use super::{HenyeyGreenstein, MediumProperties};

/// Constant absorption and scattering coefficients (per scene unit, RGB) and a phase
/// function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homogeneous {
    pub sigma_a: Vec3,
    pub sigma_s: Vec3,
    pub phase: HenyeyGreenstein,
}

impl Homogeneous {
    /// The medium of extinction `sigma_t` and single-scattering `albedo` (σs = albedo·σt),
    /// Mitsuba's parameterization.
    pub fn from_albedo(sigma_t: Vec3, albedo: Vec3, phase: HenyeyGreenstein) -> Homogeneous {
        let sigma_s = sigma_t * albedo;
        Homogeneous {
            sigma_a: (sigma_t - sigma_s).max(Vec3::ZERO),
            sigma_s,
            phase,
        }
    }

    #[inline]
    pub fn sigma_t(&self) -> Vec3 {
        self.sigma_a + self.sigma_s
    }

    #[inline]
    pub fn properties(&self) -> MediumProperties {
        MediumProperties {
            sigma_a: self.sigma_a,
            sigma_s: self.sigma_s,
        }
    }
}
