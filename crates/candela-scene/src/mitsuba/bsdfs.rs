//! `<bsdf>`: Mitsuba's BSDFs to Candela materials. Mitsuba's reflective BSDFs are
//! one-sided (black from the back) unless wrapped in `twosided`; Candela's are two-sided,
//! so an unwrapped one becomes [`BsdfDesc::OneSided`]. Dielectrics are two-sided in both.

use candela_core::alpha::AlphaMode;
use candela_core::math::luminance;

use candela_core::desc::{
    conductor, AlphaDesc, BsdfDesc, ImageDesc, MaterialDesc, MicrofacetDesc, TextureDesc,
};
use glam::Vec3;

use super::parse::Node;
use super::{describe, Ctx};
use crate::LoadError;

/// Adds the material of a `<bsdf>` element and returns its name (its `id` if it has one).
pub(crate) fn material(ctx: &mut Ctx, node: &Node) -> Result<String, LoadError> {
    let bsdf = bsdf(ctx, node)?;
    let name = node
        .attr("id")
        .map_or_else(|| ctx.fresh_name(node), str::to_string);
    if ctx.desc.materials.iter().any(|m| m.name == name) {
        return Err(node.error(format!("id \"{name}\" is used twice")));
    }
    ctx.desc.materials.push(MaterialDesc {
        name: name.clone(),
        bsdf,
        span: node.span.clone(),
    });
    Ok(name)
}

/// The one-sided diffuse that Mitsuba gives a shape without a BSDF: grey (0.5), or black
/// on an emitter (Mitsuba 3.9.1 renders an emitting square without a BSDF, lit by a
/// constant sky, as its radiance alone).
pub(crate) fn default_material(ctx: &mut Ctx, emitter: bool) -> String {
    let (name, albedo) = if emitter {
        ("mitsuba-default-emitter", 0.0)
    } else {
        ("mitsuba-default-diffuse", 0.5)
    };
    if !ctx.desc.materials.iter().any(|m| m.name == name) {
        ctx.desc.materials.push(MaterialDesc {
            name: name.to_string(),
            bsdf: BsdfDesc::OneSided(Box::new(BsdfDesc::Diffuse {
                albedo: TextureDesc::Constant(Vec3::splat(albedo)),
            })),
            span: candela_core::desc::Span::code(),
        });
    }
    name.to_string()
}

fn grey() -> BsdfDesc {
    BsdfDesc::Diffuse {
        albedo: TextureDesc::Constant(Vec3::splat(0.5)),
    }
}

fn bsdf(ctx: &mut Ctx, node: &Node) -> Result<BsdfDesc, LoadError> {
    if node.kind() == "twosided" {
        let inner: Vec<&Node> = node.plugins("bsdf").collect();
        let d = match inner.as_slice() {
            [one] => two_sided(ctx, one)?,
            [] => match referenced(ctx, node)? {
                Some(d) => two_sided_form(d),
                None => return Err(node.error("twosided needs a nested <bsdf> or a <ref>")),
            },
            _ => {
                ctx.unsupported(
                    node,
                    "twosided with different BSDFs on the two sides is not supported".into(),
                )?;
                two_sided(ctx, inner[0])?
            }
        };
        ctx.check_unused(node)?;
        return Ok(d);
    }
    if matches!(node.kind(), "mask" | "normalmap" | "blendbsdf") {
        return wrapper(ctx, node, false);
    }
    Ok(match two_sided(ctx, node)? {
        d @ (BsdfDesc::Diffuse { .. } | BsdfDesc::Conductor { .. } | BsdfDesc::Plastic { .. }) => {
            BsdfDesc::OneSided(Box::new(d))
        }
        other => other,
    })
}

