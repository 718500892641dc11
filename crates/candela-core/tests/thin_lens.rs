//! Thin-lens geometry: points on the plane of focus image to one film point whatever the
//! aperture sample; points off it spread into a circle of confusion whose diameter is the
//! one the Gaussian lens equation predicts; the field of view does not change with focus.

use candela_core::build::build;
use candela_core::camera::Camera;
use candela_core::desc::*;
use candela_core::sampler::Pcg32;
use glam::{Vec2, Vec3};

const W: u32 = 1000;
const H: u32 = 800;

fn lens_camera(focus: f32, aperture: ApertureDesc) -> CameraDesc {
    CameraDesc {
        position: Vec3::new(0.3, 1.2, 4.0),
        look_at: Vec3::new(-0.5, 0.8, 0.0),
        up: Vec3::Y,
        focal_length_mm: Some(50.0),
        lens: Some(LensDesc {
            focus: FocusDesc::Distance(focus),
            size: ApertureSizeDesc::FNumber(1.4),
            aperture,
        }),
        ..Default::default()
    }
}

fn lens_samples(n: usize, seed: u64) -> Vec<Vec2> {
    let mut rng = Pcg32::new(seed, 3);
    (0..n)
        .map(|_| Vec2::new(rng.uniform_f32(), rng.uniform_f32()))
        .collect()
}

/// The point at depth `depth` (along the view axis) on the pinhole ray through `film`.
fn point_at_depth(cam: &Camera, film: Vec2, depth: f32) -> Vec3 {
    let r = cam.generate_ray(film);
    r.o + r.d * (depth / r.d.dot(cam.forward()))
}

#[test]
fn points_on_the_plane_of_focus_image_to_one_point_at_any_focus() {
    let films = [
        Vec2::new(500.0, 400.0),
        Vec2::new(13.5, 20.25),
        Vec2::new(987.0, 650.0),
        Vec2::new(250.0, 790.0),
    ];
    for focus in [0.5f32, 2.0, 20.0] {
        let desc = lens_camera(
            focus,
            ApertureDesc::Polygon {
                blades: 6,
                rotation_deg: 10.0,
            },
        );
        let cam = Camera::new(&desc, W, H);
        assert!(cam.lens().is_some());
        for film in films {
            let p = point_at_depth(&cam, film, focus);
            for u in lens_samples(500, 1) {
                // The same film position for every lens point: the pinhole's, so the field
                // of view is that of the pinhole whatever the focus distance.
                let q = cam.project(p, u).unwrap();
                assert!((q - film).length() < 5e-3, "focus {focus}: {film} -> {q}");
                // And the lens ray through that film position passes through the point.
                let r = cam.generate_lens_ray(film, u);
                let miss = (p - r.o).cross(r.d).length();
                assert!(
                    miss < 1e-5 * focus.max(1.0),
                    "focus {focus}: misses by {miss}"
                );
            }
        }
    }
}

/// Circle of confusion diameter in pixels from the Gaussian lens equation 1/f = 1/s + 1/v:
/// a lens of focal length f focused at F has its sensor at v_F; a point at depth z comes
/// to focus at v_z, and the cone of light from the aperture (diameter 2A) cuts the sensor
/// in a disc of diameter 2A·|v_z − v_F|/v_z. With the field of view held fixed the sensor
/// height is 2·v_F·tan(fov/2).
fn thin_lens_coc_px(f: f64, a: f64, focus: f64, z: f64, fov_y_deg: f64, height: f64) -> f64 {
    let v = |s: f64| 1.0 / (1.0 / f - 1.0 / s);
    let (v_f, v_z) = (v(focus), v(z));
    let c = 2.0 * a * (v_z - v_f).abs() / v_z;
    c / (2.0 * v_f * (0.5 * fov_y_deg.to_radians()).tan()) * height
}

