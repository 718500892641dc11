//! From a [`SceneDesc`] to a render-time [`Scene`]: validation (every reference resolves,
//! every number is finite, every mesh is non-empty) and the canonical forms the renderer
//! needs (world-space meshes, one light per emitting triangle, the BVH, the light sampler).

use std::collections::HashMap;
use std::fmt;
use std::sync::Arc;

use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::accel::{
    Accel, AccelLayout, Geometry, LeafLayout, NodeLayout, Shape, Simd, TriangleMesh,
};
use crate::alpha::{AlphaMask, AlphaMode};
use crate::bsdf::{
    Conductor, ConductorFresnel, Dielectric, Lobe, Microfacet, MicrofacetDistribution, Plastic,
    ThinDielectric,
};
use crate::camera::Camera;
use crate::desc::{
    ApertureDesc, ApertureSizeDesc, BsdfDesc, CameraDesc, EnvironmentDesc, EnvironmentMapDesc,
    FocusDesc, GeometryDesc, ImageDesc, LensDesc, MeshDesc, MicrofacetDesc, PixelFilterDesc,
    SceneDesc, ShapeDesc, Span, TextureDesc,
};
use crate::filter::PixelFilter;
use crate::geometry::Aabb;
use crate::instance::{Instance, Instances, Transform};
use crate::light::envmap::{Cubemap, Equirect, Image};
use crate::light::{EnvironmentLight, EnvironmentMap, Light, LightId, SphereLight};
use crate::light_sampler::LightSampler;
use crate::material::{Material, MaterialId, Texture};
use crate::scene::{Mesh, Prim, Scene, Sphere};
use crate::texture::ImageTexture;

mod lights;
mod media;

pub use lights::LUMENS_PER_WATT;

/// A description that cannot be built, with the place that caused it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BuildError {
    pub span: Span,
    pub message: String,
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.span, self.message)
    }
}

impl std::error::Error for BuildError {}

fn err<T>(span: &Span, message: impl Into<String>) -> Result<T, BuildError> {
    Err(BuildError {
        span: span.clone(),
        message: message.into(),
    })
}

fn check_finite(span: &Span, what: &str, values: &[f32]) -> Result<(), BuildError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        err(span, format!("{what} must be finite"))
    }
}

fn check_color(span: &Span, what: &str, c: Vec3) -> Result<(), BuildError> {
    check_finite(span, what, &c.to_array())?;
    if c.min_element() < 0.0 {
        return err(span, format!("{what} must not be negative"));
    }
    Ok(())
}

/// The most pixels an image may have: 2²⁶ (8192 × 8192), whose film takes 4.8 GB. A
/// resolution is two numbers in a small file, so without a cap a scene of a hundred bytes
/// could ask for terabytes.
pub const MAX_PIXELS: u64 = 1 << 26;

/// Checks a resolution: not empty, at most [`MAX_PIXELS`].
pub fn check_resolution(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("resolution {width}x{height} is empty"));
    }
    if width as u64 * height as u64 > MAX_PIXELS {
        return Err(format!(
            "resolution {width}x{height} has more than {MAX_PIXELS} pixels (8192x8192)"
        ));
    }
    Ok(())
}

/// Validates a description and builds the scene.
pub fn build(desc: &SceneDesc) -> Result<Scene, BuildError> {
    build_taking(desc, Vec::new())
}

/// [`build`], consuming the description: each mesh that one shape alone holds is moved
/// into the scene rather than copied (and transformed to world space in place), so that
/// a big scene's geometry is in memory once, not twice.
pub fn build_owned(mut desc: SceneDesc) -> Result<Scene, BuildError> {
    let taken = desc
        .shapes
        .iter_mut()
        .map(|shape| match &mut shape.geometry {
            GeometryDesc::Mesh(m) => Arc::get_mut(m).map(std::mem::take),
            _ => None,
        })
        .collect();
    build_taking(&desc, taken)
}

