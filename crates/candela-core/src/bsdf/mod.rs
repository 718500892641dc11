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
//!   refraction) return `pdf = 0` and `f = 0` from `f`/`pdf`; their `sample` returns
//!   `pdf = 1` and the [`BsdfFlags::DELTA`] flag, so that MIS never weights them.
//! - `sample(wo, u_lobe, u_dir)` returns `f`, `wi`, `pdf` such that `f · |cos θᵢ| / pdf`
//!   is the sample's weight. For a delta sample `f` is that weight divided by |cos θᵢ|.
//! - Reflection-only lobes are two-sided: seen from below (`wo.z < 0`) they behave as seen
//!   from above, mirrored (so [`BsdfDesc::TwoSided`](crate::desc::BsdfDesc::TwoSided) only
//!   records intent, e.g. from an imported scene). Reflection means `wo.z·wi.z > 0`.
//! - Transmission: a dielectric's `eta` is η_inside/η_outside, the outside being the side
//!   the shading normal points to. Transmitted radiance is scaled by 1/η'² (η' = η_t/η_i
//!   of the crossing), because Candela traces camera paths only (Veach 1997, §5.2); a thin
//!   sheet has no net refraction and no scaling.
//! - Light leaks: [`Bsdf`] decides between reflection and transmission with the
//!   **geometric** normal. A pair of directions that is a reflection for the shading
//!   normal but a transmission for the geometric one (or the other way round) gets f = 0,
//!   pdf = 0, and such sampled directions are rejected (pbrt-v3 §9.1's rule), so light
//!   never leaks through a surface because its shading normal is bent.

mod conductor;
mod dielectric;
mod diffuse;
pub mod fresnel;
mod metal_rough;
pub mod microfacet;
mod plastic;

pub use conductor::{Conductor, ConductorFresnel};
pub use dielectric::{Dielectric, ThinDielectric};
pub use diffuse::Diffuse;
pub use metal_rough::MetalRough;
pub use microfacet::{Beckmann, Microfacet, MicrofacetDistribution, TrowbridgeReitz};
pub use plastic::Plastic;

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
    /// BSDF value (no cosine), or the delta lobe's weight divided by |cos θᵢ|.
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
    Conductor(Conductor),
    Dielectric(Dielectric),
    ThinDielectric(ThinDielectric),
    Plastic(Plastic),
    MetalRough(MetalRough),
}

