//! The environment light: radiance arriving from infinitely far away, looked up by
//! direction alone. Escaped rays read it ([`EnvironmentLight::le`]); next event estimation
//! samples it in proportion to its filtered radiance, and shadow rays towards it go to
//! infinity.

use std::f32::consts::PI;

use glam::{Mat3, Vec2, Vec3};

use super::envmap::{Cubemap, Equirect, MapSample};
use super::{LightBounds, LightFlags, LightSample, LightSource, ShadingCtx, SkyImportance};
use crate::geometry::Ray;
use crate::math::luminance;
use crate::sampling::{sample_uniform_sphere, UNIFORM_SPHERE_PDF};

/// What the environment looks like, in its native frame.
#[derive(Clone, Debug)]
pub enum EnvironmentMap {
    Constant(Vec3),
    Equirect(Equirect),
    Cubemap(Cubemap),
}

/// How [`EnvironmentLight::sample_li`] picks directions. Importance is the default; the
/// uniform strategy exists to measure what importance sampling buys.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EnvironmentSampling {
    #[default]
    Importance,
    /// Uniform over the sphere, whatever the map.
    Uniform,
}

#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    pub map: EnvironmentMap,
    pub strength: f32,
    /// World from map (a rotation), and its inverse.
    pub world_from_map: Mat3,
    pub map_from_world: Mat3,
    pub visible: bool,
    pub background: Vec3,
    pub sampling: EnvironmentSampling,
    /// Radius of the scene's bounding sphere, for [`Self::power`].
    pub scene_radius: f32,
    /// ∫ luminance(L) dω over the sphere, strength included.
    pub luminance_integral: f32,
    /// Worth to light sampling by surface normal (world frame, strength included), for
    /// choosing among infinite lights; boxed, to keep [`super::Light`] small.
    pub importance: Box<SkyImportance>,
}

impl EnvironmentLight {
    pub fn new(
        map: EnvironmentMap,
        strength: f32,
        world_from_map: Mat3,
        scene_radius: f32,
    ) -> EnvironmentLight {
        let integral = match &map {
            EnvironmentMap::Constant(c) => 4.0 * PI * luminance(*c),
            EnvironmentMap::Equirect(m) => m.luminance_integral(),
            EnvironmentMap::Cubemap(m) => m.luminance_integral(),
        };
        let importance = match &map {
            EnvironmentMap::Constant(c) => SkyImportance::constant(luminance(*c)),
            EnvironmentMap::Equirect(m) => SkyImportance::from_patches(m.luminance_patches()),
            EnvironmentMap::Cubemap(m) => SkyImportance::from_patches(m.luminance_patches()),
        };
        EnvironmentLight {
            importance: Box::new(importance.rotated_scaled(world_from_map, strength)),
            map,
            strength,
            world_from_map,
            map_from_world: world_from_map.transpose(),
            visible: true,
            background: Vec3::ZERO,
            sampling: EnvironmentSampling::Importance,
            scene_radius,
            luminance_integral: strength * integral,
        }
    }

    /// Radiance arriving along `-d` from direction `d` (world space, unit).
    pub fn eval(&self, d: Vec3) -> Vec3 {
        match &self.map {
            // The same everywhere: no rotation into the map's frame.
            EnvironmentMap::Constant(c) => self.strength * *c,
            _ => self.strength * self.eval_local(self.map_from_world * d),
        }
    }

    /// The map's radiance towards `local` (the map's frame, unit), strength not applied.
    fn eval_local(&self, local: Vec3) -> Vec3 {
        match &self.map {
            EnvironmentMap::Constant(c) => *c,
            EnvironmentMap::Equirect(m) => m.eval(local),
            EnvironmentMap::Cubemap(m) => m.eval(local),
        }
    }

    /// What a camera ray that escapes sees: the map, or the background when hidden.
    pub fn le_camera(&self, ray: &Ray) -> Vec3 {
        if self.visible {
            self.le(ray)
        } else {
            self.background
        }
    }