/// [`build`] with the meshes of `taken[shape]`, where given, in place of the
/// description's (which [`build_owned`] has emptied).
fn build_taking(desc: &SceneDesc, mut taken: Vec<Option<MeshDesc>>) -> Result<Scene, BuildError> {
    let r = &desc.render;
    if let Err(m) = check_resolution(r.width, r.height) {
        return err(&Span::code(), m);
    }
    if r.spp == 0 {
        return err(&Span::code(), "spp must be at least 1");
    }
    let filter = build_filter(r.filter)?;
    let camera = build_camera(desc)?;

    let mut materials = Vec::with_capacity(desc.materials.len());
    let mut alphas = Vec::with_capacity(desc.materials.len());
    let mut material_ids: HashMap<&str, MaterialId> = HashMap::new();
    for m in &desc.materials {
        if material_ids
            .insert(&m.name, MaterialId(materials.len() as u32))
            .is_some()
        {
            return err(&m.span, format!("material \"{}\" is defined twice", m.name));
        }
        materials.push(build_material(&m.bsdf, &m.span)?);
        alphas.push(build_alpha(&m.bsdf, &m.span)?);
    }

    let mut meshes = Vec::new();
    let mut spheres = Vec::new();
    let mut lights = Vec::new();
    lights::check_emission_profiles(desc)?;
    let shared = shared_meshes(desc);
    // Object-space mesh of each shared `MeshDesc`, by its address.
    let mut object_mesh: HashMap<*const MeshDesc, u32> = HashMap::new();
    let mut object_meshes = Vec::new();
    let mut instances = Vec::new();
    let mut media = media::MediaBuilder::new(desc)?;
    for (shape_index, shape) in desc.shapes.iter().enumerate() {
        let Some(&material) = material_ids.get(shape.material.as_str()) else {
            return err(
                &shape.span,
                format!("unknown material \"{}\"", shape.material),
            );
        };
        let material = media.shape_material(shape_index, material, &mut materials, &mut alphas);
        if let Some(le) = shape.emission {
            check_color(&shape.span, "emission", le)?;
        }
        check_finite(&shape.span, "transform", &shape.transform.to_cols_array())?;
        if shape.transform.determinant() == 0.0 {
            return err(&shape.span, "transform is singular");
        }
        let emission = shape.emission.filter(|le| *le != Vec3::ZERO);
        let emission_texture = match &shape.emission_texture {
            None => None,
            Some(_) if shape.emission.is_none() => {
                return err(&shape.span, "an emission texture needs an `emission`");
            }
            Some(_) if matches!(shape.geometry, GeometryDesc::Sphere { .. }) => {
                return err(
                    &shape.span,
                    "emission textures are not supported on spheres",
                );
            }
            Some(t) => Some(Arc::new(build_texture(t, &shape.span, "emission texture")?)),
        };
        match &shape.geometry {
            GeometryDesc::Sphere { .. } if alphas[material.0 as usize].is_some() => {
                return err(
                    &shape.span,
                    format!(
                        "material \"{}\" has alpha, which only meshes support",
                        shape.material
                    ),
                );
            }
            GeometryDesc::Sphere { center, radius } => {
                let sphere = build_sphere(shape, *center, *radius, material)?;
                let light = emission.map(|le| {
                    lights.push(Light::Sphere(SphereLight {
                        center: sphere.center,
                        radius: sphere.radius,
                        le,
                        inward: sphere.flip_normals,
                    }));
                    LightId(lights.len() as u32 - 1)
                });
                spheres.push(Sphere { light, ..sphere });
            }
            GeometryDesc::Mesh(m) if emission.is_none() && shared.contains(&Arc::as_ptr(m)) => {
                let next = object_meshes.len() as u32;
                let mesh = *object_mesh.entry(Arc::as_ptr(m)).or_insert(next);
                if mesh == next {
                    validate_mesh(m, &shape.span)?;
                    object_meshes.push(object_space(MeshDesc::clone(m), material));
                }
                instances.push(Instance {
                    mesh,
                    transform: Transform::new(shape.transform),
                    material,
                    flip_normals: shape.flip_normals,
                    alpha: alphas[material.0 as usize].clone(),
                });
            }
            geometry => {
                let local = match geometry {
                    GeometryDesc::Mesh(m) => {
                        let own = taken.get_mut(shape_index).and_then(Option::take);
                        let m = own.unwrap_or_else(|| MeshDesc::clone(m));
                        validate_mesh(&m, &shape.span)?;
                        m
                    }
                    GeometryDesc::Rectangle => rectangle(),
                    GeometryDesc::Disk => disk(128),
                    GeometryDesc::Cube => cube(),
                    GeometryDesc::Sphere { .. } => unreachable!("handled above"),
                };
                let mut mesh = to_world(local, shape.transform, material);
                mesh.flip_normals = shape.flip_normals;
                mesh.alpha = alphas[material.0 as usize].clone();
                if let Some(le) = emission {
                    let texture = emission_texture.as_ref();
                    lights::triangle_lights(desc, shape_index, &mut mesh, le, texture, &mut lights);
                }
                mesh.cache_face_normals();
                meshes.push(mesh);
            }
        }
    }

    for l in &desc.lights {
        lights.push(lights::build_light(l)?);
    }

    let triangles: usize = meshes.iter().map(|m| m.indices.len()).sum();
    let mut prims = Vec::with_capacity(triangles + spheres.len());
    for (mi, m) in meshes.iter().enumerate() {
        prims.extend((0..m.indices.len() as u32).map(|tri| Prim::Triangle {
            mesh: mi as u32,
            tri,
        }));
    }
    prims.extend((0..spheres.len() as u32).map(Prim::Sphere));
    // Each primitive's shape, made when asked rather than held in an array beside the
    // meshes.
    let shape = |i: u32| match prims[i as usize] {
        Prim::Triangle { mesh, tri } => Shape::Triangle(meshes[mesh as usize].vertices(tri)),
        Prim::Sphere(s) => Shape::Sphere {
            center: spheres[s as usize].center,
            radius: spheres[s as usize].radius,
        },
    };
    // The accelerator reads the meshes' own arrays; only triangles of alpha-masked meshes
    // pay for the filter.
    let geometry = Geometry::new(
        meshes
            .iter()
            .map(|m| TriangleMesh {
                positions: &m.positions,
                indices: &m.indices,
                filtered: m.alpha.is_some(),
            })
            .collect(),
        spheres.iter().map(|s| (s.center, s.radius)).collect(),
    );
    let layout = AccelLayout {
        nodes: NodeLayout::Full,
        leaves: LeafLayout::choose(r.accel, geometry.len()),
    };
    let accel = Accel::build_geometry(&geometry, Simd::best(), layout);
    let instances = Instances::new(object_meshes, instances, r.accel);
    let bounds = (0..prims.len() as u32)
        .map(|i| shape(i).bounds())
        .chain((!instances.is_empty()).then(|| instances.bounds()))
        .reduce(Aabb::union);
    let scene_radius = bounds.map_or(1.0, |b| (0.5 * (b.max - b.min).length()).max(1e-3));
    for light in &mut lights {
        light.set_lamp_sampling(r.lamp_sampling);
        if let Light::Directional(d) = light {
            d.scene_radius = scene_radius;
        }
    }
    if let Some(env) = &desc.environment {
        lights.push(Light::Environment(build_environment(env, scene_radius)?));
    }
    let light_sampler = LightSampler::new(r.light_sampler, r.ris_candidates, &lights);
    let infinite_lights = lights
        .iter()
        .enumerate()
        .filter(|(_, l)| l.is_infinite())
        .map(|(i, _)| LightId(i as u32))
        .collect();

    let materials_len = materials.len();
    Ok(Scene {
        camera,
        filter,
        settings: r.clone(),
        meshes,
        spheres,
        materials,
        lights,
        infinite_lights,
        light_sampler,
        prims,
        accel,
        instances,
        media: media.finish(materials_len),
    })
}

