//! Materials: what a surface is made of, turned into a [`Bsdf`] at each shading point.

use glam::{Vec2, Vec3};

use crate::bsdf::{Bsdf, Diffuse, Lobe};

/// Index of a material in [`crate::Scene::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId(pub u32);

/// A colour that may vary over a surface (linear values).
#[derive(Clone, Debug)]
pub enum Texture {
    Constant(Vec3),
}

impl Texture {
    pub fn eval(&self, _uv: Vec2) -> Vec3 {
        match self {
            Texture::Constant(c) => *c,
        }
    }
}

#[derive(Clone, Debug)]
pub enum Material {
    Diffuse {
        albedo: Texture,
    },
    /// Black from the back: see [`crate::desc::BsdfDesc::OneSided`].
    OneSided(Box<Material>),
}

impl Material {
    /// The BSDF at a point with shading normal `ns`, geometric normal `ng` and texture
    /// coordinates `uv`.
    pub fn bsdf(&self, ns: Vec3, ng: Vec3, uv: Vec2) -> Bsdf {
        match self {
            Material::Diffuse { albedo } => Bsdf::new(
                ns,
                ng,
                Lobe::Diffuse(Diffuse {
                    albedo: albedo.eval(uv),
                }),
            ),
            Material::OneSided(inner) => Bsdf {
                one_sided: true,
                ..inner.bsdf(ns, ng, uv)
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sided_is_black_from_the_back_only() {
        let diffuse = Material::Diffuse {
            albedo: Texture::Constant(Vec3::splat(0.5)),
        };
        let two = diffuse.bsdf(Vec3::Z, Vec3::Z, Vec2::ZERO);
        let one = Material::OneSided(Box::new(diffuse)).bsdf(Vec3::Z, Vec3::Z, Vec2::ZERO);
        let (front, back) = (Vec3::new(0.3, 0.0, 0.9).normalize(), -Vec3::Z);
        let wi = Vec3::new(-0.2, 0.1, 0.8).normalize();
        assert_eq!(one.f(front, wi), two.f(front, wi));
        assert_eq!(one.pdf(front, wi), two.pdf(front, wi));
        assert!(one.sample(front, 0.5, Vec2::splat(0.3)).is_some());
        // From the back the two-sided diffuse reflects; the one-sided one is black.
        assert!(two.f(back, -wi).max_element() > 0.0);
        assert_eq!(one.f(back, -wi), Vec3::ZERO);
        assert_eq!(one.pdf(back, -wi), 0.0);
        assert!(one.sample(back, 0.5, Vec2::splat(0.3)).is_none());
    }
}