    /// Fraction of the map's power (luminance × texel solid angle) carried by its
    /// brightest `fraction` of texels: near `fraction` for an even sky, near 1 for a
    /// small sun. A measure of how much importance sampling matters.
    pub fn peak_fraction(&self, fraction: f32) -> f32 {
        let mut power: Vec<f32> = match &self.map {
            EnvironmentMap::Constant(_) => return fraction.clamp(0.0, 1.0),
            EnvironmentMap::Equirect(m) => {
                let (w, h) = (m.image.width, m.image.height);
                m.image
                    .pixels
                    .iter()
                    .enumerate()
                    .map(|(i, p)| luminance(*p) * (PI * ((i / w) as f32 + 0.5) / h as f32).sin())
                    .collect()
            }
            EnvironmentMap::Cubemap(m) => m
                .faces
                .iter()
                .flat_map(|f| {
                    let n = f.width;
                    f.pixels.iter().enumerate().map(move |(i, p)| {
                        let a = 2.0 * ((i % n) as f32 + 0.5) / n as f32 - 1.0;
                        let b = 2.0 * ((i / n) as f32 + 0.5) / n as f32 - 1.0;
                        luminance(*p) * (1.0 + a * a + b * b).powf(-1.5)
                    })
                })
                .collect(),
        };
        let total: f64 = power.iter().map(|&p| p as f64).sum();
        if total <= 0.0 {
            return 0.0;
        }
        power.sort_unstable_by(|a, b| b.total_cmp(a));
        let k = ((fraction.clamp(0.0, 1.0) * power.len() as f32).ceil() as usize).max(1);
        (power[..k].iter().map(|&p| p as f64).sum::<f64>() / total) as f32
    }
}

impl LightSource for EnvironmentLight {
    const FLAGS: LightFlags = LightFlags::INFINITE;

    /// Radiance along an escaped ray.
    fn le(&self, ray: &Ray) -> Vec3 {
        self.eval(ray.d.normalize())
    }

    /// The radiance and density from one lookup of the map (the equirect map's grid, the
    /// cube map's face); a constant map's without normalising or rotating the direction.
    fn le_pdf(&self, ctx: &ShadingCtx, ray: &Ray) -> (Vec3, f32) {
        let local = || self.map_from_world * ray.d.normalize();
        let (l, pdf) = match (&self.map, self.sampling) {
            (EnvironmentMap::Constant(c), _) => return (self.strength * *c, UNIFORM_SPHERE_PDF),
            (EnvironmentMap::Equirect(m), EnvironmentSampling::Importance) => m.eval_pdf(local()),
            (EnvironmentMap::Cubemap(m), EnvironmentSampling::Importance) => m.eval_pdf(local()),
            (_, EnvironmentSampling::Uniform) => return (self.le(ray), self.pdf_li(ctx, ray.d)),
        };
        (self.strength * l, pdf)
    }

    fn sample_li(&self, _ctx: &ShadingCtx, u: Vec2) -> Option<LightSample> {
        let s = match (&self.map, self.sampling) {
            (_, EnvironmentSampling::Uniform) | (EnvironmentMap::Constant(_), _) => {
                let dir = sample_uniform_sphere(u);
                let radiance = self.eval_local(dir);
                MapSample {
                    dir,
                    pdf: 1.0 / (4.0 * PI),
                    radiance,
                }
            }
            (EnvironmentMap::Equirect(m), _) => m.sample(u)?,
            (EnvironmentMap::Cubemap(m), _) => m.sample(u)?,
        };
        // A rotation of a unit vector: unit to rounding, as the maps' directions are.
        let wi = self.world_from_map * s.dir;
        Some(LightSample {
            radiance: self.strength * s.radiance,
            wi,
            distance: f32::INFINITY,
            pdf: s.pdf,
            is_delta: false,
            p_light: wi,
            n_light: Vec3::ZERO,
        })
    }

    fn pdf_li(&self, _ctx: &ShadingCtx, wi: Vec3) -> f32 {
        let local = || self.map_from_world * wi.normalize();
        match (&self.map, self.sampling) {
            (EnvironmentMap::Constant(_), _) | (_, EnvironmentSampling::Uniform) => {
                UNIFORM_SPHERE_PDF
            }
            (EnvironmentMap::Equirect(m), _) => m.pdf(local()),
            (EnvironmentMap::Cubemap(m), _) => m.pdf(local()),
        }
    }

    /// Power Φ the scene receives: as pbrt-v4's `ImageInfiniteLight::Phi`, the flux
    /// through a disk of the scene's bounding radius r, averaged over orientations,
    /// Φ = π r² ∫ L dω (luminance-weighted).
    fn power(&self) -> f32 {
        PI * self.scene_radius * self.scene_radius * self.luminance_integral
    }

    /// Worth to light sampling at `ctx`, for light selection: the irradiance of the
    /// radiance above the sky's mean, plus a sixteenth of the whole (see
    /// [`SkyImportance`]).
    fn importance(&self, ctx: &ShadingCtx) -> f32 {
        self.importance.at(ctx)
    }

    /// Infinite: the BVH sampler picks it apart from the tree.
    fn bounds(&self) -> Option<LightBounds> {
        None
    }
}
