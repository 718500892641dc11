//! How much each infinite light (a sun, a sky) is worth to next event estimation at a
//! shading point, for choosing among them: the light BVH keeps these apart from its tree
//! and picks among them by this importance rather than uniformly.
//!
//! A directional light counts its irradiance E·|n·ω|: BSDF sampling can never find it.
//! An environment counts the irradiance of its radiance **above its mean** (Karlík et al.
//! 2019, "MIS Compensation", subtract the mean from the environment's sampling density
//! for the same reason; the maps' own densities subtract half of it, see
//! `envmap::compensated`): BSDF sampling finds the even part of a sky about as well as
//! light sampling does, and with MIS it then carries most of that light anyway, so a pick
//! spent on an even sky mostly buys variance for the other lights. A constant sky beside
//! a sun therefore gets few picks; a sky whose light is in a bright sun keeps its share.
//! One sixteenth of the sky's whole irradiance is added, so that it is never refused (no
//! MIS, a sky-only region). On `bench/scenes/sun-sky-glass.xml` (a directional sun and a
//! constant sky) fixed picks of the sun with probability 0.5, 0.7, 0.9 and 0.97 gave
//! relMSE (worst 0.1 % of pixels dropped, 8 seeds) 0.0089, 0.0058, 0.0041 and 0.0038,
//! picks by the whole irradiance (no subtraction) 0.0073, and these picks 0.0039
//! (`bench/RESULTS.md`, `## env_paths`).
//!
//! Irradiance comes from the luminance's spherical harmonics up to order 2 (Ramamoorthi &
//! Hanrahan 2001, "An Efficient Representation for Irradiance Environment Maps": a few
//! per cent off for smooth skies; a sun's clamped cosine comes out blurred, 0.09 of its
//! peak edge-on where it is 0, which an importance can afford), on the brighter side of
//! the surface, max(E(n), E(−n)), as the light does not know which side is lit. Where
//! there is no surface (in a medium) the fluence stands in: E for a directional light,
//! ∫ L dω for an environment.

use std::f32::consts::PI;

use glam::{Mat3, Vec3};

use super::{receiver_cos, ShadingCtx};

/// The irradiance of an environment as a function of the surface normal: the order-2
/// spherical-harmonic approximation, as the quadratic form E(n) = nᵀ A n + b·n + c.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyIrradiance {
    a: Mat3,
    b: Vec3,
    c: f32,
    /// ∫ L dω (luminance): the fluence, for points without a normal.
    fluence: f32,
}

/// The real spherical harmonics of order ≤ 2 at unit `d` (in the order l = 0; l = 1:
/// y, z, x; l = 2: xy, yz, 3z² − 1, xz, x² − y²), with their normalisation constants.
fn sh9(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_095,
        0.488_603 * y,
        0.488_603 * z,
        0.488_603 * x,
        1.092_548 * x * y,
        1.092_548 * y * z,
        0.315_392 * (3.0 * z * z - 1.0),
        1.092_548 * x * z,
        0.546_274 * (x * x - y * y),
    ]
}

/// Sums of luminance × the harmonics over patches of the sphere: the projection of the
/// luminance onto them.
#[derive(Default)]
struct Projection {
    l: [f64; 9],
    fluence: f64,
}

impl Projection {
    fn add(&mut self, y: &[f32; 9], w: f32) {
        for (acc, y) in self.l.iter_mut().zip(y) {
            *acc += (y * w) as f64;
        }
        self.fluence += w as f64;
    }

    /// E = Σ Â_l L_lm Y_lm(n) with Â = π, 2π/3, π/4, expanded into the quadratic form.
    fn irradiance(&self) -> SkyIrradiance {
        let l = self.l.map(|v| v as f32);
        let (a1, a2) = (2.0 * PI / 3.0, PI / 4.0);
        let xy = a2 * 1.092_548 * l[4] / 2.0;
        let yz = a2 * 1.092_548 * l[5] / 2.0;
        let xz = a2 * 1.092_548 * l[7] / 2.0;
        let xx = a2 * 0.546_274 * l[8];
        let zz = a2 * 0.315_392 * 3.0 * l[6];
        SkyIrradiance {
            a: Mat3::from_cols(
                Vec3::new(xx, xy, xz),
                Vec3::new(xy, -xx, yz),
                Vec3::new(xz, yz, zz),
            ),
            b: a1 * 0.488_603 * Vec3::new(l[3], l[1], l[2]),
            c: PI * 0.282_095 * l[0] - a2 * 0.315_392 * l[6],
            fluence: self.fluence as f32,
        }
    }
}

