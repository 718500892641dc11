//! `<sensor>` (with its `<film>` and `<sampler>`) and `<integrator>`: the camera and the
//! render settings.

use candela_core::desc::{
    ApertureDesc, ApertureSizeDesc, CameraDesc, FocusDesc, LensDesc, PixelFilterDesc, SamplerKind,
};
use glam::{Mat4, Vec3};

use super::parse::Node;
use super::{describe, transform, Ctx};
use crate::LoadError;

/// Candela's depth for Mitsuba's "unlimited" (−1); Russian roulette ends paths long
/// before it.
const UNLIMITED_DEPTH: u32 = 1024;

/// Mitsuba's `max_depth` m as Candela's `max_depth`. Mitsuba counts path vertices after
/// the camera, so m = 1 shows emitters only (Candela's 0) and m = 2 is direct light
/// (Candela's 1); −1 is unlimited. m = 0 renders black in Mitsuba, which Candela cannot
/// express.
pub fn candela_max_depth(m: i64) -> Result<u32, String> {
    match m {
        -1 => Ok(UNLIMITED_DEPTH),
        1.. => Ok(u32::try_from(m - 1)
            .unwrap_or(UNLIMITED_DEPTH)
            .min(UNLIMITED_DEPTH)),
        0 => Err("max_depth 0 (a black image) is not supported; use 1 or more".into()),
        _ => Err(format!(
            "max_depth {m} is invalid: use -1 (unlimited) or 1 or more"
        )),
    }
}

/// The integrators whose image is the path tracer's in expectation, with the `max_depth`
/// each takes by default (Mitsuba 3.9.1): the volumetric ones (a scene with media renders
/// with Candela's volumetric path tracer whichever is named), the particle tracer, and the
/// differentiable ones, whose primal image is a path tracer's.
const PATH_INTEGRATORS: &[(&str, i64)] = &[
    ("path", -1),
    ("volpath", -1),
    ("volpathmis", -1),
    ("ptracer", -1),
    ("prb", 6),
    ("prb_basic", 6),
    ("prb_projective", 6),
];

/// `<integrator>`: any of [`PATH_INTEGRATORS`], with `max_depth`, `rr_depth` and
/// `hide_emitters`, or `direct`/`direct_projective`, direct light alone (Mitsuba's
/// `max_depth` 2). Their own sampling knobs change the noise and not the expectation, so
/// they are read and, away from their defaults, warned of.
pub(crate) fn integrator(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    let kind = node.kind();
    if kind == "aov" {
        return super::aov::aov_integrator(ctx, node);
    }
    let direct = matches!(kind, "direct" | "direct_projective");
    let default_depth = match PATH_INTEGRATORS.iter().find(|(name, _)| *name == kind) {
        Some(&(_, depth)) => depth,
        None if direct => 2,
        None => {
            let known: Vec<&str> = PATH_INTEGRATORS.iter().map(|(name, _)| *name).collect();
            return ctx.unsupported(
                node,
                format!(
                    "<{}> is not supported (only {} and direct are)",
                    describe(node),
                    known.join(", ")
                ),
            );
        }
    };
    // `direct` has no max_depth: one given is left unread, and so refused below.
    let depth = if direct {
        None
    } else {
        node.integer("max_depth")?
    };
    let m = depth.unwrap_or(default_depth);
    ctx.desc.render.max_depth = candela_max_depth(m).map_err(|e| match node.prop("max_depth") {
        Some(p) => p.error(e),
        None => node.error(e),
    })?;
    if let Some(rr) = node.integer("rr_depth")? {
        let p = node.prop("rr_depth").expect("read just now");
        // Both count scattering events, so Mitsuba's value carries over as it is.
        ctx.desc.render.rr_depth = u32::try_from(rr)
            .map_err(|_| p.error(format!("rr_depth {rr} is invalid: use 0 or more")))?;
    }
    ctx.desc.render.hide_emitters = node.boolean("hide_emitters")?.unwrap_or(false);
    // Sample counts per pass or per shading point (one of each in Candela).
    for knob in [
        "emitter_samples",
        "bsdf_samples",
        "shading_samples",
        "samples_per_pass",
        "sppc",
        "sppp",
        "sppi",
    ] {
        if let Some(p) = node.prop(knob) {
            if !matches!(p.attr("value"), Some("1") | Some("-1")) {
                ctx.warn(
                    p,
                    format!(
                        "{knob} is Mitsuba's sampling choice and does not change the \
                         expected image; Candela renders {kind} as its path tracer"
                    ),
                );
            }
        }
    }
    ctx.check_unused(node)
}

