//! `<bsdf>`: Mitsuba's BSDFs to Candela materials. Mitsuba's reflective BSDFs are
//! one-sided (black from the back) unless wrapped in `twosided`; Candela's are two-sided,
//! so an unwrapped one becomes [`BsdfDesc::OneSided`].

use candela_core::desc::{BsdfDesc, MaterialDesc, TextureDesc};
use glam::Vec3;

use super::parse::Node;
use super::{describe, Ctx};
use crate::LoadError;

/// BSDFs that Candela will map once the materials work lands.
const PLANNED: &[&str] = &[
    "conductor",
    "roughconductor",
    "dielectric",
    "roughdielectric",
    "thindielectric",
    "plastic",
    "roughplastic",
];

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

/// The grey one-sided diffuse that Mitsuba gives a shape without a BSDF.
pub(crate) fn default_material(ctx: &mut Ctx) -> String {
    const NAME: &str = "mitsuba-default-diffuse";
    if !ctx.desc.materials.iter().any(|m| m.name == NAME) {
        ctx.desc.materials.push(MaterialDesc {
            name: NAME.to_string(),
            bsdf: BsdfDesc::OneSided(Box::new(grey())),
            span: candela_core::desc::Span::code(),
        });
    }
    NAME.to_string()
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
            [] => return Err(node.error("twosided needs a nested <bsdf>")),
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
    Ok(match two_sided(ctx, node)? {
        BsdfDesc::Diffuse { albedo } => BsdfDesc::OneSided(Box::new(BsdfDesc::Diffuse { albedo })),
        other => other,
    })
}

/// The BSDF as Candela's (two-sided) material.
fn two_sided(ctx: &mut Ctx, node: &Node) -> Result<BsdfDesc, LoadError> {
    let d = match node.kind() {
        "diffuse" => BsdfDesc::Diffuse {
            albedo: TextureDesc::Constant(ctx.color(node, "reflectance", Vec3::splat(0.5))?),
        },
        "twosided" => return Err(node.error("twosided inside twosided")),
        k => {
            let why = if PLANNED.contains(&k) {
                "is not supported yet"
            } else {
                "is not supported"
            };
            ctx.unsupported(node, format!("<{}> {why}", describe(node)))?;
            ctx.warn(node, "using a grey diffuse in its place");
            return Ok(grey());
        }
    };
    ctx.check_unused(node)?;
    Ok(d)
}