/// The meshes to instance: those that two or more non-emitting shapes hold (the same
/// `Arc`). A mesh placed once gains nothing from a BLAS of its own and would cost every
/// ray a detour through the TLAS, so it is flattened into world space with the rest;
/// emitting shapes stay flattened because each of their triangles is an area light in
/// world space.
fn shared_meshes(desc: &SceneDesc) -> std::collections::HashSet<*const MeshDesc> {
    let mut count: HashMap<*const MeshDesc, u32> = HashMap::new();
    for shape in &desc.shapes {
        if let GeometryDesc::Mesh(m) = &shape.geometry {
            if shape.emission.is_none_or(|le| le == Vec3::ZERO) {
                *count.entry(Arc::as_ptr(m)).or_default() += 1;
            }
        }
    }
    count
        .into_iter()
        .filter(|&(_, n)| n >= 2)
        .map(|(m, _)| m)
        .collect()
}

fn check_image(span: &Span, what: &str, img: &ImageDesc) -> Result<(), BuildError> {
    if img.width == 0 || img.height == 0 {
        return err(
            span,
            format!("{what} is empty ({}x{})", img.width, img.height),
        );
    }
    if img.pixels.len() != img.width as usize * img.height as usize {
        return err(
            span,
            format!(
                "{what} has {} pixels for {}x{}",
                img.pixels.len(),
                img.width,
                img.height
            ),
        );
    }
    if img
        .pixels
        .iter()
        .any(|p| !p.is_finite() || p.min_element() < 0.0)
    {
        return err(span, format!("{what} has a negative or non-finite pixel"));
    }
    Ok(())
}