pub(crate) fn sensor(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    match node.kind() {
        "perspective" | "thinlens" | "orthographic" => {}
        _ => return ctx.unsupported(node, format!("<{}> is not supported", describe(node))),
    }
    for f in node.plugins("film") {
        film(ctx, f)?;
    }
    for s in node.plugins("sampler") {
        sampler(ctx, s)?;
    }
    super::media::sensor_medium(ctx, node)?;
    let to_world = match node.prop("to_world") {
        Some(t) => transform::transform(t)?,
        None => Mat4::IDENTITY,
    };
    let r = &ctx.desc.render;
    let aspect = r.width as f32 / r.height as f32;
    let fov_y_deg = if node.kind() == "orthographic" {
        CameraDesc::default().fov_y_deg
    } else {
        let (fov, axis) = field_of_view(node)?;
        vertical_fov(fov, axis, aspect).ok_or_else(|| {
            node.error(format!(
                "fov_axis \"{axis}\" is not one of x, y, diagonal, smaller, larger"
            ))
        })?
    };
    // Candela does not clip. Mitsuba's defaults (0.01 and 10⁴) rarely cut anything; other
    // values may be meant to, so those are pointed out.
    let near = node.float("near_clip")?.filter(|&v| v > 0.01);
    let far = node.float("far_clip")?.filter(|&v| v < 1e4);
    for (clip, cut, side) in [
        ("near_clip", near, "nearer than"),
        ("far_clip", far, "beyond"),
    ] {
        if let Some(v) = cut {
            let p = node.prop(clip).expect("read just now");
            ctx.warn(
                p,
                format!("{clip} {v}: Candela does not clip, so geometry {side} it is visible"),
            );
        }
    }
    ctx.desc.camera = camera(ctx, node, to_world, fov_y_deg)?;
    match node.kind() {
        "thinlens" => ctx.desc.camera.lens = Some(thin_lens(node)?),
        "orthographic" => {
            ctx.desc.camera.ortho_height = Some(ortho_height(node, to_world, aspect)?)
        }
        _ => {}
    }
    ctx.check_unused(node)
}

/// The view height of Mitsuba's `orthographic` sensor, whose camera space spans
/// [−1, 1] across the film's width and [−1/aspect, 1/aspect] up it, scaled by `to_world`.
/// Pixels stay square only where it scales x and y alike.
fn ortho_height(node: &Node, to_world: Mat4, aspect: f32) -> Result<f32, LoadError> {
    let sx = to_world.transform_vector3(Vec3::X).length();
    let sy = to_world.transform_vector3(Vec3::Y).length();
    if (sx - sy).abs() > 1e-4 * sx.max(sy) {
        return Err(node.error(format!(
            "an orthographic sensor's to_world scales x by {sx} and y by {sy}: Candela's pixels \
             are square, so both must be the same"
        )));
    }
    Ok(2.0 * sx / aspect)
}

/// The sensor's `fov` (degrees) and the axis it spans. As in Mitsuba's `parse_fov`, a
/// `focal_length` ("50mm" when neither it nor `fov` is given) is a 35 mm film
/// equivalent: the fov spans the film's diagonal, 2·atan(√(36² + 24²)/(2f)), and
/// `fov_axis` is not read (Mitsuba reports it as unused).
pub(crate) fn field_of_view(node: &Node) -> Result<(f32, &str), LoadError> {
    let Some(p) = node.prop("focal_length") else {
        return Ok(match node.float("fov")? {
            Some(fov) => (fov, node.string("fov_axis")?.unwrap_or("x")),
            None => (focal_length_fov(50.0), "diagonal"),
        });
    };
    if node.prop("fov").is_some() {
        return Err(node.error("give a sensor's fov or its focal_length, not both"));
    }
    let v = p.typed(&["string", "float"])?.req("value")?;
    let mm = v.trim().strip_suffix("mm").unwrap_or(v.trim());
    match mm.parse::<f32>() {
        Ok(f) if f > 0.0 && f.is_finite() => Ok((focal_length_fov(f), "diagonal")),
        _ => Err(p.error(format!(
            "focal_length \"{v}\" is not a positive length in millimetres (e.g. \"50mm\")"
        ))),
    }
}

/// The diagonal fov (degrees) of a lens of focal length `mm` on 36 × 24 mm film.
fn focal_length_fov(mm: f32) -> f32 {
    let diagonal = (36.0f32 * 36.0 + 24.0 * 24.0).sqrt();
    (2.0 * (diagonal / (2.0 * mm)).atan()).to_degrees()
}

/// Mitsuba's camera frame looks along +z with +y up and the image's right along −x (see
/// `transform::look_at`); Candela's camera is position, target and up.
fn camera(ctx: &mut Ctx, node: &Node, m: Mat4, fov_y_deg: f32) -> Result<CameraDesc, LoadError> {
    let position = m.transform_point3(Vec3::ZERO);
    let forward = m.transform_vector3(Vec3::Z).normalize_or_zero();
    let up = m.transform_vector3(Vec3::Y).normalize_or_zero();
    if forward == Vec3::ZERO || up == Vec3::ZERO {
        return Err(node.error("the sensor's to_world is singular"));
    }
    // Candela's image right is forward × up; Mitsuba's is the frame's −x. They agree
    // unless the transform mirrors.
    if m.determinant() < 0.0 {
        ctx.unsupported(
            node,
            "the sensor's to_world mirrors (negative determinant); the image would be flipped"
                .into(),
        )?;
    }
    Ok(CameraDesc {
        position,
        look_at: position + forward,
        up,
        fov_y_deg,
        span: node.span.clone(),
        ..CameraDesc::default()
    })
}