#[test]
fn off_focus_points_spread_into_the_thin_lens_circle_of_confusion() {
    let focus = 2.0f32;
    let desc = lens_camera(focus, ApertureDesc::Disc);
    let cam = Camera::new(&desc, W, H);
    let lens = cam.lens().unwrap();
    // 50 mm at f/1.4 in metres.
    assert!((lens.aperture_radius - 0.05 / 2.8).abs() < 1e-7);
    let us = lens_samples(20_000, 2);
    for film in [Vec2::new(500.0, 400.0), Vec2::new(120.0, 700.0)] {
        for z in [0.7f32, 1.0, 3.0, 10.0] {
            let p = point_at_depth(&cam, film, z);
            let qs: Vec<Vec2> = us.iter().map(|&u| cam.project(p, u).unwrap()).collect();
            let lo = qs.iter().fold(Vec2::INFINITY, |a, &q| a.min(q));
            let hi = qs.iter().fold(Vec2::NEG_INFINITY, |a, &q| a.max(q));
            let want = thin_lens_coc_px(
                0.05,
                lens.aperture_radius as f64,
                focus as f64,
                z as f64,
                desc.vertical_fov_deg() as f64,
                H as f64,
            );
            // The extremes of 2·10⁴ uniform disc samples fall short of the rim by ~0.2%
            // (P(x > 1 − δ) ≈ 0.6·δ^1.5); 1% leaves room for that and nothing else.
            for (axis, extent) in [("x", hi.x - lo.x), ("y", hi.y - lo.y)] {
                let rel = extent as f64 / want - 1.0;
                assert!(
                    rel.abs() < 0.01,
                    "z = {z}, {axis}: measured {extent:.3} px, thin lens {want:.3} px"
                );
            }
            // Behind the plane of focus the blur is an upright image of the aperture,
            // in front of it an inverted one: the lens's top half maps up or down.
            let centre = (lo + hi) * 0.5;
            let upright = us
                .iter()
                .zip(&qs)
                .filter(|(u, _)| lens.sample_point(**u).y > 0.0)
                .all(|(_, q)| (q.y < centre.y) == (z > focus));
            assert!(upright, "z = {z}: wrong orientation of the blur");
        }
    }
}

#[test]
fn pinhole_ignores_the_lens_sample_and_zero_aperture_is_a_pinhole() {
    let pinhole = Camera::new(&CameraDesc::default(), 64, 48);
    let mut closed = lens_camera(2.0, ApertureDesc::Disc);
    closed.lens.as_mut().unwrap().size = ApertureSizeDesc::Radius(0.0);
    let closed = Camera::new(&closed, 64, 48);
    assert!(!pinhole.needs_lens_sample() && !closed.needs_lens_sample());
    for (k, u) in lens_samples(100, 4).into_iter().enumerate() {
        let film = Vec2::new((k % 64) as f32 + 0.5, (k % 48) as f32 + 0.25);
        let (a, b) = (
            pinhole.generate_ray(film),
            pinhole.generate_lens_ray(film, u),
        );
        assert_eq!((a.o, a.d), (b.o, b.d));
    }
}

#[test]
fn bad_lens_descriptions_are_errors_with_their_span() {
    let span = Span::new("dof.toml", 7, 1);
    type Edit = Box<dyn Fn(&mut CameraDesc)>;
    let cases: Vec<(Edit, &str)> = vec![
        (
            Box::new(|c| c.lens.as_mut().unwrap().focus = FocusDesc::Distance(-1.0)),
            "focus distance",
        ),
        (
            Box::new(|c| {
                c.lens.as_mut().unwrap().focus = FocusDesc::Point(Vec3::new(0.0, 0.0, 9.0))
            }),
            "focus distance",
        ),
        (
            Box::new(|c| c.lens.as_mut().unwrap().size = ApertureSizeDesc::FNumber(0.0)),
            "f-number",
        ),
        (
            Box::new(|c| c.lens.as_mut().unwrap().size = ApertureSizeDesc::Radius(f32::NAN)),
            "aperture radius",
        ),
        (
            Box::new(|c| {
                c.lens.as_mut().unwrap().aperture = ApertureDesc::Polygon {
                    blades: 2,
                    rotation_deg: 0.0,
                }
            }),
            "blades",
        ),
        (
            Box::new(|c| {
                c.lens.as_mut().unwrap().aperture = ApertureDesc::Image {
                    width: 2,
                    height: 2,
                    luminance: vec![0.0; 4],
                }
            }),
            "black",
        ),
        (
            Box::new(|c| {
                c.lens.as_mut().unwrap().aperture = ApertureDesc::Image {
                    width: 2,
                    height: 2,
                    luminance: vec![1.0; 3],
                }
            }),
            "3 values",
        ),
        (Box::new(|c| c.focal_length_mm = Some(0.0)), "focal length"),
        (Box::new(|c| c.sensor_mm = Vec2::new(36.0, -1.0)), "sensor"),
    ];
    for (edit, what) in cases {
        let mut desc = SceneDesc {
            camera: CameraDesc {
                position: Vec3::new(0.0, 0.0, 5.0),
                look_at: Vec3::ZERO,
                span: span.clone(),
                ..lens_camera(2.0, ApertureDesc::Disc)
            },
            ..Default::default()
        };
        edit(&mut desc.camera);
        let e = build(&desc)
            .err()
            .unwrap_or_else(|| panic!("{what}: built"));
        assert_eq!(e.span, span);
        assert!(e.to_string().starts_with("dof.toml:7:1: "), "{e}");
        assert!(e.message.contains(what), "{what}: {e}");
    }
}