/// Validates an environment and makes its canonical, sampleable form.
fn build_environment(env: &EnvironmentDesc, radius: f32) -> Result<EnvironmentLight, BuildError> {
    let span = &env.span;
    check_finite(span, "environment strength", &[env.strength])?;
    if env.strength < 0.0 {
        return err(span, "environment strength must not be negative");
    }
    check_color(span, "environment background", env.background)?;
    let r = env.rotation;
    check_finite(span, "environment rotation", &r.to_cols_array())?;
    let off = (r.transpose() * r - Mat3::IDENTITY).abs().to_cols_array();
    if off.iter().any(|&e| e > 1e-3) || r.determinant() < 0.0 {
        return err(
            span,
            "environment rotation must be a rotation (orthonormal, det +1)",
        );
    }
    let map = match &env.map {
        EnvironmentMapDesc::Constant(c) => {
            check_color(span, "environment constant", *c)?;
            EnvironmentMap::Constant(*c)
        }
        EnvironmentMapDesc::Equirect(img) => {
            check_image(span, "environment map", img)?;
            EnvironmentMap::Equirect(Equirect::new(Image::from_desc(img)))
        }
        EnvironmentMapDesc::Cubemap(faces) => {
            let n = faces[0].width;
            for (f, name) in faces.iter().zip(["+x", "-x", "+y", "-y", "+z", "-z"]) {
                let what = format!("cube map face {name}");
                check_image(span, &what, f)?;
                if f.width != n || f.height != n {
                    return err(
                        span,
                        format!(
                            "{what} is {}x{}; faces must be square and all {n}x{n}",
                            f.width, f.height
                        ),
                    );
                }
            }
            EnvironmentMap::Cubemap(Cubemap::new(Box::new(
                faces.each_ref().map(Image::from_desc),
            )))
        }
    };
    let mut light = EnvironmentLight::new(map, env.strength, r, radius);
    light.visible = env.visible;
    light.background = env.background;
    Ok(light)
}

fn build_camera(desc: &SceneDesc) -> Result<Camera, BuildError> {
    let c = &desc.camera;
    check_finite(
        &c.span,
        "camera",
        &[c.position.to_array(), c.look_at.to_array(), c.up.to_array()].concat(),
    )?;
    let view = c.look_at - c.position;
    if view.length_squared() == 0.0 {
        return err(&c.span, "camera position and look_at coincide");
    }
    if view
        .normalize()
        .cross(c.up.normalize_or_zero())
        .length_squared()
        < 1e-10
    {
        return err(
            &c.span,
            "camera up vector is parallel to the view direction (or zero)",
        );
    }
    if let Some(f) = c.focal_length_mm {
        if !(f.is_finite() && f > 0.0) {
            return err(&c.span, format!("focal length {f} mm must be positive"));
        }
    }
    if !(c.sensor_mm.is_finite() && c.sensor_mm.min_element() > 0.0) {
        return err(
            &c.span,
            format!("sensor size {} mm must be positive", c.sensor_mm),
        );
    }
    if !(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0) {
        return err(
            &c.span,
            format!(
                "fov {} must lie strictly between 0 and 180 degrees",
                c.fov_y_deg
            ),
        );
    }
    if let Some(h) = c.ortho_height {
        if !(h.is_finite() && h > 0.0) {
            return err(
                &c.span,
                format!("orthographic view height {h} must be positive"),
            );
        }
        if c.lens.is_some() {
            return err(&c.span, "an orthographic camera takes no lens");
        }
    }
    if let Some(lens) = &c.lens {
        validate_lens(c, lens)?;
    }
    Ok(Camera::new(c, desc.render.width, desc.render.height))
}

