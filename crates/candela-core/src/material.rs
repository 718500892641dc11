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
    Diffuse { albedo: Texture },
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
        }
    }
}
