//! Materials: each BSDF description checked and made into its render-time
//! [`Material`], its textures, and the alpha mask a material asks for.

use glam::Vec3;

use crate::alpha::{AlphaMask, AlphaMode};
use crate::bsdf::{
    Conductor, ConductorFresnel, Dielectric, Lobe, Microfacet, MicrofacetDistribution, Plastic,
    ThinDielectric,
};
use crate::desc::{BsdfDesc, MicrofacetDesc, Span, TextureDesc};
use crate::material::{Material, Texture};
use crate::texture::ImageTexture;

use super::validate::{check_color, check_finite, check_image, err, BuildError};

/// The render-time texture of a description, checked (`what` names it in errors).
pub fn build_texture(t: &TextureDesc, span: &Span, what: &str) -> Result<Texture, BuildError> {
    match t {
        TextureDesc::Constant(c) => {
            check_color(span, what, *c)?;
            Ok(Texture::Constant(*c))
        }
        TextureDesc::Checker { a, b, uv_transform } => {
            check_color(span, what, *a)?;
            check_color(span, what, *b)?;
            check_finite(span, what, &uv_transform.to_cols_array())?;
            Ok(Texture::Checker {
                a: *a,
                b: *b,
                uv_transform: *uv_transform,
            })
        }
        TextureDesc::Image(t) => {
            let img = &t.image;
            check_image(span, &format!("{what} image"), img)?;
            check_color(span, what, t.scale)?;
            check_finite(span, what, &t.uv_transform.to_cols_array())?;
            if t.channel.is_some_and(|c| c > 2) {
                return err(span, format!("{what} channel must be 0, 1 or 2"));
            }
            Ok(Texture::Image(ImageTexture {
                image: t.image.clone(),
                wrap: t.wrap,
                uv_transform: t.uv_transform,
                scale: t.scale,
                channel: t.channel,
            }))
        }
    }
}

fn microfacet(
    span: &Span,
    alpha_u: f32,
    alpha_v: f32,
    distribution: MicrofacetDesc,
) -> Result<Microfacet, BuildError> {
    check_finite(span, "roughness", &[alpha_u, alpha_v])?;
    if alpha_u < 0.0 || alpha_v < 0.0 {
        return err(span, "roughness must not be negative");
    }
    // Tiny but non-zero α would overflow D; below the smooth threshold it is a mirror.
    let (u, v) = (alpha_u.max(1e-4), alpha_v.max(1e-4));
    Ok(match distribution {
        MicrofacetDesc::Ggx => Microfacet::ggx(u, v),
        MicrofacetDesc::Beckmann => Microfacet::beckmann(u, v),
    })
}

fn check_eta(span: &Span, eta: f32) -> Result<(), BuildError> {
    if !(eta.is_finite() && eta > 0.0) {
        return err(span, format!("eta {eta} must be positive and finite"));
    }
    Ok(())
}