/// Mitsuba's `thinlens`: a disc aperture of `aperture_radius` (scene units) focused on the
/// plane `focus_distance` along the view axis, as Candela's thin lens.
fn thin_lens(node: &Node) -> Result<LensDesc, LoadError> {
    let get = |name: &str| {
        node.float(name)?
            .ok_or_else(|| node.error(format!("thinlens needs \"{name}\"")))
    };
    let (radius, focus) = (get("aperture_radius")?, get("focus_distance")?);
    if radius < 0.0 || focus <= 0.0 {
        return Err(node.error("thinlens needs aperture_radius >= 0 and focus_distance > 0"));
    }
    Ok(LensDesc {
        focus: FocusDesc::Distance(focus),
        size: ApertureSizeDesc::Radius(radius),
        aperture: ApertureDesc::Disc,
    })
}

/// The vertical field of view (degrees) of a Mitsuba `fov` along `axis` on an image of
/// width/height `aspect`: tan(fov_y/2) = tan(fov/2)·(height/extent along the axis).
pub(crate) fn vertical_fov(fov: f32, axis: &str, aspect: f32) -> Option<f32> {
    let t = (fov.to_radians() * 0.5).tan();
    let ty = match axis {
        "x" => t / aspect,
        "y" => t,
        "diagonal" => t / (1.0 + aspect * aspect).sqrt(),
        "smaller" if aspect >= 1.0 => t,
        "smaller" => t / aspect,
        "larger" if aspect >= 1.0 => t / aspect,
        "larger" => t,
        _ => return None,
    };
    Some((2.0 * ty.atan()).to_degrees())
}

fn film(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    if node.kind() != "hdrfilm" {
        return ctx.unsupported(node, format!("<{}> is not supported", describe(node)));
    }
    let dim = |name: &str, default: u32| -> Result<u32, LoadError> {
        match node.integer(name)? {
            None => Ok(default),
            Some(v) if v > 0 && v <= 1 << 16 => Ok(v as u32),
            Some(v) => Err(node.error(format!("film {name} {v} is out of range"))),
        }
    };
    ctx.desc.render.width = dim("width", 768)?;
    ctx.desc.render.height = dim("height", 576)?;
    // Output encoding: Candela picks it from the output file's extension.
    for s in ["file_format", "pixel_format", "component_format"] {
        node.string(s)?;
    }
    node.boolean("banner")?;
    // Mitsuba's default filter is a Gaussian of σ = 0.5 pixels, truncated at 4σ.
    let gaussian = PixelFilterDesc::Gaussian {
        stddev: 0.5,
        radius: 2.0,
    };
    ctx.desc.render.filter = gaussian;
    for f in node.plugins("rfilter") {
        ctx.desc.render.filter = match f.kind() {
            "box" => PixelFilterDesc::Box,
            "tent" => PixelFilterDesc::Tent {
                radius: positive(f, "radius", 1.0)?,
            },
            "gaussian" => {
                let stddev = positive(f, "stddev", 0.5)?;
                PixelFilterDesc::Gaussian {
                    stddev,
                    radius: 4.0 * stddev,
                }
            }
            _ => {
                ctx.unsupported(f, format!("<{}> is not supported", describe(f)))?;
                gaussian
            }
        };
        ctx.check_unused(f)?;
    }
    ctx.check_unused(node)
}

fn sampler(ctx: &mut Ctx, node: &Node) -> Result<(), LoadError> {
    match node.kind() {
        "independent" => ctx.desc.render.sampler = SamplerKind::Independent,
        "stratified" | "multijitter" | "orthogonal" | "ldsampler" => {
            ctx.desc.render.sampler = SamplerKind::default();
            ctx.warn(
                node,
                "Candela uses its own stratified sampler (Sobol', the first bounce's \
                 direction from a CMJ pattern) instead; the image converges to the same result",
            )
        }
        _ => return ctx.unsupported(node, format!("<{}> is not supported", describe(node))),
    }
    if let Some(n) = node.integer("sample_count")? {
        if n < 1 || n > u32::MAX as i64 {
            return Err(node.error(format!("sample_count {n} is out of range")));
        }
        ctx.desc.render.spp = n as u32;
    } else {
        ctx.desc.render.spp = 4;
    }
    if let Some(seed) = node.integer("seed")? {
        ctx.desc.render.seed = seed as u64;
    }
    node.boolean("jitter")?;
    ctx.check_unused(node)
}

/// A positive float property of a filter, with its default.
fn positive(node: &Node, name: &str, default: f32) -> Result<f32, LoadError> {
    match node.float(name)? {
        None => Ok(default),
        Some(v) if v > 0.0 => Ok(v),
        Some(v) => Err(node.error(format!("{name} must be positive, got {v}"))),
    }
}
