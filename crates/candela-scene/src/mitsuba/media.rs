//! `<medium>` and `<phase>`: Mitsuba's `homogeneous` and `heterogeneous` media, their
//! `gridvolume` (a `.vol` file, see [`crate::vol`]) and `constvolume` volumes, and the
//! `isotropic` and `hg` phase functions; a shape's `interior`/`exterior` media and the
//! sensor's medium. Mitsuba's defaults: σt 1, albedo 0.75, scale 1, HG g 0.8.

use std::sync::Arc;

use candela_core::desc::{
    GridDesc, MediumDesc, MediumKindDesc, PhaseDesc, ShapeMediaDesc, VolumeDesc,
};
use glam::{Mat4, Vec3};

use super::parse::Node;
use super::{describe, transform, Ctx};
use crate::LoadError;

/// A `<medium>`, top-level or nested: added to the description; returns its name.
pub(crate) fn medium(ctx: &mut Ctx, node: &Node) -> Result<String, LoadError> {
    node.used.set(true);
    let name = node
        .attr("id")
        .map_or_else(|| ctx.fresh_name(node), str::to_string);
    if ctx.desc.media.media.iter().any(|m| m.name == name) {
        return Err(node.error(format!("id \"{name}\" is used twice")));
    }
    let scale = node.float("scale")?.unwrap_or(1.0);
    let kind = match node.kind() {
        "homogeneous" => {
            let sigma_t = node.color("sigma_t")?.unwrap_or(Vec3::ONE);
            let albedo = constant_volume(ctx, node, "albedo", Vec3::splat(0.75))?;
            MediumKindDesc::Homogeneous {
                sigma_t: sigma_t * scale,
                albedo,
            }
        }
        "heterogeneous" => heterogeneous(ctx, node, scale)?,
        _ => {
            ctx.unsupported(
                node,
                format!(
                    "<{}> is not supported (homogeneous and heterogeneous are)",
                    describe(node)
                ),
            )?;
            // Under --lenient: vacuum, so that what refers to it still loads.
            MediumKindDesc::Homogeneous {
                sigma_t: Vec3::ZERO,
                albedo: Vec3::ZERO,
            }
        }
    };
    let mut phase = PhaseDesc::Isotropic;
    for p in node.plugins("phase") {
        phase = match p.kind() {
            "isotropic" => PhaseDesc::Isotropic,
            "hg" => PhaseDesc::HenyeyGreenstein {
                g: p.float("g")?.unwrap_or(0.8),
            },
            _ => {
                return Err(p.error(format!(
                    "<{}> is not supported (isotropic and hg are)",
                    describe(p)
                )))
            }
        };
        ctx.check_unused(p)?;
    }
    // Sampling choices that change the noise, not the expectation.
    for knob in ["sample_emitters", "has_spectral_extinction"] {
        if let Some(p) = node.prop(knob) {
            p.used.set(true);
        }
    }
    ctx.check_unused(node)?;
    ctx.desc.media.media.push(MediumDesc {
        name: name.clone(),
        kind,
        phase,
        span: node.span.clone(),
    });
    Ok(name)
}

/// The `volume` child called `name`, marked as used.
fn volume<'a>(node: &'a Node, name: &str) -> Option<&'a Node> {
    let v = node
        .children
        .iter()
        .find(|c| c.tag == "volume" && c.name() == name)?;
    v.used.set(true);
    Some(v)
}

/// A property that is a colour or a `constvolume`; `default` where absent.
fn constant_volume(
    ctx: &mut Ctx,
    node: &Node,
    name: &str,
    default: Vec3,
) -> Result<Vec3, LoadError> {
    match volume(node, name) {
        Some(v) if v.kind() == "constvolume" => {
            let c = v.color("value")?.unwrap_or(Vec3::ONE);
            ctx.check_unused(v)?;
            Ok(c)
        }
        Some(v) => Err(v.error(format!(
            "{name} of a {} medium must be a colour or a constvolume, not <{}>",
            node.kind(),
            describe(v)
        ))),
        None => Ok(node.color(name)?.unwrap_or(default)),
    }
}