pub(super) fn build_material(bsdf: &BsdfDesc, span: &Span) -> Result<Material, BuildError> {
    Ok(match bsdf {
        BsdfDesc::Diffuse { albedo } => Material::Diffuse {
            albedo: build_texture(albedo, span, "albedo")?,
        },
        // Never shaded: the volumetric integrator passes through null surfaces.
        BsdfDesc::Null => Material::Diffuse {
            albedo: Texture::Constant(Vec3::ZERO),
        },
        BsdfDesc::Conductor {
            eta,
            k,
            specular,
            alpha_u,
            alpha_v,
            distribution,
        } => {
            check_color(span, "eta", *eta)?;
            check_color(span, "k", *k)?;
            check_color(span, "specular", *specular)?;
            let (eta, k) = (*eta, *k);
            Material::Fixed(Lobe::Conductor(Conductor {
                distrib: microfacet(span, *alpha_u, *alpha_v, *distribution)?,
                fresnel: if *specular == Vec3::ONE {
                    ConductorFresnel::Complex { eta, k }
                } else {
                    ConductorFresnel::ScaledComplex {
                        eta,
                        k,
                        scale: *specular,
                    }
                },
            }))
        }
        BsdfDesc::Dielectric {
            eta,
            alpha_u,
            alpha_v,
            distribution,
            thin,
            tint,
        } => {
            check_eta(span, *eta)?;
            let distrib = microfacet(span, *alpha_u, *alpha_v, *distribution)?;
            let clear = matches!(tint, TextureDesc::Constant(c) if *c == Vec3::ONE);
            if *thin {
                if !distrib.effectively_smooth() {
                    return err(span, "a thin dielectric must be smooth (roughness 0)");
                }
                if !clear {
                    return err(span, "a thin dielectric takes no tint");
                }
                Material::Fixed(Lobe::ThinDielectric(ThinDielectric { eta: *eta }))
            } else {
                let lobe = Dielectric {
                    eta: *eta,
                    distrib,
                    tint: Vec3::ONE,
                };
                if clear {
                    Material::Fixed(Lobe::Dielectric(lobe))
                } else {
                    Material::Dielectric {
                        tint: build_texture(tint, span, "tint")?,
                        lobe,
                    }
                }
            }
        }
        BsdfDesc::Plastic {
            albedo,
            eta,
            alpha,
            distribution,
            linear,
            specular,
        } => {
            check_eta(span, *eta)?;
            check_color(span, "specular", *specular)?;
            let distrib = microfacet(span, *alpha, *alpha, *distribution)?;
            Material::Plastic {
                albedo: build_texture(albedo, span, "albedo")?,
                coat: Plastic {
                    linear: *linear,
                    specular: *specular,
                    ..Plastic::rough(Vec3::ONE, *eta, distrib)
                },
            }
        }
        BsdfDesc::MetalRough {
            base_color,
            metallic,
            roughness,
        } => Material::MetalRough {
            base_color: build_texture(base_color, span, "base_color")?,
            metallic: build_texture(metallic, span, "metallic")?,
            roughness: build_texture(roughness, span, "roughness")?,
        },
        BsdfDesc::TwoSided(inner) => build_material(inner, span)?,
        BsdfDesc::NormalMap { map, inner } => Material::NormalMap {
            map: build_texture(map, span, "normal_map")?,
            inner: Box::new(build_material(inner, span)?),
        },
        BsdfDesc::OneSided(inner) => Material::OneSided(Box::new(build_material(inner, span)?)),
        BsdfDesc::Alpha { inner, .. } => build_material(inner, span)?,
        BsdfDesc::Mix { weight, a, b } => {
            for side in [a, b] {
                if build_alpha(side, span)?.is_some() {
                    return err(
                        span,
                        "an alpha mask inside a mix is not supported (put it around the mix)",
                    );
                }
            }
            Material::mix(
                build_texture(weight, span, "mix weight")?,
                build_material(a, span)?,
                build_material(b, span)?,
            )
        }
    })
}

/// The coverage a material asks for (an [`BsdfDesc::Alpha`] at any depth of wrappers).
pub(super) fn build_alpha(bsdf: &BsdfDesc, span: &Span) -> Result<Option<AlphaMask>, BuildError> {
    match bsdf {
        BsdfDesc::Alpha { alpha, .. } => {
            check_finite(span, "alpha", &[alpha.factor])?;
            if let AlphaMode::Mask { cutoff } = alpha.mode {
                check_finite(span, "alpha cutoff", &[cutoff])?;
            }
            let texture = match &alpha.texture {
                Some(t) => Some(build_texture(t, span, "alpha")?),
                None => None,
            };
            Ok(Some(AlphaMask {
                mode: alpha.mode,
                factor: alpha.factor,
                texture,
            }))
        }
        BsdfDesc::TwoSided(inner)
        | BsdfDesc::OneSided(inner)
        | BsdfDesc::NormalMap { inner, .. } => build_alpha(inner, span),
        _ => Ok(None),
    }
}
