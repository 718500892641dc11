//! `candela info`: what a scene contains.

use std::path::Path;

use candela_core::light::{EnvironmentLight, EnvironmentMap, Light, LightSource};

use crate::render::LoadArgs;
use crate::UserError;

pub fn run(path: &Path, load: &LoadArgs) -> Result<(), UserError> {
    let desc = load.load(path)?;
    // What is printed of the description, taken before the build moves its meshes.
    let shapes = desc.shapes.len();
    let names: Vec<String> = desc.materials.iter().map(|m| m.name.clone()).collect();
    let c = desc.camera.clone();
    let s = desc.render.clone();
    let scene = candela_core::build::build_owned(desc)?;
    let memory = crate::footprint::describe(&scene);
    let b = scene.bounds();
    let count = |f: fn(&Light) -> bool| scene.lights.iter().filter(|l| f(l)).count();
    println!("scene      {}", path.display());
    println!(
        "shapes     {} ({} meshes, {} spheres)",
        shapes,
        scene.meshes.len(),
        scene.spheres.len()
    );
    if scene.instances.is_empty() {
        println!("triangles  {}", scene.triangle_count());
    } else {
        println!(
            "triangles  {} rendered, {} stored ({} instances of {})",
            scene.triangle_count(),
            scene.stored_triangle_count(),
            scene.instances.instances.len(),
            shared_meshes(scene.instances.meshes.len())
        );
    }
    println!(
        "lights     {} ({} emitting triangles, {} emitting quads, {} spheres, {} points, {} environments), total power {:.4} W",
        scene.lights.len(),
        count(|l| matches!(l, Light::Triangle(_))),
        count(|l| matches!(l, Light::Parallelogram(_))),
        count(|l| matches!(l, Light::Sphere(_))),
        count(|l| matches!(l, Light::Point(_))),
        count(|l| matches!(l, Light::Environment(_))),
        scene.lights.iter().map(Light::power).sum::<f32>()
    );
    for l in &scene.lights {
        if let Light::Environment(env) = l {
            print_environment(env);
        }
    }
    println!("materials  {} ({})", names.len(), names.join(", "));
    let view = match c.ortho_height {
        Some(h) => format!("orthographic, {h} high"),
        None => format!("vertical fov {}°", c.vertical_fov_deg()),
    };
    println!(
        "camera     at {:?} looking at {:?}, up {:?}, {view}",
        c.position.to_array(),
        c.look_at.to_array(),
        c.up.to_array(),
    );
    println!(
        "bounds     {:?} to {:?}",
        b.min.to_array(),
        b.max.to_array()
    );
    println!("memory     {memory}");
    println!(
        "render     {}x{}, {} spp, max depth {}, seed {}, mis {:?}, light sampler {:?}, \
         lamp sampling {:?}",
        s.width, s.height, s.spp, s.max_depth, s.seed, s.mis, s.light_sampler, s.lamp_sampling
    );
    Ok(())
}

/// The environment's map, its power estimate and how peaked it is (the share of power in
/// the brightest 1% of texels: about 0.01 for an even sky, near 1 for a small sun).
fn print_environment(env: &EnvironmentLight) {
    let map = match &env.map {
        EnvironmentMap::Constant(c) => format!("constant {:?}", c.to_array()),
        EnvironmentMap::Equirect(m) => format!("equirect {}x{}", m.image.width, m.image.height),
        EnvironmentMap::Cubemap(m) => {
            format!("cube map 6 x {}x{}", m.faces[0].width, m.faces[0].height)
        }
    };
    println!(
        "environment {map}, strength {}, {}",
        env.strength,
        if env.visible {
            "visible".to_string()
        } else {
            format!("hidden (background {:?})", env.background.to_array())
        }
    );
    println!(
        "            power {:.4} W (pi r^2 * integral of L over the sphere, r = {:.3}), \
         brightest 1% of texels hold {:.1}% of it",
        env.power(),
        env.scene_radius,
        100.0 * env.peak_fraction(0.01)
    );
}

/// "1 shared mesh", "3 shared meshes".
pub fn shared_meshes(n: usize) -> String {
    format!("{n} shared mesh{}", if n == 1 { "" } else { "es" })
}