/// The BSDF as Candela's (two-sided) material.
fn two_sided(ctx: &mut Ctx, node: &Node) -> Result<BsdfDesc, LoadError> {
    let kind = node.kind();
    let d = match kind {
        // A medium's boundary: rays pass through (see `candela_core::medium`).
        "null" => BsdfDesc::Null,
        "diffuse" => BsdfDesc::Diffuse {
            albedo: ctx.texture(node, "reflectance", Vec3::splat(0.5))?,
        },
        "conductor" | "roughconductor" => {
            let (eta, k) = conductor_ior(ctx, node)?;
            let (alpha_u, alpha_v, distribution) = roughness(node, kind == "roughconductor")?;
            BsdfDesc::Conductor {
                eta,
                k,
                specular: specular_reflectance(ctx, node)?,
                alpha_u,
                alpha_v,
                distribution,
            }
        }
        "dielectric" | "roughdielectric" | "thindielectric" => {
            let eta = ior(node, "int_ior", 1.5046)? / ior(node, "ext_ior", 1.000277)?;
            let (alpha_u, alpha_v, distribution) = roughness(node, kind == "roughdielectric")?;
            unit_only(ctx, node, "specular_reflectance")?;
            let thin = kind == "thindielectric";
            // Mitsuba multiplies each refraction by specular_transmittance, as Candela's
            // tint does (which thin sheets lack).
            let tint = if thin {
                unit_only(ctx, node, "specular_transmittance")?;
                TextureDesc::Constant(Vec3::ONE)
            } else {
                ctx.texture(node, "specular_transmittance", Vec3::ONE)?
            };
            BsdfDesc::Dielectric {
                eta,
                alpha_u,
                alpha_v,
                distribution,
                thin,
                tint,
            }
        }
        "plastic" | "roughplastic" => {
            let eta = ior(node, "int_ior", 1.49)? / ior(node, "ext_ior", 1.000277)?;
            let (alpha_u, alpha_v, distribution) = roughness(node, kind == "roughplastic")?;
            if alpha_u != alpha_v {
                return Err(node.error("roughplastic takes one alpha, not alpha_u and alpha_v"));
            }
            BsdfDesc::Plastic {
                albedo: ctx.texture(node, "diffuse_reflectance", Vec3::splat(0.5))?,
                eta,
                alpha: alpha_u,
                distribution,
                linear: !node.boolean("nonlinear")?.unwrap_or(false),
                specular: specular_reflectance(ctx, node)?,
            }
        }
        "mask" | "normalmap" | "blendbsdf" => return wrapper(ctx, node, true),
        "twosided" => return Err(node.error("twosided inside twosided")),
        _ => {
            ctx.unsupported(node, format!("<{}> is not supported", describe(node)))?;
            ctx.warn(node, "using a grey diffuse in its place");
            return Ok(grey());
        }
    };
    ctx.check_unused(node)?;
    Ok(d)
}

/// `mask`, `normalmap` and `blendbsdf`, which wrap nested BSDFs or `<ref>`s to them
/// (two-sided where the wrapper sits in a `twosided`, so that they keep the sidedness of
/// their place).
///
/// - `mask`: Mitsuba's opacity α (default 0.5) lets a ray pass with probability 1 − α,
///   which is Candela's stochastic alpha ([`AlphaMode::Blend`]).
/// - `normalmap`: Mitsuba's shading normal 2·rgb − 1 in the frame of ∂p/∂u and n × ∂p/∂u,
///   Candela's tangent-space normal map (x along +u, y along +v) on the same uvs.
/// - `blendbsdf`: (1 − w)·first + w·second, Candela's [`BsdfDesc::Mix`].
///
/// Mask opacity and blend weight are read as Mitsuba's `eval_1` reads a texture: see
/// [`scalar`].
fn wrapper(ctx: &mut Ctx, node: &Node, in_two_sided: bool) -> Result<BsdfDesc, LoadError> {
    let kind = node.kind();
    let count = if kind == "blendbsdf" { 2 } else { 1 };
    let mut inner = nested(ctx, node, in_two_sided)?;
    if inner.len() != count {
        let what = if count == 1 { "one" } else { "two" };
        return Err(node.error(format!(
            "{kind} needs exactly {what} nested <bsdf> or <ref>, not {}",
            inner.len()
        )));
    }
    let d = match kind {
        "mask" => {
            let alpha = match scalar(ctx.texture(node, "opacity", Vec3::splat(0.5))?) {
                TextureDesc::Constant(c) => AlphaDesc {
                    mode: AlphaMode::Blend,
                    factor: c.x,
                    texture: None,
                },
                t => AlphaDesc {
                    mode: AlphaMode::Blend,
                    factor: 1.0,
                    texture: Some(t),
                },
            };
            BsdfDesc::Alpha {
                alpha,
                inner: Box::new(inner.remove(0)),
            }
        }
        "normalmap" => {
            if node.prop("normalmap").is_none() {
                return Err(node.error("normalmap needs a <texture name=\"normalmap\">"));
            }
            BsdfDesc::NormalMap {
                map: ctx.texture(node, "normalmap", Vec3::Z)?,
                inner: Box::new(inner.remove(0)),
            }
        }
        _ => {
            let weighted = node.children.iter().any(|c| c.name() == "weight");
            if !weighted {
                return Err(node.error("blendbsdf needs a `weight` (a float or a texture)"));
            }
            let b = inner.pop().expect("two nested");
            BsdfDesc::Mix {
                weight: scalar(ctx.texture(node, "weight", Vec3::ZERO)?),
                a: Box::new(inner.pop().expect("two nested")),
                b: Box::new(b),
            }
        }
    };
    ctx.check_unused(node)?;
    Ok(d)
}