impl SkyIrradiance {
    /// From the luminance carried by small patches of the sphere: each `(d, lum · dω)`,
    /// `d` a unit direction (the patches should cover the sphere; their sum is ∫ L dω).
    pub fn from_patches(patches: impl IntoIterator<Item = (Vec3, f32)>) -> SkyIrradiance {
        let mut sum = Projection::default();
        for (d, w) in patches {
            sum.add(&sh9(d), w);
        }
        sum.irradiance()
    }

    /// A sky of the same luminance `lum` everywhere: E = π·lum on every side.
    pub fn constant(lum: f32) -> SkyIrradiance {
        SkyIrradiance {
            a: Mat3::ZERO,
            b: Vec3::ZERO,
            c: PI * lum,
            fluence: 4.0 * PI * lum,
        }
    }

    /// The same sky turned by the rotation `r` (a direction d of the old sky is r·d).
    pub fn rotated(&self, r: Mat3) -> SkyIrradiance {
        SkyIrradiance {
            a: r * self.a * r.transpose(),
            b: r * self.b,
            ..*self
        }
    }

    /// Scaled by `k` (a strength).
    pub fn scaled(&self, k: f32) -> SkyIrradiance {
        SkyIrradiance {
            a: self.a * k,
            b: self.b * k,
            c: self.c * k,
            fluence: self.fluence * k,
        }
    }

    /// Irradiance (luminance) on a surface of unit normal `n`, unshadowed: approximate,
    /// and possibly slightly negative away from a sun (the order-2 ringing).
    pub fn irradiance(&self, n: Vec3) -> f32 {
        n.dot(self.a * n) + self.b.dot(n) + self.c
    }

    /// Irradiance on the brighter side of a surface at `ctx`, max(E(n), E(−n)), never
    /// negative; the fluence where there is no normal.
    pub fn brighter_side(&self, ctx: &ShadingCtx) -> f32 {
        if ctx.n == Vec3::ZERO {
            return self.fluence;
        }
        let even = ctx.n.dot(self.a * ctx.n) + self.c;
        (even + self.b.dot(ctx.n).abs()).max(0.0)
    }
}

/// An environment's importance: see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyImportance {
    /// The whole sky's irradiance.
    all: SkyIrradiance,
    /// The irradiance of the radiance above the sky's mean.
    excess: SkyIrradiance,
}

/// The share of the whole sky's irradiance every environment keeps.
const SKY_FLOOR: f32 = 1.0 / 16.0;

impl SkyImportance {
    /// From patches of the sphere as for [`SkyIrradiance::from_patches`]; `area` is each
    /// patch's solid angle (the first item of `patches` is luminance × area).
    pub fn from_patches<I>(patches: I) -> SkyImportance
    where
        I: Iterator<Item = (Vec3, f32, f32)> + Clone,
    {
        let (light, area) = patches
            .clone()
            .fold((0.0f64, 0.0f64), |(l, a), (_, w, da)| {
                (l + w as f64, a + da as f64)
            });
        let mean = (light / area) as f32;
        let (mut all, mut excess) = (Projection::default(), Projection::default());
        for (d, w, da) in patches {
            let y = sh9(d);
            all.add(&y, w);
            excess.add(&y, (w - mean * da).max(0.0));
        }
        SkyImportance {
            all: all.irradiance(),
            excess: excess.irradiance(),
        }
    }

    /// A sky of luminance `lum` everywhere: nothing above its mean.
    pub fn constant(lum: f32) -> SkyImportance {
        SkyImportance {
            all: SkyIrradiance::constant(lum),
            excess: SkyIrradiance::constant(0.0),
        }
    }

    /// The same sky turned by the rotation `r` and scaled by `k`.
    pub fn rotated_scaled(&self, r: Mat3, k: f32) -> SkyImportance {
        SkyImportance {
            all: self.all.rotated(r).scaled(k),
            excess: self.excess.rotated(r).scaled(k),
        }
    }

