//! The AOV passes on scenes whose albedo, normal and depth are known in closed form.
//!
//! The passes have no Monte Carlo noise where each sample sees the same value (a wall's
//! albedo, a plane's normal, the depth of a plane facing the camera), so the checks are
//! exact up to f32 round-off: 1e-5 on albedo and normals (a few ulps of a product of a
//! few factors), 1e-5 relative on depth (a dot product of positions of size ~10). Glass
//! and mirrors are chosen so that every sample's product of delta weights is 1 (or within
//! 1e-5 of it): a Fresnel choice taken with probability R carries weight R/R.

use std::f32::consts::FRAC_PI_4;
use std::sync::atomic::AtomicBool;

use candela_core::aov::{render_aovs, AovFilm};
use candela_core::build::build;
use candela_core::desc::*;
use glam::{Mat4, Vec3};

const RHO: Vec3 = Vec3::new(0.7, 0.5, 0.2);
const SIZE: u32 = 16;

fn diffuse(name: &str, albedo: Vec3) -> MaterialDesc {
    MaterialDesc::diffuse(name, albedo)
}

fn shape(geometry: GeometryDesc, material: &str, transform: Mat4) -> ShapeDesc {
    ShapeDesc::new(geometry, material).transformed(transform)
}

/// A scene seen from (0, 0, 5) towards the origin, `fov` degrees vertically.
fn scene(fov: f32, materials: Vec<MaterialDesc>, shapes: Vec<ShapeDesc>) -> SceneDesc {
    SceneDesc {
        camera: CameraDesc {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: fov,
            span: Span::code(),
            ..Default::default()
        },
        materials,
        shapes,
        render: RenderSettings {
            width: SIZE,
            height: SIZE,
            spp: 8,
            seed: 7,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn aovs(desc: &SceneDesc) -> AovFilm {
    let scene = build(desc).expect("scene builds");
    render_aovs(&scene, 0..desc.render.spp, &AtomicBool::new(false))
}

fn assert_close(what: &str, got: Vec3, want: Vec3, tol: f32) {
    assert!(
        (got - want).abs().max_element() <= tol,
        "{what}: {got} expected {want}"
    );
}

/// Every pixel's samples all hit something.
fn assert_all_hit(film: &AovFilm) {
    for p in &film.pixels {
        assert_eq!((p.samples, p.hits), (8, 8));
    }
}

#[test]
fn albedo_of_a_diffuse_wall_is_its_reflectance() {
    let wall = shape(
        GeometryDesc::Rectangle,
        "wall",
        Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0)) * Mat4::from_scale(Vec3::splat(10.0)),
    );
    let film = aovs(&scene(40.0, vec![diffuse("wall", RHO)], vec![wall]));
    assert_all_hit(&film);
    for (i, p) in film.pixels.iter().enumerate() {
        assert_close(&format!("albedo of pixel {i}"), p.albedo(), RHO, 1e-5);
        assert_close(&format!("normal of pixel {i}"), p.normal(), Vec3::Z, 1e-5);
    }
}

/// A perfect mirror (η = 1, k = 1000: Fresnel reflectance 1 − 4·10⁻⁶) at 45° turns the
/// view up onto a ceiling: the passes show the ceiling's albedo and normal, and the
/// mirror's depth.
#[test]
fn albedo_through_a_mirror_is_the_reflected_walls() {
    let mirror = MaterialDesc::new(
        "mirror",
        BsdfDesc::Conductor {
            eta: Vec3::ONE,
            k: Vec3::splat(1000.0),
            specular: Vec3::ONE,
            alpha_u: 0.0,
            alpha_v: 0.0,
            distribution: MicrofacetDesc::default(),
        },
    );
    // Normal (0, 1, 1)/√2: the camera's −z turns into +y.
    let mirror_shape = shape(
        GeometryDesc::Rectangle,
        "mirror",
        Mat4::from_rotation_x(-FRAC_PI_4) * Mat4::from_scale(Vec3::splat(3.0)),
    );
    // Normal −y, at y = 3.
    let ceiling = shape(
        GeometryDesc::Rectangle,
        "ceiling",
        Mat4::from_translation(Vec3::new(0.0, 3.0, 0.0))
            * Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2)
            * Mat4::from_scale(Vec3::splat(20.0)),
    );
    let film = aovs(&scene(
        20.0,
        vec![mirror, diffuse("ceiling", RHO)],
        vec![mirror_shape, ceiling],
    ));
    assert_all_hit(&film);
    for (i, p) in film.pixels.iter().enumerate() {
        assert_close(&format!("albedo of pixel {i}"), p.albedo(), RHO, 1e-5);
        assert_close(&format!("normal of pixel {i}"), p.normal(), -Vec3::Y, 1e-5);
    }
    // The mirror's plane y = −z: a ray (x, y, −1)·t from z = 5 meets it at depth
    // 5/(1 − y), between the centre rows' depths on either side of 5.
    let c = SIZE / 2;
    let (above, below) = (film.pixel(c, c - 1).depth(), film.pixel(c, c).depth());
    assert!(above > 5.0 && below < 5.0, "{above} {below}");
}

