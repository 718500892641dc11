//! Bidirectional scattering distribution functions.
//!
//! # Conventions (once, for every BSDF in this module)
//!
//! - Lobes work in the local shading frame: the shading normal is +z, so
//!   `cos θ = w.z`.
//! - `wo` (towards the viewer / previous vertex) and `wi` (towards the light / next
//!   vertex) both point **away** from the surface and are unit vectors.
//! - `f(wo, wi)` is the BSDF value alone, **without** the cosine factor |cos θᵢ|; the
//!   integrator multiplies by it.
//! - `pdf` is in **solid angle** measure over `wi`. Delta lobes (perfect mirrors and
//!   refraction) return `pdf = 0` and `f = 0` from `f`/`pdf`; their `sample` returns the
//!   lobe's weight in `f` with `pdf = 1` and the [`BsdfFlags::DELTA`] flag, so that MIS
//!   never weights them.
//! - `sample(wo, u_lobe, u_dir)` returns `f`, `wi`, `pdf` such that `f · |cos θᵢ| / pdf`
//!   is the sample's weight.

mod diffuse;

pub use diffuse::Diffuse;

use glam::{Vec2, Vec3};

use crate::math::Frame;

/// What kind of scattering a sampled direction came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct BsdfFlags(u8);

impl BsdfFlags {
    pub const REFLECTION: BsdfFlags = BsdfFlags(1);
    pub const TRANSMISSION: BsdfFlags = BsdfFlags(2);
    pub const DIFFUSE: BsdfFlags = BsdfFlags(4);
    pub const GLOSSY: BsdfFlags = BsdfFlags(8);
    pub const DELTA: BsdfFlags = BsdfFlags(16);

    pub const fn union(self, o: BsdfFlags) -> BsdfFlags {
        BsdfFlags(self.0 | o.0)
    }

    pub const fn contains(self, o: BsdfFlags) -> bool {
        self.0 & o.0 == o.0
    }

    pub const fn is_delta(self) -> bool {
        self.contains(BsdfFlags::DELTA)
    }
}

/// A sampled scattering direction.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// BSDF value (no cosine), or the delta lobe's weight.
    pub f: Vec3,
    pub wi: Vec3,
    /// Solid-angle density of `wi` (1 for delta lobes).
    pub pdf: f32,
    pub flags: BsdfFlags,
}

/// The scattering lobes Candela knows, in the local shading frame.
#[derive(Clone, Copy, Debug)]
pub enum Lobe {
    Diffuse(Diffuse),
}

impl Lobe {
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            Lobe::Diffuse(l) => l.f(wo, wi),
        }
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Lobe::Diffuse(l) => l.pdf(wo, wi),
        }
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        match self {
            Lobe::Diffuse(l) => l.sample(wo, u_lobe, u),
        }
    }

    /// Whether every component is a delta (then NEE is pointless).
    pub fn is_delta(&self) -> bool {
        match self {
            Lobe::Diffuse(_) => false,
        }
    }
}

/// A lobe placed in the world by its shading frame. Takes and returns world directions.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    pub frame: Frame,
    /// Geometric normal, to reject light leaks where shading and geometric normals
    /// disagree.
    pub ng: Vec3,
    pub lobe: Lobe,
    /// Black when `wo` is below the shading frame (imported one-sided BSDFs).
    pub one_sided: bool,
}

impl Bsdf {
    pub fn new(ns: Vec3, ng: Vec3, lobe: Lobe) -> Bsdf {
        Bsdf {
            frame: Frame::from_z(ns),
            ng,
            lobe,
            one_sided: false,
        }
    }

    /// Whether `wo` (local) sees nothing: grazing, or the back of a one-sided BSDF.
    fn blind(&self, lo: Vec3) -> bool {
        lo.z == 0.0 || (self.one_sided && lo.z < 0.0)
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
        if self.blind(lo) {
            return Vec3::ZERO;
        }
        self.lobe.f(lo, li)
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
        if self.blind(lo) {
            return 0.0;
        }
        self.lobe.pdf(lo, li)
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let lo = self.frame.to_local(wo);
        if self.blind(lo) {
            return None;
        }
        let s = self.lobe.sample(lo, u_lobe, u)?;
        if s.pdf == 0.0 || !s.pdf.is_finite() || s.wi.z == 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi: self.frame.to_world(s.wi),
            ..s
        })
    }

    pub fn is_delta(&self) -> bool {
        self.lobe.is_delta()
    }

    /// |cos θ| of `wi` against the shading normal.
    pub fn abs_cos(&self, wi: Vec3) -> f32 {
        wi.dot(self.frame.n).abs()
    }
}
