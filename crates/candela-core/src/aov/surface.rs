//! What one camera ray contributes to the passes: the first non-specular surface behind
//! any chain of perfect mirrors and glass, its albedo and shading normal, and the depth of
//! the first surface of all.

use glam::Vec3;

use crate::bsdf::Lobe;
use crate::geometry::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;

/// Delta bounces followed before a chain of mirrors is given up as black (a hall of
/// mirrors; any real scene ends long before).
const MAX_SPECULAR_BOUNCES: u32 = 16;

/// One camera ray's values for the passes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstSurface {
    /// The first non-specular surface's [`lobe_albedo`] times the reflectance or
    /// transmittance of the delta lobes on the way, in [0, 1]; black where the chain
    /// escaped or ended.
    pub albedo: Vec3,
    /// That surface's world-space shading normal (black where there is none).
    pub normal: Vec3,
    /// Distance along the camera's viewing axis to the first surface hit, specular or not.
    pub depth: f32,
}

/// The albedo OIDN asks of a surface for denoising ("the approximate colour of the
/// surface independent of illumination and viewing angle", in [0, 1]):
/// - Lambertian: its reflectance;
/// - plastic: its diffuse base (a clear coat that absorbs nothing is left out);
/// - glTF metallic-roughness: the base colour (the diffuse colour of a dielectric, the
///   reflectance at normal incidence F₀ of a metal);
/// - rough conductor: its Fresnel reflectance at normal incidence;
/// - rough glass: its transmission tint;
/// - delta lobes (only met when a chain of them is cut short): 1.
pub fn lobe_albedo(lobe: &Lobe) -> Vec3 {
    match lobe {
        Lobe::Diffuse(d) => d.albedo,
        Lobe::Plastic(p) => p.albedo,
        Lobe::MetalRough(m) => m.base_color,
        Lobe::Conductor(c) => c.fresnel.eval(1.0),
        Lobe::Dielectric(d) => d.tint,
        Lobe::ThinDielectric(_) => Vec3::ONE,
    }
}

/// Follows `ray` (a camera ray) through delta lobes to the first surface that is not
/// one: `None` where the camera ray itself escapes. Each delta bounce takes one 1D and one
/// 2D number from `sampler` (reflect or refract at glass, by Fresnel, as the path tracer
/// chooses), so over a pixel's samples glass shows the Fresnel blend of what it reflects
/// and transmits. A refraction's radiance scaling 1/η′² does not apply to albedo.
pub fn first_surface<S: Sampler>(
    scene: &Scene,
    mut ray: Ray,
    sampler: &mut S,
) -> Option<FirstSurface> {
    let first = scene.intersect(&ray, f32::INFINITY)?;
    let depth = (first.p - scene.camera.position).dot(scene.camera.forward());
    let mut through = Vec3::ONE;
    let mut si = first;
    for _ in 0..=MAX_SPECULAR_BOUNCES {
        let bsdf = scene.materials[si.material.0 as usize].bsdf_at(&si);
        if !bsdf.is_delta() {
            return Some(FirstSurface {
                albedo: (through * lobe_albedo(&bsdf.lobe)).clamp(Vec3::ZERO, Vec3::ONE),
                normal: bsdf.frame.n,
                depth,
            });
        }
        let wo = -ray.d;
        let u_lobe = sampler.get_1d();
        let u = sampler.get_2d();
        let Some(bs) = bsdf.sample(wo, u_lobe, u) else {
            break;
        };
        through *= bs.f * (bsdf.abs_cos(bs.wi) / bs.pdf) * bsdf.eta_crossed_sq(wo, &bs);
        ray = si.spawn_ray(bs.wi);
        match scene.intersect(&ray, f32::INFINITY) {
            Some(next) => si = next,
            None => break,
        }
    }
    Some(FirstSurface {
        albedo: Vec3::ZERO,
        normal: Vec3::ZERO,
        depth,
    })
}