/// A `heterogeneous` medium: `sigma_t` a `gridvolume` (or a constant, which makes it
/// homogeneous), `albedo` a colour, `constvolume` or a `gridvolume` placed like σt's.
fn heterogeneous(ctx: &mut Ctx, node: &Node, scale: f32) -> Result<MediumKindDesc, LoadError> {
    let sigma_t = match volume(node, "sigma_t") {
        Some(v) if v.kind() == "gridvolume" => grid_volume(ctx, v)?,
        _ => {
            let sigma_t = constant_volume(ctx, node, "sigma_t", Vec3::ONE)?;
            let albedo = constant_volume(ctx, node, "albedo", Vec3::splat(0.75))?;
            return Ok(MediumKindDesc::Homogeneous {
                sigma_t: sigma_t * scale,
                albedo,
            });
        }
    };
    let albedo = match volume(node, "albedo") {
        Some(v) if v.kind() == "gridvolume" => {
            let (grid, to_world) = grid_volume(ctx, v)?;
            if to_world != sigma_t.1 {
                return Err(v.error(
                    "an albedo grid must be placed as sigma_t's (the same to_world and box)",
                ));
            }
            VolumeDesc::Grid(grid)
        }
        _ => VolumeDesc::Constant(constant_volume(ctx, node, "albedo", Vec3::splat(0.75))?),
    };
    Ok(MediumKindDesc::Grid {
        sigma_t: sigma_t.0,
        albedo,
        scale,
        to_world: sigma_t.1,
    })
}

/// A `gridvolume`: the grid of its `.vol` file and the transform of its unit cube to
/// the world (`to_world`, after the file's box where `use_grid_bbox` is set).
fn grid_volume(ctx: &mut Ctx, v: &Node) -> Result<(Arc<GridDesc>, Mat4), LoadError> {
    let file = v
        .string("filename")?
        .ok_or_else(|| v.error("a gridvolume needs a filename"))?;
    let vol = crate::vol::load_vol(&ctx.base.join(file))?;
    let mut to_world = match v.prop("to_world") {
        Some(t) if t.tag == "transform" => transform::transform(t)?,
        Some(t) => return Err(t.error("to_world must be a <transform>")),
        None => Mat4::IDENTITY,
    };
    if v.boolean("use_grid_bbox")?.unwrap_or(false) {
        to_world = to_world
            * Mat4::from_translation(vol.bbox_min)
            * Mat4::from_scale(vol.bbox_max - vol.bbox_min);
    }
    if let Some(f) = v.string("filter_type")? {
        if f != "trilinear" {
            let p = v.prop("filter_type").expect("read just now");
            return Err(p.error(format!(
                "filter_type \"{f}\" is not supported (trilinear is)"
            )));
        }
    }
    if let Some(w) = v.string("wrap_mode")? {
        if w != "clamp" {
            let p = v.prop("wrap_mode").expect("read just now");
            return Err(p.error(format!("wrap_mode \"{w}\" is not supported (clamp is)")));
        }
    }
    if let Some(p) = v.prop("raw") {
        p.used.set(true);
    }
    ctx.check_unused(v)?;
    Ok((Arc::new(vol.grid), to_world))
}

/// The media of a shape: `<ref name="interior|exterior" id>` or nested `<medium
/// name="…">`, recorded for shape `index` (the one about to be added).
pub(crate) fn shape_media(ctx: &mut Ctx, node: &Node, index: usize) -> Result<(), LoadError> {
    let mut sides = [None, None];
    for c in &node.children {
        let side = match c.name() {
            "interior" => 0,
            "exterior" => 1,
            _ => continue,
        };
        let name = match c.tag.as_str() {
            "ref" => referenced(ctx, c)?,
            "medium" => medium(ctx, c)?,
            _ => continue,
        };
        c.used.set(true);
        sides[side] = Some(name);
    }
    if sides.iter().any(Option::is_some) {
        let [interior, exterior] = sides;
        ctx.desc.media.shapes.push(ShapeMediaDesc {
            shape: index,
            interior,
            exterior,
            span: node.span.clone(),
        });
    }
    Ok(())
}

/// The sensor's medium: a `<ref>` to a medium or a nested `<medium>`.
pub(crate) fn sensor_medium(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    for c in &node.children {
        let name = match c.tag.as_str() {
            "ref" if ctx.medium_ids.contains(c.attr("id").unwrap_or("")) => referenced(ctx, c)?,
            "medium" => medium(ctx, c)?,
            _ => continue,
        };
        c.used.set(true);
        ctx.desc.media.camera = Some(name);
        ctx.desc.media.camera_span = c.span.clone();
    }
    Ok(())
}

/// The medium a `<ref id>` names.
fn referenced(ctx: &Ctx, r: &Node) -> Result<String, LoadError> {
    let id = r.req("id")?;
    if ctx.medium_ids.contains(id) {
        Ok(id.to_string())
    } else {
        Err(r.error(format!("no <medium> has the id \"{id}\"")))
    }
}