/// Mirrors a direction through the surface plane (z → −z).
#[inline]
fn flip_z(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

impl Lobe {
    #[inline]
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.f_pdf(wo, wi).0
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.f_pdf(wo, wi).1
    }

    /// [`Self::f`] and [`Self::pdf`] of one pair at once: the microfacet lobes share their
    /// half vector, D, Λ(ωo) and Fresnel term between the two (next event estimation
    /// and every sample ask for both).
    #[inline]
    pub fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (wo, wi) = if wo.z < 0.0 && self.is_reflective() {
            (flip_z(wo), flip_z(wi))
        } else {
            (wo, wi)
        };
        match self {
            Lobe::Diffuse(l) => (l.f(wo, wi), l.pdf(wo, wi)),
            Lobe::Conductor(l) => l.f_pdf(wo, wi),
            Lobe::Plastic(l) => l.f_pdf(wo, wi),
            Lobe::MetalRough(l) => l.f_pdf(wo, wi),
            Lobe::Dielectric(l) => l.f_pdf(wo, wi),
            Lobe::ThinDielectric(_) => (Vec3::ZERO, 0.0),
        }
    }

    #[inline]
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let flip = wo.z < 0.0 && self.is_reflective();
        let wo = if flip { flip_z(wo) } else { wo };
        let s = match self {
            Lobe::Diffuse(l) => l.sample(wo, u_lobe, u),
            Lobe::Conductor(l) => l.sample(wo, u),
            Lobe::Plastic(l) => l.sample(wo, u_lobe, u),
            Lobe::MetalRough(l) => l.sample(wo, u_lobe, u),
            Lobe::Dielectric(l) => l.sample(wo, u_lobe, u),
            Lobe::ThinDielectric(l) => l.sample(wo, u_lobe),
        }?;
        Some(if flip {
            BsdfSample {
                wi: flip_z(s.wi),
                ..s
            }
        } else {
            s
        })
    }

    /// Whether [`Self::sample`] reads `u_lobe` (the lambertian and conductor lobes have
    /// one component and ignore it).
    #[inline]
    pub fn takes_lobe_sample(&self) -> bool {
        !matches!(self, Lobe::Diffuse(_) | Lobe::Conductor(_))
    }

    /// Whether the lobe looks the same in every frame about its normal (no anisotropic
    /// roughness): then its shading frame's tangent is arbitrary, and the material builds
    /// it with [`Bsdf::new`] (no tangent to orthogonalize, no ∂p/∂u to read) rather than
    /// [`Bsdf::with_tangent`].
    pub fn is_isotropic(&self) -> bool {
        let round = |m: &Microfacet| {
            let (ax, ay) = m.alpha();
            ax == ay
        };
        match self {
            Lobe::Diffuse(_) | Lobe::ThinDielectric(_) => true,
            Lobe::Conductor(l) => round(&l.distrib),
            Lobe::Dielectric(l) => round(&l.distrib),
            Lobe::Plastic(l) => round(&l.distrib),
            Lobe::MetalRough(l) => l.distrib.alpha_x == l.distrib.alpha_y,
        }
    }

    #[inline]
    fn is_reflective(&self) -> bool {
        !matches!(self, Lobe::Dielectric(_) | Lobe::ThinDielectric(_))
    }

    /// Whether every component is a delta (then NEE is pointless). Plastic is not: its
    /// coat is a delta but its base is diffuse, and NEE goes through `f`/`pdf`, which
    /// hold only the diffuse part.
    #[inline]
    pub fn is_delta(&self) -> bool {
        match self {
            Lobe::Diffuse(_) | Lobe::Plastic(_) | Lobe::MetalRough(_) => false,
            Lobe::Conductor(l) => l.is_delta(),
            Lobe::Dielectric(l) => l.is_delta(),
            Lobe::ThinDielectric(_) => true,
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
    #[inline]
    pub fn new(ns: Vec3, ng: Vec3, lobe: Lobe) -> Bsdf {
        Bsdf {
            frame: Frame::from_z(ns),
            ng,
            lobe,
            one_sided: false,
        }
    }

    /// A BSDF whose frame's first axis (the direction of `alpha_u`) follows the surface
    /// tangent `dpdu`, made orthogonal to `ns`; falls back to [`Bsdf::new`] when `dpdu`
    /// is zero or parallel to `ns`.
    pub fn with_tangent(ns: Vec3, ng: Vec3, dpdu: Vec3, lobe: Lobe) -> Bsdf {
        let s = (dpdu - ns * ns.dot(dpdu)).normalize_or_zero();
        if s == Vec3::ZERO || !s.is_finite() {
            return Bsdf::new(ns, ng, lobe);
        }
        Bsdf {
            frame: Frame {
                s,
                t: ns.cross(s),
                n: ns,
            },
            ng,
            lobe,
            one_sided: false,
        }
    }

    /// Whether the geometric normal agrees with the shading frame on reflection versus
    /// transmission for this pair (see the module's conventions on light leaks).
    /// `cos_o` and `cos_i` are the local z of `wo` and `wi` (their shading cosines).
    #[inline(always)]
    fn sides_agree(&self, wo: Vec3, wi: Vec3, cos_o: f32, cos_i: f32) -> bool {
        let geometric_reflection = wo.dot(self.ng) * wi.dot(self.ng) > 0.0;
        let shading_reflection = cos_o * cos_i > 0.0;
        geometric_reflection == shading_reflection
    }

    /// Whether `wo`, of shading cosine `cos_o`, sees nothing: grazing, or the back of a
    /// one-sided BSDF.
    #[inline(always)]
    fn blind(&self, cos_o: f32) -> bool {
        cos_o == 0.0 || (self.one_sided && cos_o < 0.0)
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
        if self.blind(lo.z) || !self.sides_agree(wo, wi, lo.z, li.z) {
            return Vec3::ZERO;
        }
        self.lobe.f(lo, li)
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
        if self.blind(lo.z) || !self.sides_agree(wo, wi, lo.z, li.z) {
            return 0.0;
        }
        self.lobe.pdf(lo, li)
    }

    /// [`Self::f`] times |cos θᵢ|, and [`Self::pdf`], of one pair of directions: what next
    /// event estimation asks for, with one change of frame instead of three.
    ///
    /// The Lambertian lobe is handled here and inlined into the caller, as in
    /// [`Self::sample`]: out of line, `wo` and `wi` went through memory and the caller
    /// saved its registers around the call (callgrind, Cornell: 77 instructions a call
    /// plus ~25 around it, for what is two dot products and a few compares). The other
    /// lobes go through `Self::f_cos_pdf_lobe`.
    #[inline(always)]
    pub fn f_cos_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let Lobe::Diffuse(d) = &self.lobe else {
            return self.f_cos_pdf_lobe(wo, wi);
        };
        // The Lambertian lobe reads only the two cosines: two dot products instead of two
        // changes of frame, and one dispatch instead of two.
        let (cos_o, cos_i) = (wo.dot(self.frame.n), wi.dot(self.frame.n));
        if self.blind(cos_o) || !self.sides_agree(wo, wi, cos_o, cos_i) {
            return (Vec3::ZERO, 0.0);
        }
        d.f_cos_pdf(cos_o, cos_i)
    }

    /// [`Self::f_cos_pdf`] of every lobe but the Lambertian one.
    #[inline(never)]
    fn f_cos_pdf_lobe(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
        if self.blind(lo.z) || !self.sides_agree(wo, wi, lo.z, li.z) {
            return (Vec3::ZERO, 0.0);
        }
        let (f, pdf) = self.lobe.f_pdf(lo, li);
        (f * li.z.abs(), pdf)
    }

    /// Samples a direction. The Lambertian lobe, most scenes' walls, is handled here and
    /// inlined into the caller, so that `wo` and the frame need not be passed through
    /// memory (out of line, the loads of `wo` and of the normal, stored just before in
    /// other pieces, were this function's hottest instructions); the other lobes go
    /// through `Self::sample_lobe`.
    #[inline(always)]
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let Lobe::Diffuse(d) = &self.lobe else {
            return self.sample_lobe(wo, u_lobe, u);
        };
        // The Lambertian lobe reads only the cosine of `wo` (one dot product, not a
        // change of frame) and is two-sided already (no mirroring of `wo` and back).
        let cos_o = wo.dot(self.frame.n);
        if self.blind(cos_o) {
            return None;
        }
        let s = d.sample_from(cos_o, u)?;
        // Its pdf, |cos θᵢ|/π, is positive (or no sample) and finite, so wi.z ≠ 0: only f
        // is left to check.
        if !s.f.is_finite() {
            return None;
        }
        self.checked_to_world(wo, cos_o, s)
    }

    /// [`Self::sample`] of every lobe but the Lambertian one.
    #[inline(never)]
    fn sample_lobe(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let lo = self.frame.to_local(wo);
        if self.blind(lo.z) {
            return None;
        }
        let s = self.lobe.sample(lo, u_lobe, u)?;
        if s.pdf == 0.0 || !s.pdf.is_finite() || s.wi.z == 0.0 || !s.f.is_finite() {
            return None;
        }
        self.checked_to_world(wo, lo.z, s)
    }

    /// A local sample `s` for `wo` (of shading cosine `cos_o`) in world space, unless its
    /// geometric and shading sides disagree.
    #[inline(always)]
    fn checked_to_world(&self, wo: Vec3, cos_o: f32, s: BsdfSample) -> Option<BsdfSample> {
        let wi = self.frame.to_world(s.wi);
        if !self.sides_agree(wo, wi, cos_o, s.wi.z) {
            return None;
        }
        Some(BsdfSample { wi, ..s })
    }

    #[inline]
    pub fn is_delta(&self) -> bool {
        self.lobe.is_delta()
    }

    /// The square of the relative index η′ that the sampled direction `s` crossed: η′² for
    /// a refraction, 1 otherwise. Refraction scales radiance by 1/η′², so the product of
    /// these along a path undoes that scaling: Russian roulette judges a path by what it
    /// will carry out of the glass, not by the medium it is in (pbrt-v4's `etaScale`,
    /// Mitsuba's η²).
    pub fn eta_crossed_sq(&self, wo: Vec3, s: &BsdfSample) -> f32 {
        match &self.lobe {
            Lobe::Dielectric(d) if s.flags.contains(BsdfFlags::TRANSMISSION) => {
                let etap = if wo.dot(self.frame.n) > 0.0 {
                    d.eta
                } else {
                    1.0 / d.eta
                };
                etap * etap
            }
            _ => 1.0,
        }
    }

    /// |cos θ| of `wi` against the shading normal.
    #[inline]
    pub fn abs_cos(&self, wi: Vec3) -> f32 {
        wi.dot(self.frame.n).abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f_cos_pdf_is_f_times_cos_and_pdf() {
        let ns = Vec3::new(0.2, 0.3, 0.9).normalize();
        let ng = Vec3::new(0.0, 0.2, 1.0).normalize();
        let lobes = [
            Lobe::Diffuse(Diffuse {
                albedo: Vec3::new(0.7, 0.5, 0.2),
            }),
            Lobe::MetalRough(MetalRough::new(Vec3::new(0.9, 0.6, 0.3), 0.5, 0.4)),
            Lobe::Conductor(Conductor {
                distrib: Microfacet::beckmann(0.3, 0.2),
                fresnel: ConductorFresnel::Complex {
                    eta: Vec3::new(0.2, 0.9, 1.1),
                    k: Vec3::new(3.9, 2.4, 2.2),
                },
            }),
            Lobe::Conductor(Conductor {
                distrib: Microfacet::ggx(0.2, 0.2),
                fresnel: ConductorFresnel::Schlick {
                    f0: Vec3::new(0.9, 0.6, 0.3),
                },
            }),
            Lobe::Dielectric(Dielectric {
                eta: 1.5,
                distrib: Microfacet::beckmann(0.4, 0.4),
                tint: Vec3::new(1.0, 0.8, 0.6),
            }),
            Lobe::Plastic(Plastic::rough(
                Vec3::new(0.6, 0.3, 0.2),
                1.5,
                Microfacet::ggx(0.3, 0.3),
            )),
            Lobe::Plastic(Plastic::new(Vec3::new(0.6, 0.3, 0.2), 1.5)),
        ];
        let dirs = [
            Vec3::new(0.3, -0.2, 0.9),
            Vec3::new(-0.7, 0.1, 0.4),
            Vec3::new(0.1, 0.8, -0.3),
            Vec3::new(0.5, 0.5, 0.05),
        ]
        .map(Vec3::normalize);
        let mut nonzero = 0;
        for lobe in lobes {
            let bsdf = Bsdf::with_tangent(ns, ng, Vec3::X, lobe);
            for wo in dirs {
                for wi in dirs {
                    let (f, pdf) = bsdf.f_cos_pdf(wo, wi);
                    assert_eq!(f, bsdf.f(wo, wi) * bsdf.abs_cos(wi), "{wo} {wi}");
                    assert_eq!(pdf, bsdf.pdf(wo, wi), "{wo} {wi}");
                    nonzero += usize::from(pdf > 0.0 && f.max_element() > 0.0);
                }
            }
        }
        eprintln!("{nonzero} pairs with f and pdf > 0");
        // Not vacuous: most lobes see several pairs of the same side.
        assert!(nonzero >= 20, "{nonzero}");
    }
}