/// A solid glass ball (η = 1.5) around a diffuse core, inside a diffuse sphere: whatever
/// each sample does at the glass (reflect, refract, reflect inside), its delta weights
/// multiply to 1 once the refraction's 1/η′² radiance scaling is taken out (a path that
/// ends on the core, inside the glass, would otherwise carry 1/2.25), so every pixel, on
/// the ball or beside it, has the albedo of the diffuse surfaces.
#[test]
fn albedo_through_glass_is_the_surroundings() {
    let glass = MaterialDesc::new(
        "glass",
        BsdfDesc::Dielectric {
            eta: 1.5,
            alpha_u: 0.0,
            alpha_v: 0.0,
            distribution: MicrofacetDesc::default(),
            thin: false,
            tint: TextureDesc::Constant(Vec3::ONE),
        },
    );
    let ball = shape(
        GeometryDesc::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        },
        "glass",
        Mat4::IDENTITY,
    );
    let room = shape(
        GeometryDesc::Sphere {
            center: Vec3::ZERO,
            radius: 20.0,
        },
        "room",
        Mat4::IDENTITY,
    );
    let core = shape(
        GeometryDesc::Sphere {
            center: Vec3::ZERO,
            radius: 0.4,
        },
        "room",
        Mat4::IDENTITY,
    );
    let film = aovs(&scene(
        30.0,
        vec![glass, diffuse("room", RHO)],
        vec![ball, core, room],
    ));
    assert_all_hit(&film);
    for (i, p) in film.pixels.iter().enumerate() {
        assert_close(&format!("albedo of pixel {i}"), p.albedo(), RHO, 1e-5);
    }
    // The centre pixel sees the ball at depth 4, a corner the room at about 20 + 5.
    let c = SIZE / 2;
    assert!((film.pixel(c, c).depth() - 4.0).abs() < 0.05);
    assert!(film.pixel(0, 0).depth() > 20.0);
}

#[test]
fn normal_pass_of_a_tilted_plane_is_its_normal() {
    let tilt = Mat4::from_rotation_y(0.4) * Mat4::from_rotation_x(-0.3);
    let n = tilt.transform_vector3(Vec3::Z).normalize();
    let plane = shape(
        GeometryDesc::Rectangle,
        "wall",
        tilt * Mat4::from_scale(Vec3::splat(10.0)),
    );
    let film = aovs(&scene(40.0, vec![diffuse("wall", RHO)], vec![plane]));
    assert_all_hit(&film);
    for (i, p) in film.pixels.iter().enumerate() {
        assert_close(&format!("normal of pixel {i}"), p.normal(), n, 1e-5);
        assert!((p.normal().length() - 1.0).abs() < 1e-5);
    }
}

/// A plane facing the camera at z = −2 lies 7 away along the viewing axis in every pixel
/// (the corner rays travel 1.09× that far: the pass is the axis depth, not the ray's).
#[test]
fn depth_of_a_plane_facing_the_camera_is_its_distance() {
    let plane = shape(
        GeometryDesc::Rectangle,
        "wall",
        Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0)) * Mat4::from_scale(Vec3::splat(10.0)),
    );
    let film = aovs(&scene(45.0, vec![diffuse("wall", RHO)], vec![plane]));
    assert_all_hit(&film);
    for (i, &d) in film.depth().iter().enumerate() {
        assert!((d - 7.0).abs() <= 7e-5, "depth of pixel {i}: {d}");
    }
}

/// Where nothing is hit, albedo and normal are black and depth is +∞.
#[test]
fn empty_pixels_are_black_and_infinitely_deep() {
    let film = aovs(&scene(40.0, vec![diffuse("wall", RHO)], vec![]));
    for p in &film.pixels {
        assert_eq!(p.samples, 8);
        assert_eq!((p.albedo(), p.normal()), (Vec3::ZERO, Vec3::ZERO));
        assert_eq!(p.depth(), f32::INFINITY);
    }
}