    /// The importance at `ctx`.
    #[inline]
    pub fn at(&self, ctx: &ShadingCtx) -> f32 {
        self.excess.brighter_side(ctx) + SKY_FLOOR * self.all.brighter_side(ctx)
    }

    /// Where the sky's irradiance is the same on every side (a constant sky: no linear
    /// or quadratic term), its importance on a surface and where there is no surface,
    /// which [`Self::at`] then returns at every point: the quadratic forms' terms in n
    /// are zero, so n·(A n) + c + |b·n| is c exactly.
    pub fn even(&self) -> Option<(f32, f32)> {
        let even = |s: &SkyIrradiance| s.a == Mat3::ZERO && s.b == Vec3::ZERO;
        (even(&self.all) && even(&self.excess)).then(|| {
            let surface = self.excess.c.max(0.0) + SKY_FLOOR * self.all.c.max(0.0);
            let volume = self.excess.fluence + SKY_FLOOR * self.all.fluence;
            (surface, volume)
        })
    }
}

/// What the light BVH keeps of an infinite light to weigh it at a shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InfiniteImportance {
    /// A directional light: the luminance of its irradiance, and the unit direction
    /// towards it.
    Direction { irradiance: f32, wi: Vec3 },
    /// An environment.
    Sky(SkyImportance),
    /// An environment whose importance is the same at every point with a normal
    /// (`surface`) and at every point without one (`volume`): see
    /// [`SkyImportance::even`]. Weighing it costs a comparison, not two quadratic forms.
    EvenSky { surface: f32, volume: f32 },
}

impl InfiniteImportance {
    /// An environment's: [`InfiniteImportance::EvenSky`] where [`SkyImportance::even`]
    /// says so, else [`InfiniteImportance::Sky`].
    pub fn sky(s: &SkyImportance) -> InfiniteImportance {
        match s.even() {
            Some((surface, volume)) => InfiniteImportance::EvenSky { surface, volume },
            None => InfiniteImportance::Sky(*s),
        }
    }