/// The BSDFs nested in a wrapper, in document order: `<bsdf>` children, and `<ref id>`s
/// not naming a texture slot, to BSDFs as they were mapped where they are defined (where
/// the wrapper sits inside a twosided, so does what it refers to).
fn nested(ctx: &mut Ctx, node: &Node, in_two_sided: bool) -> Result<Vec<BsdfDesc>, LoadError> {
    let mut out = Vec::new();
    for c in &node.children {
        if c.tag == "bsdf" {
            c.used.set(true);
            out.push(match in_two_sided {
                true => two_sided(ctx, c)?,
                false => bsdf(ctx, c)?,
            });
        } else if c.tag == "ref" && matches!(c.name(), "" | "bsdf") {
            let d = ref_bsdf(ctx, c)?;
            out.push(if in_two_sided { two_sided_form(d) } else { d });
        }
    }
    Ok(out)
}

/// A texture as Mitsuba's `eval_1` reads it for a scalar parameter (a mask's opacity, a
/// blend's weight), in the first channel that Candela's scalar parameters read. Checked
/// against Mitsuba 3.9.1:
/// - a bitmap gives its luminance (Rec. 709 Y);
/// - a constant colour gives its mean, which is how the RGB variants reduce a colour
///   given inline;
/// - a checkerboard gives its colours the other way round from `eval` (its squares'
///   colours as a reflectance): at uv (0.05, 0.05) under a `to_uv` scale of 4, `eval`
///   is `color0` and `eval_1` is `color1`.
fn scalar(t: TextureDesc) -> TextureDesc {
    let mean = |c: Vec3| Vec3::splat((c.x + c.y + c.z) / 3.0);
    match t {
        TextureDesc::Constant(c) => TextureDesc::Constant(mean(c)),
        TextureDesc::Checker { a, b, uv_transform } => TextureDesc::Checker {
            a: mean(b),
            b: mean(a),
            uv_transform,
        },
        TextureDesc::Image(mut t) => {
            if t.image.pixels.iter().any(|c| c.x != c.y || c.y != c.z) {
                let image = &*t.image;
                t.image = std::sync::Arc::new(ImageDesc {
                    pixels: image
                        .pixels
                        .iter()
                        .map(|&c| Vec3::splat(luminance(c)))
                        .collect(),
                    ..*image
                });
            }
            TextureDesc::Image(t)
        }
    }
}

/// A BSDF as mapped where it was defined, as it reads inside a `twosided`: every
/// one-sided part two-sided, through the wrappers and blends around it (Mitsuba's
/// `twosided` shows each nested BSDF its front from either side).
fn two_sided_form(d: BsdfDesc) -> BsdfDesc {
    match d {
        BsdfDesc::OneSided(inner) => *inner,
        BsdfDesc::Mix { weight, a, b } => BsdfDesc::Mix {
            weight,
            a: Box::new(two_sided_form(*a)),
            b: Box::new(two_sided_form(*b)),
        },
        BsdfDesc::NormalMap { map, inner } => BsdfDesc::NormalMap {
            map,
            inner: Box::new(two_sided_form(*inner)),
        },
        BsdfDesc::Alpha { alpha, inner } => BsdfDesc::Alpha {
            alpha,
            inner: Box::new(two_sided_form(*inner)),
        },
        d => d,
    }
}

/// The BSDF a wrapper's single `<ref id>` (one not naming a texture slot) refers to, as
/// it was mapped where it is defined (one-sided unless it is a twosided); `None` without
/// such a ref.
fn referenced(ctx: &mut Ctx, node: &Node) -> Result<Option<BsdfDesc>, LoadError> {
    node.children
        .iter()
        .find(|c| c.tag == "ref" && matches!(c.name(), "" | "bsdf"))
        .map(|r| ref_bsdf(ctx, r))
        .transpose()
}

/// The BSDF a `<ref id>` names, as it was mapped where it is defined.
fn ref_bsdf(ctx: &mut Ctx, r: &Node) -> Result<BsdfDesc, LoadError> {
    r.used.set(true);
    let id = r.req("id")?;
    let found = ctx.bsdf_ids.get(id).and_then(|name| {
        ctx.desc
            .materials
            .iter()
            .find(|m| &m.name == name)
            .map(|m| m.bsdf.clone())
    });
    found.ok_or_else(|| r.error(format!("no <bsdf> defined before it has the id \"{id}\"")))
}

