//! `candela info`: what a scene contains.

use std::path::Path;

use candela_core::light::Light;

use crate::render::LoadArgs;
use crate::UserError;

pub fn run(path: &Path, load: &LoadArgs) -> Result<(), UserError> {
    let desc = load.load(path)?;
    let scene = candela_core::build::build(&desc)?;
    let s = &scene.settings;
    let b = scene.bounds();
    let count = |f: fn(&Light) -> bool| scene.lights.iter().filter(|l| f(l)).count();
    println!("scene      {}", path.display());
    println!(
        "shapes     {} ({} meshes, {} spheres)",
        desc.shapes.len(),
        scene.meshes.len(),
        scene.spheres.len()
    );
    println!("triangles  {}", scene.triangle_count());
    println!(
        "lights     {} ({} emitting triangles, {} spheres, {} points), total power {:.4} W",
        scene.lights.len(),
        count(|l| matches!(l, Light::Triangle(_))),
        count(|l| matches!(l, Light::Sphere(_))),
        count(|l| matches!(l, Light::Point(_))),
        scene.lights.iter().map(Light::power).sum::<f32>()
    );
    let names: Vec<&str> = desc.materials.iter().map(|m| m.name.as_str()).collect();
    println!("materials  {} ({})", names.len(), names.join(", "));
    let c = &desc.camera;
    println!(
        "camera     at {:?} looking at {:?}, up {:?}, vertical fov {}°",
        c.position.to_array(),
        c.look_at.to_array(),
        c.up.to_array(),
        c.vertical_fov_deg()
    );
    println!(
        "bounds     {:?} to {:?}",
        b.min.to_array(),
        b.max.to_array()
    );
    println!(
        "render     {}x{}, {} spp, max depth {}, seed {}, mis {:?}, light sampler {:?}",
        s.width, s.height, s.spp, s.max_depth, s.seed, s.mis, s.light_sampler
    );
    Ok(())
}
