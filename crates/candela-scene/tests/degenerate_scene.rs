//! NaN and Inf: a scene built from every degenerate case a renderer meets — zero-area
//! and needle triangles (also as emitters), zero and opposing shading normals,
//! zero-roughness GGX (conductor, glTF metal-rough with roughness 0, rough glass at
//! α = 0 along one axis), a camera grazing a plane, and sphere lights of radius 10⁻⁷ (radius 0 itself is a located error) —
//! renders an image whose every pixel is finite, and the film drops no sample as
//! non-finite (the integrator must not produce one, not merely have it filtered).

use std::path::Path;
use std::sync::atomic::AtomicBool;

const SCENE: &str = r#"
[render]
resolution = [48, 32]
spp = 64
max_depth = 8
seed = 7

[camera]
type = "pinhole"
position = [0, 0.000001, 4]   # grazing the floor at y = 0
look_at = [0, 0.000001, 0]
fov = 60

[materials.white]
type = "diffuse"
albedo = 0.8

[materials.mirror]
type = "conductor"
preset = "Au"
alpha = 0

[materials.aniso]
type = "conductor"
alpha_u = 0
alpha_v = 0.5

[materials.gltf_smooth]
type = "metal_rough"
base_color = 0.9
metallic = 1
roughness = 0

[materials.gltf_dielectric]
type = "metal_rough"
base_color = 0.9
metallic = 0
roughness = 0

[materials.glass]
type = "dielectric"
eta = 1.5
alpha_u = 0
alpha_v = 0.3

[[shape]]                       # the floor, seen edge-on
type = "rectangle"
material = "white"
transform = [{ rotate = { axis = [1, 0, 0], angle = -90 } }, { scale = 10 }]

[[shape]]                       # zero-area triangles: a point, a line, a needle
type = "mesh"
material = "mirror"
positions = [[0, 1, 0], [0, 1, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0], [3, 1, 0],
             [-1, 0.5, 0], [1, 0.5, 0], [0, 0.5, 0.0000001]]
indices = [[0, 1, 2], [3, 4, 5], [6, 7, 8]]

[[shape]]                       # an emitting needle and an emitting point
type = "mesh"
material = "white"
emission = 5
positions = [[-1, 1.5, 0], [1, 1.5, 0], [0, 1.5, 0.0000001], [0, 2, 0], [0, 2, 0], [0, 2, 0]]
indices = [[0, 1, 2], [3, 4, 5]]

[[shape]]                       # zero normals and normals facing away from the face
type = "mesh"
material = "gltf_smooth"
positions = [[-2, 0, -1], [-1, 0, -1], [-1, 1, -1], [-2, 1, -1]]
normals = [[0, 0, 0], [0, 0, -1], [0, 0, 0], [0, 0, -1]]
indices = [[0, 1, 2], [0, 2, 3]]

[[shape]]
type = "mesh"
material = "aniso"
positions = [[1, 0, -1], [2, 0, -1], [2, 1, -1], [1, 1, -1]]
normals = [[0, 1, 0], [0, -1, 0], [1, 0, 0], [0, 0, -1]]
indices = [[0, 1, 2], [0, 2, 3]]

[[shape]]
type = "sphere"
center = [0, 0.5, 1]
radius = 0.4
material = "glass"

[[shape]]
type = "sphere"
center = [-0.8, 0.3, 1.5]
radius = 0.3
material = "gltf_dielectric"

[[shape]]                       # a sphere light of almost zero radius
type = "sphere"
center = [0.5, 1, 1]
radius = 0.0000001
material = "white"
emission = 100

[[light]]
type = "point"
position = [0, 3, 2]
intensity = 20

[[light]]
type = "spot"
position = [1, 3, 1]
direction = [0, -1, 0]
inner_angle = 0
outer_angle = 0.0001
intensity = 50

[[light]]
type = "directional"
direction = [1, -0.00001, 0]    # grazing the floor
irradiance = 2
"#;

#[test]
fn a_scene_of_degenerate_cases_renders_finite_without_rejected_samples() {
    let desc = match candela_scene::parse_toml_scene(SCENE, Path::new("degenerate.toml")) {
        Ok(d) => d,
        Err(e) => panic!("{e}"),
    };
    let scene = match candela_core::build::build(&desc) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    };
    let spp = desc.render.spp;
    let film =
        candela_core::integrator::render(&scene, 0..spp, &AtomicBool::new(false), &|_| {}).film;
    let pixels = film.resolve();
    assert_eq!(pixels.len(), 48 * 32);
    assert!(pixels
        .iter()
        .all(|p| p.is_finite() && p.min_element() >= 0.0));
    assert_eq!(
        film.rejected_samples(),
        0,
        "non-finite samples were produced"
    );
    // Not a black image: the lights reach the camera.
    let lit = pixels.iter().filter(|p| p.max_element() > 0.0).count();
    eprintln!("{lit} of {} pixels lit", pixels.len());
    assert!(lit > pixels.len() / 4, "{lit} lit");
}

#[test]
fn a_sphere_of_radius_zero_is_a_located_error() {
    let text = SCENE.replace("radius = 0.0000001", "radius = 0");
    let desc = candela_scene::parse_toml_scene(&text, Path::new("degenerate.toml")).unwrap();
    let line = text.lines().position(|l| l == "radius = 0").unwrap();
    let e = candela_core::build::build(&desc).err().unwrap().to_string();
    // The error names the [[shape]] table two lines above the radius.
    assert!(
        e.starts_with(&format!("degenerate.toml:{}:", line - 2)),
        "{e}"
    );
    assert!(e.contains("radius 0 must be positive"), "{e}");
}