fn validate_lens(c: &CameraDesc, lens: &LensDesc) -> Result<(), BuildError> {
    let forward = (c.look_at - c.position).normalize();
    let focus = match lens.focus {
        FocusDesc::LookAt => (c.look_at - c.position).length(),
        FocusDesc::Distance(d) => d,
        FocusDesc::Point(p) => {
            check_finite(&c.span, "focus point", &p.to_array())?;
            (p - c.position).dot(forward)
        }
    };
    if !(focus.is_finite() && focus > 0.0) {
        return err(
            &c.span,
            format!("focus distance {focus} must be positive (in front of the camera)"),
        );
    }
    match lens.size {
        ApertureSizeDesc::Radius(r) if !(r.is_finite() && r >= 0.0) => {
            return err(&c.span, format!("aperture radius {r} must not be negative"));
        }
        ApertureSizeDesc::FNumber(n) if !(n.is_finite() && n > 0.0) => {
            return err(&c.span, format!("f-number {n} must be positive"));
        }
        _ => {}
    }
    match &lens.aperture {
        ApertureDesc::Disc => {}
        ApertureDesc::Polygon {
            blades,
            rotation_deg,
        } => {
            if !(3..=64).contains(blades) {
                return err(
                    &c.span,
                    format!("aperture blades {blades} must be between 3 and 64"),
                );
            }
            check_finite(&c.span, "aperture rotation", &[*rotation_deg])?;
        }
        ApertureDesc::Image {
            width,
            height,
            luminance,
        } => {
            if *width == 0 || *height == 0 {
                return err(&c.span, "aperture image is empty");
            }
            if luminance.len() != *width as usize * *height as usize {
                return err(
                    &c.span,
                    format!(
                        "aperture image has {} values for {width}x{height} pixels",
                        luminance.len()
                    ),
                );
            }
            if luminance.iter().any(|v| !v.is_finite() || *v < 0.0) {
                return err(&c.span, "aperture image has a negative or non-finite value");
            }
            if !luminance.iter().any(|&v| v > 0.0) {
                return err(&c.span, "aperture image is black: no light passes");
            }
        }
    }
    Ok(())
}

fn build_filter(f: PixelFilterDesc) -> Result<PixelFilter, BuildError> {
    let (radius, stddev) = match f {
        PixelFilterDesc::Box => (1.0, 1.0),
        PixelFilterDesc::Tent { radius } => (radius, 1.0),
        PixelFilterDesc::Gaussian { stddev, radius } => (radius, stddev),
    };
    if !(radius.is_finite() && radius > 0.0 && stddev.is_finite() && stddev > 0.0) {
        return err(
            &Span::code(),
            format!("pixel filter {f:?} needs a positive, finite radius and stddev"),
        );
    }
    Ok(PixelFilter::new(f))
}

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