/// `specular_reflectance`, which Mitsuba's conductors and plastics multiply their Fresnel
/// reflection by, as a colour; a texture there is refused.
fn specular_reflectance(ctx: &mut Ctx, node: &Node) -> Result<Vec3, LoadError> {
    match node.prop("specular_reflectance") {
        Some(p) if p.tag == "texture" => {
            unit_only(ctx, node, "specular_reflectance")?;
            Ok(Vec3::ONE)
        }
        _ => Ok(node.color("specular_reflectance")?.unwrap_or(Vec3::ONE)),
    }
}

/// η and k of a conductor: a `material` preset (default `none`, an ideal mirror), or
/// `eta` and `k` given directly.
fn conductor_ior(ctx: &mut Ctx, node: &Node) -> Result<(Vec3, Vec3), LoadError> {
    let material = node.string("material")?;
    let (eta, k) = (node.color("eta")?, node.color("k")?);
    match (material, eta, k) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
            Err(node.error("give a conductor's material or its eta and k, not both"))
        }
        (None, Some(eta), Some(k)) => Ok((eta, k)),
        (None, Some(_), None) | (None, None, Some(_)) => {
            Err(node.error("a conductor needs both eta and k"))
        }
        // η = 0, k = 1 reflects everything at every angle: Mitsuba's "none".
        (Some("none"), None, None) | (None, None, None) => Ok((Vec3::ZERO, Vec3::ONE)),
        (Some(name), None, None) => match conductor(name) {
            Some(ior) => Ok(ior),
            None => {
                let p = node.prop("material").expect("read just now");
                ctx.unsupported(
                    p,
                    format!(
                        "\"{name}\" is not one of Mitsuba's conductor materials \
                         (Au, Ag, Cu, Al, Cr, W, … or none); give eta and k instead"
                    ),
                )?;
                Ok((Vec3::ZERO, Vec3::ONE))
            }
        },
    }
}

/// Mitsuba's named indices of refraction (its `ior.h`), for `int_ior` and `ext_ior`.
const NAMED_IOR: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

/// An index of refraction given as a number or by one of Mitsuba's names.
fn ior(node: &Node, name: &str, default: f32) -> Result<f32, LoadError> {
    let Some(p) = node.prop(name) else {
        return Ok(default);
    };
    let v = p.req("value")?;
    let ior = match p.tag.as_str() {
        "float" => p.parse_f32(v)?,
        "string" => NAMED_IOR
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(v))
            .map(|&(_, x)| x)
            .ok_or_else(|| p.error(format!("unknown index of refraction \"{v}\"")))?,
        t => {
            return Err(p.error(format!(
                "\"{name}\" must be a <float> or a <string> material name, not <{t}>"
            )))
        }
    };
    if ior <= 0.0 {
        return Err(p.error(format!("\"{name}\" must be positive, got {ior}")));
    }
    Ok(ior)
}

/// The microfacet α along u and v, `alpha` (default 0.1, as Mitsuba) or `alpha_u` and
/// `alpha_v`, and the `distribution` (default beckmann, as Mitsuba); α is zero for the
/// smooth variants, whose distribution does not matter.
fn roughness(node: &Node, rough: bool) -> Result<(f32, f32, MicrofacetDesc), LoadError> {
    if !rough {
        return Ok((0.0, 0.0, MicrofacetDesc::Beckmann));
    }
    let distribution = match node.string("distribution")? {
        None | Some("beckmann") => MicrofacetDesc::Beckmann,
        Some("ggx") => MicrofacetDesc::Ggx,
        Some(d) => {
            let p = node.prop("distribution").expect("read just now");
            return Err(p.error(format!(
                "unknown microfacet distribution \"{d}\" (ggx or beckmann)"
            )));
        }
    };
    // Candela always samples visible normals; the flag changes noise, not the image.
    node.boolean("sample_visible")?;
    let alpha = node.float("alpha")?;
    let (u, v) = (node.float("alpha_u")?, node.float("alpha_v")?);
    let (u, v) = match (alpha, u, v) {
        (Some(a), None, None) => (a, a),
        (None, Some(u), Some(v)) => (u, v),
        (None, None, None) => (0.1, 0.1),
        _ => return Err(node.error("give alpha, or both alpha_u and alpha_v")),
    };
    Ok((u, v, distribution))
}

/// A colour Candela's BSDF cannot scale by: accepted only where it is 1 (the default).
fn unit_only(ctx: &mut Ctx, node: &Node, name: &str) -> Result<(), LoadError> {
    if let Some(p) = node.prop(name) {
        if p.tag == "texture" || node.color(name)? != Some(Vec3::ONE) {
            ctx.unsupported(
                p,
                format!(
                    "\"{name}\" other than 1 is not supported in {}",
                    describe(node)
                ),
            )?;
        }
    }
    Ok(())
}
