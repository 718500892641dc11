//! Alpha-tested (glTF `MASK`) and alpha-blended (glTF `BLEND`) surfaces: the one place
//! that decides whether a ray passes through a triangle it hit.
//!
//! The ray queries ([`Scene::intersect`], [`Scene::occluded`]) hand
//! [`Scene::alpha_accepts`] to the acceleration structure as its filter, which calls it
//! only for triangles of masked meshes (flagged at build); a rejected hit is as if the
//! triangle were not there, so camera rays, bounce rays and shadow rays all see the same
//! cut-out.
//!
//! - `Mask`: the surface is there where α ≥ cutoff and absent elsewhere (a threshold, as
//!   the glTF 2.0 specification §3.9.4 prescribes).
//! - `Blend`: stochastic transparency (Enderton et al. 2010): the hit is kept with
//!   probability α, so the expected transmittance through one layer is 1 − α. The
//!   uniform number comes from a hash of the ray and the primitive, not from a sampler
//!   dimension: images stay identical whatever the thread count or the order in which the
//!   BVH visits primitives, and two queries of the same ray agree.
//!
//! α is `factor` times the texture's first channel at the hit's uv (loaders put the
//! image's alpha there).

use glam::Vec2;

pub use crate::desc::AlphaMode;
use crate::geometry::{Ray, TriangleHit};
use crate::sampler::hash_uniform;
use crate::scene::{Prim, Scene};
use crate::texture::Texture;

/// The coverage of a mesh's surface.
#[derive(Clone, Debug)]
pub struct AlphaMask {
    pub mode: AlphaMode,
    pub factor: f32,
    /// Read through its first channel; `None` is 1 everywhere.
    pub texture: Option<Texture>,
}

impl AlphaMask {
    /// α at texture coordinates `uv`.
    pub fn alpha(&self, uv: Vec2) -> f32 {
        self.factor * self.texture.as_ref().map_or(1.0, |t| t.eval_scalar(uv))
    }

    /// Whether a hit at `uv` is passed through; `u` is the hit's uniform number in [0, 1).
    pub fn rejects(&self, uv: Vec2, u: f32) -> bool {
        let a = self.alpha(uv);
        match self.mode {
            // Written so that a NaN α hides the surface.
            AlphaMode::Mask { cutoff } => a.partial_cmp(&cutoff).is_none_or(|o| o.is_lt()),
            AlphaMode::Blend => u.partial_cmp(&a).is_none_or(|o| o.is_ge()),
        }
    }
}

/// A uniform number in [0, 1) fixed by the ray and the primitive (splitmix64 over their
/// bits): the same ray meeting the same triangle always decides the same way.
pub fn hit_uniform(ray: &Ray, mesh: u32, tri: u32) -> f32 {
    hash_uniform(
        ((mesh as u64) << 32) | tri as u64,
        &[ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z],
    )
}

impl Scene {
    /// Whether the ray passes through triangle `tri` of mesh `mesh`, hit at barycentrics
    /// `bary`, because the surface is not there (see the module docs).
    #[inline]
    pub fn alpha_rejects(&self, mesh: u32, tri: u32, bary: Vec2, ray: &Ray) -> bool {
        let m = &self.meshes[mesh as usize];
        match &m.alpha {
            None => false,
            Some(alpha) => alpha.rejects(m.uv_at(tri, bary), hit_uniform(ray, mesh, tri)),
        }
    }

    /// The acceleration structure's filter: whether `hit` on primitive `prim` (an index
    /// into [`Scene::prims`]) counts.
    #[inline]
    pub fn alpha_accepts(&self, prim: u32, hit: &TriangleHit, ray: &Ray) -> bool {
        match self.prims[prim as usize] {
            Prim::Triangle { mesh, tri } => {
                !self.alpha_rejects(mesh, tri, Vec2::new(hit.b1, hit.b2), ray)
            }
            Prim::Sphere(_) => true,
        }
    }

    /// The instances' filter: whether `hit` on triangle `tri` of instance `inst` counts.
    /// The hit's uniform number hashes the world-space ray, so every instance of a mesh
    /// decides independently; instance ids are kept apart from mesh ids by the top bit.
    #[inline]
    pub fn instance_alpha_accepts(
        &self,
        inst: u32,
        tri: u32,
        hit: &TriangleHit,
        ray: &Ray,
    ) -> bool {
        let i = &self.instances.instances[inst as usize];
        match &i.alpha {
            None => true,
            Some(alpha) => {
                let m = &self.instances.meshes[i.mesh as usize];
                let uv = m.uv_at(tri, Vec2::new(hit.b1, hit.b2));
                !alpha.rejects(uv, hit_uniform(ray, inst | 1 << 31, tri))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};

    #[test]
    fn hit_uniforms_are_uniform_and_deterministic() {
        // 100 000 rays into 10 bins: chi-square with 9 degrees of freedom; 27.9 is the
        // 0.999 quantile, so a correct hash fails this with probability 10⁻³ (fixed inputs,
        // so it either always passes or always fails).
        let n = 100_000;
        let mut bins = [0u32; 10];
        for i in 0..n {
            let ray = Ray::new(Vec3::new(i as f32 * 1e-3, 0.5, -1.0), Vec3::Z);
            let u = hit_uniform(&ray, 3, 7);
            assert!((0.0..1.0).contains(&u));
            assert_eq!(u, hit_uniform(&ray, 3, 7));
            bins[(u * 10.0) as usize] += 1;
        }
        let e = n as f64 / 10.0;
        let chi2: f64 = bins.iter().map(|&b| (b as f64 - e).powi(2) / e).sum();
        eprintln!("hit_uniform: chi2 {chi2:.2} (9 dof), bins {bins:?}");
        assert!(chi2 < 27.9, "chi2 {chi2}, bins {bins:?}");
    }

    #[test]
    fn mask_is_a_threshold_and_blend_keeps_alpha() {
        let mask = AlphaMask {
            mode: AlphaMode::Mask { cutoff: 0.5 },
            factor: 0.6,
            texture: None,
        };
        assert!(!mask.rejects(Vec2::ZERO, 0.99));
        let low = AlphaMask {
            factor: 0.4,
            ..mask.clone()
        };
        assert!(low.rejects(Vec2::ZERO, 0.0));
        let blend = AlphaMask {
            mode: AlphaMode::Blend,
            ..low
        };
        assert!(!blend.rejects(Vec2::ZERO, 0.39) && blend.rejects(Vec2::ZERO, 0.4));
        // NaN alpha hides the surface rather than poisoning anything.
        let nan = AlphaMask {
            factor: f32::NAN,
            ..blend
        };
        assert!(nan.rejects(Vec2::ZERO, 0.0));
    }
}