fn build_material(bsdf: &BsdfDesc, span: &Span) -> Result<Material, BuildError> {
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
fn build_alpha(bsdf: &BsdfDesc, span: &Span) -> Result<Option<AlphaMask>, BuildError> {
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

fn build_sphere(
    shape: &ShapeDesc,
    center: Vec3,
    radius: f32,
    material: MaterialId,
) -> Result<Sphere, BuildError> {
    check_finite(
        &shape.span,
        "sphere",
        &[center.x, center.y, center.z, radius],
    )?;
    if radius <= 0.0 {
        return err(
            &shape.span,
            format!("sphere radius {radius} must be positive"),
        );
    }
    let m = Mat3::from_mat4(shape.transform);
    let scales = [m.x_axis.length(), m.y_axis.length(), m.z_axis.length()];
    let (lo, hi) = (
        scales.iter().copied().fold(f32::INFINITY, f32::min),
        scales.iter().copied().fold(0.0, f32::max),
    );
    if hi - lo > 1e-4 * hi {
        return err(
            &shape.span,
            "a sphere's transform must scale all axes equally",
        );
    }
    Ok(Sphere {
        center: shape.transform.transform_point3(center),
        radius: radius * hi,
        material,
        light: None,
        flip_normals: shape.flip_normals,
    })
}

fn validate_mesh(m: &MeshDesc, span: &Span) -> Result<(), BuildError> {
    if m.indices.is_empty() || m.positions.is_empty() {
        return err(span, "mesh has no triangles");
    }
    if !m.normals.is_empty() && m.normals.len() != m.positions.len() {
        return err(
            span,
            format!(
                "mesh has {} normals for {} positions",
                m.normals.len(),
                m.positions.len()
            ),
        );
    }
    if !m.uvs.is_empty() && m.uvs.len() != m.positions.len() {
        return err(
            span,
            format!(
                "mesh has {} uvs for {} positions",
                m.uvs.len(),
                m.positions.len()
            ),
        );
    }
    if !m.colors.is_empty() && m.colors.len() != m.positions.len() {
        return err(
            span,
            format!(
                "mesh has {} colours for {} positions",
                m.colors.len(),
                m.positions.len()
            ),
        );
    }
    if !m.tangents.is_empty() && m.tangents.len() != m.positions.len() {
        return err(
            span,
            format!(
                "mesh has {} tangents for {} positions",
                m.tangents.len(),
                m.positions.len()
            ),
        );
    }
    if let Some(i) = m
        .indices
        .iter()
        .flatten()
        .find(|&&i| i as usize >= m.positions.len())
    {
        return err(
            span,
            format!(
                "mesh index {i} is out of range ({} positions)",
                m.positions.len()
            ),
        );
    }
    if m.positions
        .iter()
        .chain(&m.normals)
        .chain(&m.colors)
        .any(|p| !p.is_finite())
        || m.uvs.iter().any(|uv| !uv.is_finite())
        || m.tangents.iter().any(|t| !t.is_finite())
    {
        return err(span, "mesh has a non-finite vertex attribute");
    }
    Ok(())
}

fn to_world(local: MeshDesc, m: Mat4, material: MaterialId) -> Mesh {
    let xf = Transform::new(m);
    Mesh {
        // Through `into_iter`: the vectors are reused, not copied.
        positions: local.positions.into_iter().map(|p| xf.point(p)).collect(),
        normals: local.normals.into_iter().map(|n| xf.normal(n)).collect(),
        uvs: local.uvs,
        colors: local.colors,
        tangents: local.tangents.into_iter().map(|t| xf.tangent(t)).collect(),
        indices: local.indices,
        material,
        lights: Vec::new(),
        flip_normals: false,
        alpha: None,
        face_normals: Vec::new(),
    }
}

/// A shared mesh as its instances read it: the description's vertex data untouched
/// (normals and tangents not yet normalised), so that an instance's [`Transform`] makes
/// of it exactly what [`to_world`] makes of the same mesh.
fn object_space(local: MeshDesc, material: MaterialId) -> Mesh {
    Mesh {
        positions: local.positions,
        normals: local.normals,
        uvs: local.uvs,
        colors: local.colors,
        tangents: local.tangents,
        indices: local.indices,
        material,
        lights: Vec::new(),
        flip_normals: false,
        alpha: None,
        face_normals: Vec::new(),
    }
}

/// The square [-1,1]² at z = 0 facing +z, as two triangles.
pub fn rectangle() -> MeshDesc {
    MeshDesc {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        normals: vec![Vec3::Z; 4],
        uvs: vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        colors: Vec::new(),
        tangents: Vec::new(),
    }
}

/// The unit disk at z = 0 facing +z, as a fan of `segments` triangles. Its area falls
/// short of π by the factor sin(2π/n)·n/(2π) (4·10⁻⁴ at n = 128).
pub fn disk(segments: u32) -> MeshDesc {
    let mut positions = vec![Vec3::ZERO];
    let mut uvs = vec![Vec2::splat(0.5)];
    for i in 0..segments {
        let phi = std::f32::consts::TAU * i as f32 / segments as f32;
        let (s, c) = phi.sin_cos();
        positions.push(Vec3::new(c, s, 0.0));
        uvs.push(Vec2::new(0.5 + 0.5 * c, 0.5 + 0.5 * s));
    }
    let indices = (0..segments)
        .map(|i| [0, 1 + i, 1 + (i + 1) % segments])
        .collect();
    MeshDesc {
        normals: vec![Vec3::Z; positions.len()],
        positions,
        uvs,
        indices,
        colors: Vec::new(),
        tangents: Vec::new(),
    }
}

/// The cube [-1,1]³ with outward faces, four vertices per face so normals stay flat.
pub fn cube() -> MeshDesc {
    let mut mesh = MeshDesc::default();
    let rect = rectangle();
    // Each face is the rectangle rotated so that +z goes to the face's normal.
    let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for n in faces {
        let rot = glam::Quat::from_rotation_arc(Vec3::Z, n);
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(rect.positions.iter().map(|&p| rot * p + n));
        mesh.normals.extend([n; 4]);
        mesh.uvs.extend(&rect.uvs);
        mesh.indices
            .extend(rect.indices.iter().map(|t| t.map(|i| i + base)));
    }
    mesh
}