    /// The light's importance at `ctx` (what its `LightSource::importance` answers).
    #[inline]
    pub fn at(&self, ctx: &ShadingCtx) -> f32 {
        match self {
            InfiniteImportance::Direction { irradiance, wi } => irradiance * receiver_cos(ctx, *wi),
            InfiniteImportance::Sky(s) => s.at(ctx),
            InfiniteImportance::EvenSky { surface, volume } => {
                if ctx.n == Vec3::ZERO {
                    *volume
                } else {
                    *surface
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Patches of a (θ, φ) grid fine enough for the order-2 projection of smooth skies.
    fn grid(radiance: impl Fn(Vec3) -> f32) -> SkyIrradiance {
        let (nt, np) = (200, 400);
        let mut patches = Vec::new();
        for i in 0..nt {
            let theta = PI * (i as f32 + 0.5) / nt as f32;
            for j in 0..np {
                let phi = 2.0 * PI * (j as f32 + 0.5) / np as f32;
                let d = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                let dw = theta.sin() * (PI / nt as f32) * (2.0 * PI / np as f32);
                patches.push((d, radiance(d) * dw));
            }
        }
        SkyIrradiance::from_patches(patches)
    }

    #[test]
    fn constant_sky_gives_pi_l_on_every_side() {
        let s = grid(|_| 2.0);
        let exact = SkyIrradiance::constant(2.0);
        assert!((s.c - exact.c).abs() < 1e-3 && s.a.abs_diff_eq(Mat3::ZERO, 1e-3));
        for n in [Vec3::X, -Vec3::Y, Vec3::new(0.6, 0.0, 0.8)] {
            assert!(
                (s.irradiance(n) - 2.0 * PI).abs() < 1e-3,
                "{}",
                s.irradiance(n)
            );
        }
        assert!((s.fluence - 8.0 * PI).abs() < 1e-2);
    }

    #[test]
    fn linear_sky_is_exact() {
        // L = 1 + d.y is within order 1: E(n) = π + (2π/3) n.y exactly.
        let s = grid(|d| 1.0 + d.y);
        for n in [Vec3::Y, -Vec3::Y, Vec3::X, Vec3::new(0.0, 0.6, 0.8)] {
            let exact = PI + 2.0 * PI / 3.0 * n.y;
            assert!((s.irradiance(n) - exact).abs() < 2e-3, "{n}");
        }
        // The brighter side of a horizontal surface is the top.
        let ctx = ShadingCtx {
            p: Vec3::ZERO,
            n: -Vec3::Y,
        };
        assert!((s.brighter_side(&ctx) - 5.0 * PI / 3.0).abs() < 2e-3);
    }

    #[test]
    fn rotation_and_scale_follow_the_sky() {
        let sky = |d: Vec3| (1.0 + d.x).powi(3);
        let r = Mat3::from_rotation_z(0.9) * Mat3::from_rotation_y(0.4);
        let turned = grid(|d| sky(r.transpose() * d));
        let s = grid(sky).rotated(r).scaled(3.0);
        for n in [Vec3::X, Vec3::Y, Vec3::new(0.48, 0.6, 0.64)] {
            let want = 3.0 * turned.irradiance(n);
            assert!(
                (s.irradiance(n) - want).abs() < 1e-3 * want.abs().max(1.0),
                "{n}"
            );
        }
    }

    #[test]
    fn a_sun_is_seen_by_surfaces_facing_it() {
        // A point sun of ∫ L dω = 1 towards +x. The order-2 approximation of its clamped
        // cosine is 1/4 + cos γ/2 + 5/32 (3 cos² γ − 1): 1.06 facing it, 0.09 edge-on
        // (exactly 0), 0.06 facing away; the importance takes the brighter side.
        let s = SkyIrradiance::from_patches([(Vec3::X, 1.0)]);
        let at = |n: Vec3| s.brighter_side(&ShadingCtx { p: Vec3::ZERO, n });
        assert!((s.irradiance(Vec3::X) - 1.0625).abs() < 1e-4);
        assert!((s.irradiance(-Vec3::X) - 0.0625).abs() < 1e-4);
        assert!((at(Vec3::Y) - 0.093_75).abs() < 1e-4);
        assert!((at(-Vec3::X) - 1.0625).abs() < 1e-4, "the brighter side");
    }

    #[test]
    fn an_even_sky_keeps_only_its_floor_and_a_sun_its_light() {
        let ctx = ShadingCtx {
            p: Vec3::ZERO,
            n: Vec3::Y,
        };
        let even = SkyImportance::constant(1.0);
        assert!((even.at(&ctx) - PI / 16.0).abs() < 1e-6);
        // Its even form answers the same bits on a surface and off one.
        let fast = InfiniteImportance::sky(&even);
        assert!(matches!(fast, InfiniteImportance::EvenSky { .. }));
        for n in [Vec3::Y, -Vec3::X, Vec3::new(0.48, -0.6, 0.64), Vec3::ZERO] {
            let ctx = ShadingCtx { p: Vec3::ONE, n };
            assert_eq!(fast.at(&ctx).to_bits(), even.at(&ctx).to_bits(), "{n}");
        }
        // 1 % of the sphere 10⁴ times brighter than the rest, straight up: nearly all of
        // the light is above the mean, and the surface facing it sees nearly all of it.
        let patches = (0..10_000).map(|i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 10_000.0;
            let phi = i as f32 * 2.399_963; // the golden angle: an even spiral
            let r = (1.0 - z * z).sqrt();
            let d = Vec3::new(r * phi.cos(), z, r * phi.sin());
            let area = 4.0 * PI / 10_000.0;
            let l = if z > 0.98 { 1e4 } else { 1.0 };
            (d, l * area, area)
        });
        let sky = SkyImportance::from_patches(patches);
        let sun = sky.excess.brighter_side(&ctx);
        assert!(sun > 0.95 * sky.all.brighter_side(&ctx), "{sun}");
        assert!((sky.at(&ctx) - sun - sky.all.brighter_side(&ctx) / 16.0).abs() < 1e-3 * sun);
        assert!(matches!(
            InfiniteImportance::sky(&sky),
            InfiniteImportance::Sky(_)
        ));
    }
}
