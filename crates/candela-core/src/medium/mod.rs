//! Participating media in the null-scattering formulation (Novák et al. 2014; Miller,
//! Georgiev and Jarosz 2019), as pbrt-v4 and Mitsuba 3 render them: a medium gives, at each
//! point, absorption σa and scattering σs (RGB, per scene unit) and, along a ray, a
//! majorant σ_maj ≥ σa + σs. Collisions are sampled at the majorant's rate (delta
//! tracking); the fictitious "null" part σn = σ_maj − σa − σs leaves the path unchanged.
//!
//! - [`homogeneous`]: constant coefficients, majorant = σt, so no null collisions; its
//!   transmittance has a closed form.
//! - [`grid`]: a trilinearly interpolated 3D grid of σt (times a scale) and an albedo,
//!   with a majorant per cell of a coarse grid ([`majorant`]).
//! - [`phase`]: isotropic and Henyey–Greenstein phase functions.
//! - [`tracking`]: the collision sampler shared by the camera path and shadow rays.
//!
//! Chromatic σt is handled by a hero channel: each camera path draws one of the three
//! channels and samples distances by its coefficients; the other channels' densities are
//! carried as ratios and combined by the balance heuristic over channels (pbrt-v4's
//! "spectral MIS", here over RGB), so every channel stays unbiased. The integrator is
//! `crate::integrator::volpath`.

pub mod grid;
pub mod homogeneous;
pub mod majorant;
pub mod phase;
pub mod tracking;

use glam::Vec3;

pub use grid::{GridMedium, VoxelGrid};
pub use homogeneous::Homogeneous;
pub use majorant::{MajorantGrid, MajorantWalk};
pub use phase::HenyeyGreenstein;

use crate::geometry::Ray;
use crate::material::MaterialId;

/// Index of a medium in [`SceneMedia::media`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MediumId(pub u32);

/// The coefficients at a point of a medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MediumProperties {
    pub sigma_a: Vec3,
    pub sigma_s: Vec3,
}

/// A stretch `[t0, t1]` of a ray with a constant majorant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MajorantSegment {
    pub t0: f32,
    pub t1: f32,
    pub sigma_maj: Vec3,
}

/// The stretches of constant majorant along a ray, in order and end to end.
#[derive(Clone, Debug)]
pub enum Majorants<'a> {
    /// At most one stretch (a homogeneous medium, or a grid's single majorant).
    One(Option<MajorantSegment>),
    /// A grid's cells along the ray.
    Walk(MajorantWalk<'a>),
}

impl Iterator for Majorants<'_> {
    type Item = MajorantSegment;

    #[inline]
    fn next(&mut self) -> Option<MajorantSegment> {
        match self {
            Majorants::One(s) => s.take(),
            Majorants::Walk(w) => w.next(),
        }
    }
}

/// A participating medium.
#[derive(Clone, Debug)]
pub enum Medium {
    Homogeneous(Homogeneous),
    Grid(GridMedium),
}

impl Medium {
    /// The coefficients at `p`.
    #[inline]
    pub fn properties(&self, p: Vec3) -> MediumProperties {
        match self {
            Medium::Homogeneous(m) => m.properties(),
            Medium::Grid(m) => m.properties(p),
        }
    }

    /// The stretches of `ray` within `(0, t_max)` where the medium may be non-empty, in
    /// order, each with a majorant; none where the ray misses it.
    #[inline]
    pub fn majorants(&self, ray: &Ray, t_max: f32) -> Majorants<'_> {
        match self {
            Medium::Homogeneous(m) => Majorants::One(Some(MajorantSegment {
                t0: 0.0,
                t1: t_max,
                sigma_maj: m.sigma_t(),
            })),
            Medium::Grid(m) => m.majorants(ray, t_max),
        }
    }

    pub fn phase(&self) -> HenyeyGreenstein {
        match self {
            Medium::Homogeneous(m) => m.phase,
            Medium::Grid(m) => m.phase,
        }
    }

    /// Whether the medium has a closed-form transmittance (then shadow rays use it, not
    /// ratio tracking).
    #[inline]
    pub fn is_homogeneous(&self) -> bool {
        matches!(self, Medium::Homogeneous(_))
    }
}

/// e^(−σ·d) per channel, with a zero coefficient transmitting fully over any distance
/// (so an unbounded ray through a partly clear medium is not NaN).
#[inline]
pub fn transmittance(sigma: Vec3, d: f32) -> Vec3 {
    let one = |s: f32| if s == 0.0 { 1.0 } else { (-s * d).exp() };
    Vec3::new(one(sigma.x), one(sigma.y), one(sigma.z))
}

/// The media on either side of a surface: `interior` against its geometric normal,
/// `exterior` on the normal's side; `None` is vacuum.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MediumInterface {
    pub interior: Option<MediumId>,
    pub exterior: Option<MediumId>,
}

impl MediumInterface {
    /// The medium a ray leaving the surface (geometric normal `ng`) along `d` enters.
    #[inline]
    pub fn target(&self, ng: Vec3, d: Vec3) -> Option<MediumId> {
        if d.dot(ng) < 0.0 {
            self.interior
        } else {
            self.exterior
        }
    }
}

/// How a material takes part in volumetric rendering.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SurfaceMedia {
    /// A null surface: no BSDF, rays pass straight through (a medium's boundary only).
    pub null: bool,
    /// Where set, crossing the surface changes the current medium; where not, the ray keeps
    /// the medium it is in.
    pub interface: Option<MediumInterface>,
}

/// Everything the volumetric integrator needs beside the surfaces. A scene has it only
/// when it has media or null surfaces; without it the plain path tracer renders.
#[derive(Clone, Debug, Default)]
pub struct SceneMedia {
    pub media: Vec<Medium>,
    /// Indexed by [`MaterialId`]; materials past the end are plain surfaces.
    pub surfaces: Vec<SurfaceMedia>,
    /// The medium the camera sits in (a scene-wide fog when no shape bounds it).
    pub camera: Option<MediumId>,
}

impl SceneMedia {
    /// How material `m` bounds media.
    #[inline]
    pub fn surface(&self, m: MaterialId) -> SurfaceMedia {
        self.surfaces.get(m.0 as usize).copied().unwrap_or_default()
    }

    #[inline]
    pub fn medium(&self, id: MediumId) -> &Medium {
        &self.media[id.0 as usize]
    }
}
