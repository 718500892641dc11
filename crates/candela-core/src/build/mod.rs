//! From a [`SceneDesc`] to a render-time [`Scene`]: validation (every reference resolves,
//! every number is finite, every mesh is non-empty) and the canonical forms the renderer
//! needs (world-space meshes, one light per emitting triangle, the BVH, the light sampler).
//!
//! [`build`] here runs the steps in order; each concern has its file:
//! - `validate`: [`BuildError`] and the checks every part shares (finite numbers,
//!   colours, images, the resolution);
//! - `camera`: the camera and the pixel filter;
//! - `materials`: BSDFs, textures and alpha masks;
//! - `shapes`: spheres and meshes placed in the world, instancing, and the unit
//!   primitives ([`rectangle`], [`disk`], [`cube`]) as meshes;
//! - `lights`: lights that are not shapes, emitting triangles, photometric units and
//!   emission profiles;
//! - `environment`: the environment light in its sampleable form;
//! - `media`: participating media and the shapes that bound them.

use std::collections::HashMap;
use std::sync::Arc;

use glam::Vec3;

use crate::accel::{
    Accel, AccelLayout, Geometry, LeafLayout, NodeLayout, Shape, Simd, TriangleMesh, INDEXED_FROM,
};
use crate::desc::{GeometryDesc, MeshDesc, RenderSettings, SceneDesc, Span};
use crate::geometry::Aabb;
use crate::instance::{Instance, Instances, Transform};
use crate::light::{Light, LightId, SphereLight};
use crate::light_sampler::LightSampler;
use crate::material::MaterialId;
use crate::options::RenderOptions;
use crate::scene::{Mesh, Prim, Scene, Sphere};

mod camera;
mod environment;
mod lights;
mod materials;
mod media;
mod shapes;
mod validate;

use camera::{build_camera, build_filter};
use environment::build_environment;
use materials::{build_alpha, build_material};
use shapes::{build_sphere, object_space, shared_meshes, to_world, validate_mesh};
// For `lights` and `media`, which import them from here.
use validate::{check_color, check_finite, check_image, err};

pub use lights::LUMENS_PER_WATT;
pub use materials::build_texture;
pub use shapes::{cube, disk, rectangle};
pub use validate::{check_resolution, BuildError, MAX_PIXELS};

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
    if triangles + spheres.len() < INDEXED_FROM {
        meshes.iter_mut().for_each(Mesh::cache_uv_tangents);
    }
    for m in &mut meshes {
        // An emitting mesh's lights may read the uvs (emission textures).
        let material = &materials[m.material.0 as usize];
        m.cache_shading_record(
            material.reads_uv() || !m.lights.is_empty(),
            material.reads_dpdu(),
        );
    }
    for s in &mut spheres {
        s.reads_uv = materials[s.material.0 as usize].reads_uv();
    }
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
        settings: render_options(r),
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

/// What the render code reads of the settings; the rest went into the scene's objects.
fn render_options(r: &RenderSettings) -> RenderOptions {
    RenderOptions {
        width: r.width,
        height: r.height,
        spp: r.spp,
        max_depth: r.max_depth,
        rr_depth: r.rr_depth,
        seed: r.seed,
        mis: r.mis,
        integrator: r.integrator,
        sampler: r.sampler,
        hide_emitters: r.hide_emitters,
        filter_sampling: r.filter_sampling,
        isa: r.isa,
        aovs: r.aovs,
    }
}
