//! Mitsuba XML import, element by element: transforms and the camera against numbers
//! computed once with Mitsuba 3.9.1 (`mitsuba` from PyPI, `scalar_rgb` variant; the
//! scripts are quoted in each test), parameters, includes, references, BSDF sidedness,
//! emitters, meshes, render settings.

use std::path::Path;

use candela_core::camera::Camera;
use candela_core::desc::{BsdfDesc, GeometryDesc, LightKindDesc, SamplerKind, TextureDesc};
use candela_core::geometry::Ray;
use candela_scene::{load_scene_with, LoadOptions};
use candela_test_support::assert_close;
use candela_test_support::files::{load_files, options};
use candela_test_support::mitsuba::{load, load_err, scene};
use glam::{Vec2, Vec3};

fn bbox(points: impl Iterator<Item = Vec3>) -> (Vec3, Vec3) {
    points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p), hi.max(p))
    })
}

#[test]
fn transformed_shapes_land_where_mitsuba_puts_them() {
    // Bounding boxes printed by Mitsuba 3 for this very scene:
    //   sc = mi.load_string(xml); [print(s.id(), s.bbox()) for s in sc.shapes()]
    // The rectangle's first rotation axis (1, 1, 0) is not unit: Mitsuba does not
    // normalize it (its rotation also scales), and neither may the importer.
    let xml = scene(
        r#"<shape type="rectangle" id="r"><transform name="to_world">
             <scale x="2" y="0.5" z="1"/>
             <rotate x="1" y="1" z="0" angle="30"/>
             <rotate value="0 0 1" angle="45"/>
             <translate x="1" y="-2" z="3"/>
           </transform></shape>
           <shape type="cube" id="c"><transform name="to_world">
             <matrix value="0.5 0 0 1  0 2 0 0  0 0 1 -1  0 0 0 1"/>
             <rotate y="1" angle="90"/>
           </transform></shape>
           <shape type="sphere" id="s"><point name="center" x="1" y="2" z="3"/>
             <float name="radius" value="0.5"/>
             <transform name="to_world"><scale value="2"/><translate value="0, 1, 0"/></transform>
           </shape>
           <shape type="disk" id="d"><transform name="to_world">
             <lookat origin="1,1,1" target="2,1,1" up="0,1,0"/></transform></shape>"#,
    );
    let desc = load(&xml).desc;
    let mitsuba = [
        (
            Vec3::new(-0.530931, -4.0046, 1.75),
            Vec3::new(2.53093, 0.00460285, 4.25),
        ),
        (Vec3::new(-2.0, -2.0, -1.5), Vec3::new(0.0, 2.0, -0.5)),
        (Vec3::new(1.0, 4.0, 5.0), Vec3::new(3.0, 6.0, 7.0)),
        (Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 2.0, 2.0)),
    ];
    for (shape, (lo, hi)) in desc.shapes.iter().zip(mitsuba) {
        let m = shape.transform;
        let (a, b) = match &shape.geometry {
            GeometryDesc::Rectangle => bbox(
                candela_core::build::rectangle()
                    .positions
                    .into_iter()
                    .map(|p| m.transform_point3(p)),
            ),
            GeometryDesc::Cube => bbox(
                candela_core::build::cube()
                    .positions
                    .into_iter()
                    .map(|p| m.transform_point3(p)),
            ),
            GeometryDesc::Disk => bbox(
                candela_core::build::disk(128)
                    .positions
                    .into_iter()
                    .map(|p| m.transform_point3(p)),
            ),
            GeometryDesc::Sphere { center, radius } => {
                let c = m.transform_point3(*center);
                let r = radius * m.transform_vector3(Vec3::X).length();
                (c - Vec3::splat(r), c + Vec3::splat(r))
            }
            g => panic!("unexpected {g:?}"),
        };
        assert_close(a, lo, 1e-4);
        assert_close(b, hi, 1e-4);
    }
}

#[test]
fn camera_rays_match_mitsuba_for_every_fov_axis() {
    // Directions of Mitsuba's rays at film uv (1, 0.5), (0.5, 0), (0, 1) (right edge, top
    // edge, bottom-left corner) of a 200x100 film:
    //   s = mi.load_dict({'type': 'perspective', 'fov': 60.0, 'fov_axis': axis,
    //     'to_world': mi.ScalarTransform4f().look_at(origin=[1,2,3], target=[0,0,0],
    //     up=[0,1,0]), 'film': {'type': 'hdrfilm', 'width': 200, 'height': 100}})
    //   s.sample_ray(0, 0.5, uv, [0.5, 0.5])[0].d
    let wide = [
        0.242887, -0.46291, -0.852479, -0.303657, -0.279149, -0.910971, -0.643727, -0.654069,
        -0.397252,
    ];
    let tall = [
        0.542174, -0.349927, -0.763936, -0.315971, -0.0403329, -0.947911, -0.774722, -0.626134,
        -0.0880991,
    ];
    let diag = [
        0.197818, -0.474936, -0.857499, -0.301032, -0.306261, -0.903097, -0.617923, -0.651892,
        -0.439554,
    ];
    for (axis, d) in [
        ("x", wide),
        ("y", tall),
        ("diagonal", diag),
        ("smaller", tall),
        ("larger", wide),
    ] {
        let props =
            format!(r#"<float name="fov" value="60"/><string name="fov_axis" value="{axis}"/>"#);
        assert_film_rays(&props, LOOK_AT_ORIGIN, d);
    }
}

/// The sensor placement of the camera tests below.
const LOOK_AT_ORIGIN: &str = r#"<lookat origin="1,2,3" target="0,0,0" up="0,1,0"/>"#;

/// The camera's rays at film uv (1, 0.5), (0.5, 0), (0, 1) (right edge, top edge,
/// bottom-left corner) of a 200x100 sensor of type `kind` with `props`, placed by the
/// `to_world` steps `transform`.
fn film_rays(kind: &str, props: &str, transform: &str) -> Vec<Ray> {
    let xml = scene(&format!(
        r#"<sensor type="{kind}">{props}
             <transform name="to_world">{transform}</transform>
             <film type="hdrfilm"><integer name="width" value="200"/><integer name="height" value="100"/></film>
           </sensor>"#
    ));
    let cam = Camera::new(&load(&xml).desc.camera, 200, 100);
    [
        Vec2::new(200.0, 50.0),
        Vec2::new(100.0, 0.0),
        Vec2::new(0.0, 100.0),
    ]
    .into_iter()
    .map(|film| cam.generate_ray(film))
    .collect()
}

/// Checks the directions of [`film_rays`] of a perspective sensor against Mitsuba's, as in
/// `camera_rays_match_mitsuba_for_every_fov_axis`.
fn assert_film_rays(sensor_props: &str, lookat: &str, want: [f32; 9]) {
    for (i, ray) in film_rays("perspective", sensor_props, lookat)
        .iter()
        .enumerate()
    {
        assert_close(ray.d, Vec3::from_slice(&want[3 * i..]), 2e-5);
    }
}

#[test]
fn focal_length_and_no_fov_follow_mitsubas_35mm_film() {
    // Mitsuba's rays for `focal_length` 35mm, and with neither fov nor focal_length (its
    // default, 50mm), same script as above with the fov replaced:
    //   s = mi.load_string("<sensor version='3.0.0' type='perspective'>"
    //     "<string name='focal_length' value='35mm'/>...</sensor>")
    let mm35 = [
        0.2251, -0.467795, -0.854692, -0.302636, -0.290028, -0.907907, -0.633725, -0.653401,
        -0.414077,
    ];
    let mm50 = [
        0.0931372, -0.498497, -0.861874, -0.294505, -0.364234, -0.883516, -0.552213, -0.64066,
        -0.533494,
    ];
    for (props, want) in [
        (r#"<string name="focal_length" value="35mm"/>"#, mm35),
        (r#"<string name="focal_length" value="35"/>"#, mm35),
        ("", mm50),
    ] {
        assert_film_rays(props, LOOK_AT_ORIGIN, want);
    }
    // Both, or a length that is not one, are errors at their element.
    let e = load_err(&scene(
        r#"<sensor type="perspective"><float name="fov" value="40"/>
             <string name="focal_length" value="50mm"/></sensor>"#,
    ));
    assert!(
        e.contains("scene.xml:2:1:") && e.contains("not both"),
        "{e}"
    );
    let e = load_err(&scene(
        r#"<sensor type="perspective">
             <string name="focal_length" value="wide"/></sensor>"#,
    ));
    assert!(
        e.contains("scene.xml:3:14:") && e.contains("\"wide\""),
        "{e}"
    );
}

#[test]
fn lookat_without_up_rolls_the_frame_as_mitsuba_does() {
    // Mitsuba takes `up` from `coordinate_system(view direction)` when it is missing:
    //   film_rays' script as above, fov 60, <lookat origin='1,2,3' target='0,0,0'/>
    let want = [
        -0.191812, -0.883623, -0.427104, 0.00957874, -0.535543, -0.844454, -0.495925, -0.0217069,
        -0.868094,
    ];
    assert_film_rays(
        r#"<float name="fov" value="60"/>"#,
        r#"<lookat origin="1,2,3" target="0,0,0"/>"#,
        want,
    );
    // Looking straight down: Mitsuba's bbox of the unit rectangle is [0,2]×{2}×[2,4].
    //   mi.load_string("<shape version='3.0.0' type='rectangle'><transform name='to_world'>"
    //     "<lookat origin='1,2,3' target='1,-1,3'/></transform></shape>").bbox()
    let desc = load(&scene(
        r#"<shape type="rectangle"><transform name="to_world">
             <lookat origin="1,2,3" target="1,-1,3"/></transform></shape>"#,
    ))
    .desc;
    let m = desc.shapes[0].transform;
    let (lo, hi) = bbox(
        candela_core::build::rectangle()
            .positions
            .into_iter()
            .map(|p| m.transform_point3(p)),
    );
    assert_close(lo, Vec3::new(0.0, 2.0, 2.0), 1e-5);
    assert_close(hi, Vec3::new(2.0, 2.0, 4.0), 1e-5);
}

#[test]
fn a_mirroring_camera_transform_is_rejected() {
    let e = load_err(&scene(
        r#"<sensor type="perspective"><float name="fov" value="40"/>
             <transform name="to_world"><scale x="-1"/></transform></sensor>"#,
    ));
    assert!(e.contains("scene.xml:2:1:") && e.contains("mirrors"), "{e}");
}

#[test]
fn defaults_are_replaced_by_defines_and_unknown_parameters_are_errors() {
    let xml = scene(
        r#"<default name="spp" value="16"/><default name="res" value="32"/>
           <sensor type="perspective"><float name="fov" value="40"/>
             <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
             <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/></film>
           </sensor>"#,
    );
    let (_d, r) = load_files(&[("scene.xml", xml.as_bytes())], &options(&[], false));
    let r = r.unwrap().desc.render;
    assert_eq!((r.spp, r.width, r.height), (16, 32, 32));
    let (_d, r) = load_files(
        &[("scene.xml", xml.as_bytes())],
        &options(&[("spp", "3")], false),
    );
    assert_eq!(r.unwrap().desc.render.spp, 3);

    let e = load_err(&scene("\n  <integrator type=\"$kind\"/>"));
    assert!(e.contains("scene.xml:3:15:") && e.contains("$kind"), "{e}");
}

#[test]
fn includes_and_references_resolve() {
    let main = scene(
        r#"<include filename="materials.xml"/>
           <shape type="rectangle"><ref id="red"/></shape>
           <shape type="cube"><bsdf type="diffuse"/></shape>
           <shape type="disk"/>"#,
    );
    let materials = scene(
        r#"<bsdf type="twosided" id="red"><bsdf type="diffuse">
             <rgb name="reflectance" value="0.8, 0.1 0.1"/></bsdf></bsdf>"#,
    );
    let (_d, r) = load_files(
        &[
            ("scene.xml", main.as_bytes()),
            ("materials.xml", materials.as_bytes()),
        ],
        &options(&[], false),
    );
    let desc = r.unwrap().desc;
    let mat = |name: &str| &desc.materials.iter().find(|m| m.name == name).unwrap().bsdf;
    assert_eq!(desc.shapes[0].material, "red");
    // twosided(diffuse) is Candela's diffuse; a bare diffuse is one-sided, default 0.5.
    match mat("red") {
        BsdfDesc::Diffuse {
            albedo: TextureDesc::Constant(c),
        } => assert_eq!(*c, Vec3::new(0.8, 0.1, 0.1)),
        b => panic!("{b:?}"),
    }
    for shape in &desc.shapes[1..] {
        match mat(&shape.material) {
            BsdfDesc::OneSided(inner) => match inner.as_ref() {
                BsdfDesc::Diffuse {
                    albedo: TextureDesc::Constant(c),
                } => assert_eq!(*c, Vec3::splat(0.5)),
                b => panic!("{b:?}"),
            },
            b => panic!("{b:?}"),
        }
    }
    assert!(candela_core::build::build(&desc).is_ok());

    let e = load_err(&scene("<shape type=\"cube\"><ref id=\"nope\"/></shape>"));
    assert!(
        e.contains("scene.xml:2:20:") && e.contains("\"nope\""),
        "{e}"
    );
    let (_d, r) = load_files(
        &[(
            "scene.xml",
            scene("<include filename=\"scene.xml\"/>").as_bytes(),
        )],
        &options(&[], false),
    );
    assert!(r.unwrap_err().message.contains("nest too deep"));
    // An error inside an included file points into that file.
    let (_d, r) = load_files(
        &[
            (
                "scene.xml",
                scene("<include filename=\"bad.xml\"/>").as_bytes(),
            ),
            ("bad.xml", scene("<shape type=\"torus\"/>").as_bytes()),
        ],
        &options(&[], false),
    );
    let e = r.unwrap_err().to_string();
    assert!(e.contains("bad.xml:2:1:") && e.contains("torus"), "{e}");
}

#[test]
fn twosided_and_mask_may_wrap_a_reference() {
    // Mitsuba 3.9.1 loads <bsdf type="twosided"><ref id="inner"/></bsdf> (and the same in
    // a mask) as the wrapper around the BSDF defined earlier under that id.
    let desc = load(&scene(
        r#"<bsdf type="diffuse" id="inner"><rgb name="reflectance" value="0.2, 0.7, 0.2"/></bsdf>
           <bsdf type="twosided" id="ts"><ref id="inner"/></bsdf>
           <bsdf type="mask" id="m"><float name="opacity" value="0.3"/><ref id="inner"/></bsdf>
           <shape type="cube"><ref id="ts"/></shape>"#,
    ))
    .desc;
    let mat = |name: &str| &desc.materials.iter().find(|m| m.name == name).unwrap().bsdf;
    match mat("ts") {
        BsdfDesc::Diffuse {
            albedo: TextureDesc::Constant(c),
        } => assert_eq!(*c, Vec3::new(0.2, 0.7, 0.2)),
        b => panic!("{b:?}"),
    }
    match mat("m") {
        BsdfDesc::Alpha { alpha, inner } => {
            assert_eq!(alpha.factor, 0.3);
            assert!(matches!(inner.as_ref(), BsdfDesc::OneSided(_)), "{inner:?}");
        }
        b => panic!("{b:?}"),
    }
    let e = load_err(&scene(
        r#"<bsdf type="twosided" id="ts"><ref id="later"/></bsdf>
           <bsdf type="diffuse" id="later"/>"#,
    ));
    assert!(
        e.contains("scene.xml:2:31:") && e.contains("\"later\""),
        "{e}"
    );
}

#[test]
fn emitters_map_to_area_and_point_lights() {
    let desc = load(&scene(
        r#"<shape type="sphere"><boolean name="flip_normals" value="true"/>
             <emitter type="area"><rgb name="radiance" value="1, 2, 3"/></emitter></shape>
           <emitter type="point"><point name="position" value="1, 2, 3"/>
             <rgb name="intensity" value="5"/></emitter>
           <emitter type="point"><transform name="to_world"><translate x="4"/></transform></emitter>"#,
    )).desc;
    assert_eq!(desc.shapes[0].emission, Some(Vec3::new(1.0, 2.0, 3.0)));
    assert!(desc.shapes[0].flip_normals);
    let points: Vec<_> = desc
        .lights
        .iter()
        .map(|l| match l.kind {
            LightKindDesc::Point {
                position,
                intensity,
            } => (position, intensity),
            ref other => panic!("expected a point light, got {other:?}"),
        })
        .collect();
    assert_eq!(points[0], (Vec3::new(1.0, 2.0, 3.0), Vec3::splat(5.0)));
    assert_eq!(points[1], (Vec3::new(4.0, 0.0, 0.0), Vec3::ONE));
}

#[test]
fn an_emitters_constant_spectrum_is_equal_energy_white_as_in_mitsubas_rgb_mode() {
    // Mitsuba 3.9.1 scalar_rgb reads <spectrum value="1"> in an emitter as the
    // equal-energy spectrum, (1.20479, 0.948291, 0.908916) in linear sRGB:
    //   mi.traverse(mi.load_string('<emitter version="3.0.0" type="point">'
    //     '<spectrum name="intensity" value="1"/></emitter>'))['intensity.value']
    // (the same for `constant`'s radiance and `directional`'s irradiance), while <rgb> and
    // <float> stay as given and a BSDF's constant spectrum stays grey.
    let e = Vec3::new(1.20479, 0.948291, 0.908916);
    let desc = load(&scene(
        r#"<shape type="sphere"><emitter type="area"><spectrum name="radiance" value="2"/></emitter></shape>
           <shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" value="0.5"/></bsdf>
             <emitter type="area"><float name="radiance" value="2"/></emitter></shape>
           <emitter type="point"><spectrum name="intensity" value="3"/></emitter>
           <emitter type="point"><rgb name="intensity" value="3"/></emitter>
           <emitter type="constant"><spectrum name="radiance" value="0.5"/></emitter>"#,
    )).desc;
    assert_close(desc.shapes[0].emission.unwrap(), 2.0 * e, 1e-6);
    assert_eq!(desc.shapes[1].emission, Some(Vec3::splat(2.0)));
    let bsdf = &desc
        .materials
        .iter()
        .find(|m| m.name == desc.shapes[1].material)
        .unwrap()
        .bsdf;
    match bsdf {
        BsdfDesc::OneSided(inner) => match inner.as_ref() {
            BsdfDesc::Diffuse {
                albedo: TextureDesc::Constant(c),
            } => assert_eq!(*c, Vec3::splat(0.5)),
            b => panic!("{b:?}"),
        },
        b => panic!("{b:?}"),
    }
    let intensities: Vec<Vec3> = desc
        .lights
        .iter()
        .map(|l| match l.kind {
            LightKindDesc::Point { intensity, .. } => intensity,
            ref other => panic!("expected a point light, got {other:?}"),
        })
        .collect();
    assert_close(intensities[0], 3.0 * e, 1e-6);
    assert_eq!(intensities[1], Vec3::splat(3.0));
    match &desc.environment.as_ref().unwrap().map {
        candela_core::desc::EnvironmentMapDesc::Constant(c) => assert_close(*c, 0.5 * e, 1e-6),
        m => panic!("{m:?}"),
    }
    // A blackbody, which Mitsuba's RGB variants refuse too, is an error at its element.
    let e = load_err(&scene(
        r#"<shape type="sphere"><emitter type="area">
             <spectrum name="radiance" type="blackbody"><float name="temperature" value="3000"/></spectrum>
           </emitter></shape>"#,
    ));
    assert!(
        e.contains("scene.xml:3:14:") && e.contains("type=\"blackbody\"") && e.contains("<rgb>"),
        "{e}"
    );
}

#[test]
fn spectra_given_as_wavelength_pairs_reduce_to_mitsubas_rgb() {
    // Mitsuba 3.9.1 scalar_rgb, for each spectrum below:
    //   mi.traverse(mi.load_string('<bsdf version="3.0.0" type="diffuse">'
    //     '<spectrum name="reflectance" value="400:0.0, 550:1.0, 700:0.0"/></bsdf>'))
    // and likewise for a conductor's eta and k and a point light's intensity. A
    // reflectance is weighed by D65 and clamped to [0, 1] (the second and third clamp),
    // η and k by D65 and not clamped above, an emitter's colour by neither.
    let s = "400:0.2, 500:2.5, 600:1.5, 700:3.0";
    let c = "400:0, 500:8, 600:15.6, 700:18.4";
    let desc = load(&scene(&format!(
        r#"<shape type="cube"><bsdf type="diffuse"><spectrum name="reflectance" value="400:0.0, 550:1.0, 700:0.0"/></bsdf></shape>
           <shape type="cube"><bsdf type="diffuse"><spectrum name="reflectance" value="400:1, 500:0 600:0,700:0"/></bsdf></shape>
           <shape type="cube"><bsdf type="diffuse"><spectrum name="reflectance" value="{s}"/></bsdf></shape>
           <shape type="cube"><bsdf type="conductor"><spectrum name="eta" value="{s}"/><spectrum name="k" value="{c}"/></bsdf></shape>
           <emitter type="point"><spectrum name="intensity" value="{s}"/></emitter>
           <emitter type="point"><spectrum name="intensity" value="{c}"/></emitter>"#
    ))).desc;
    let inner = |i: usize| {
        let name = &desc.shapes[i].material;
        match &desc
            .materials
            .iter()
            .find(|m| &m.name == name)
            .unwrap()
            .bsdf
        {
            BsdfDesc::OneSided(inner) => inner.as_ref().clone(),
            b => panic!("{b:?}"),
        }
    };
    let albedo = |i: usize| match inner(i) {
        BsdfDesc::Diffuse {
            albedo: TextureDesc::Constant(c),
        } => c,
        b => panic!("{b:?}"),
    };
    let close = |a: Vec3, b: [f32; 3]| {
        let b = Vec3::from(b);
        assert!(
            (a - b).abs().max_element() <= 2e-5 * b.max_element().max(1.0),
            "{a} vs Mitsuba's {b}"
        );
    };
    close(albedo(0), [0.5135267, 0.9042089, 0.3001395]);
    close(albedo(1), [0.02843371, 0.0, 0.515323]);
    close(albedo(2), [1.0, 1.0, 1.0]);
    let BsdfDesc::Conductor { eta, k, .. } = inner(3) else {
        panic!()
    };
    close(eta, [1.501708, 2.157423, 1.367805]);
    close(k, [17.71471, 11.35443, 3.304508]);
    let intensity = |i: usize| match desc.lights[i].kind {
        LightKindDesc::Point { intensity, .. } => intensity,
        ref other => panic!("{other:?}"),
    };
    close(intensity(0), [1.898967, 2.040142, 1.203149]);
    close(intensity(1), [20.71084, 10.85463, 2.771152]);

    // A spectrum file (`.spd`: a pair a line, `#` comments) beside the scene, as a
    // reflectance and as an intensity (Mitsuba 3.9.1 reads the same numbers from the file
    // as from the pairs inline).
    let spd = "# test\n400 0.1\n500 0.6\n\n600 0.3\n700 0.9\n";
    let xml = scene(
        r#"<shape type="cube"><bsdf type="diffuse"><spectrum name="reflectance" filename="r.spd"/></bsdf></shape>
           <emitter type="point"><spectrum name="intensity" filename="r.spd"/></emitter>"#,
    );
    let (_dir, loaded) = load_files(
        &[("scene.xml", xml.as_bytes()), ("r.spd", spd.as_bytes())],
        &options(&[], false),
    );
    let desc = loaded.unwrap().desc;
    let BsdfDesc::OneSided(inner) = &desc.materials[0].bsdf else {
        panic!()
    };
    let BsdfDesc::Diffuse {
        albedo: TextureDesc::Constant(albedo),
    } = inner.as_ref()
    else {
        panic!()
    };
    close(*albedo, [0.3380708, 0.4875679, 0.3586755]);
    let LightKindDesc::Point { intensity, .. } = desc.lights[0].kind else {
        panic!()
    };
    close(intensity, [0.4329627, 0.4593427, 0.3177919]);
    let e = load_err(&scene(
        r#"<shape type="cube"><bsdf type="diffuse"><spectrum name="reflectance" filename="none.spd"/></bsdf></shape>"#,
    ));
    assert!(
        e.contains("scene.xml:2:41:") && e.contains("none.spd"),
        "{e}"
    );

    // What Mitsuba refuses, refused at the element.
    for (value, what) in [
        ("400:0.5", "at least two wavelength:value pairs"),
        ("500:1, 400:1", "wavelengths must rise"),
        ("400:1 500", "\"500\" is not a wavelength:value pair"),
    ] {
        let e = load_err(&scene(&format!(
            r#"<shape type="cube"><bsdf type="diffuse"><spectrum name="reflectance" value="{value}"/></bsdf></shape>"#
        )));
        assert!(
            e.contains("scene.xml:2:41:") && e.contains(what),
            "{value}: {e}"
        );
    }
}

#[test]
fn meshes_without_normals_are_smoothed_as_mitsuba_does() {
    // Mitsuba recomputes angle-weighted vertex normals for an obj (or ply) without
    // normals unless face_normals is set:
    //   m = mi.load_dict({'type': 'obj', 'filename': 'quad.obj'})
    //   m.vertex_normals_buffer()
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
    let mitsuba = [
        Vec3::new(-0.23570228, -0.23570228, 0.9428091),
        Vec3::new(0.0, -0.4472136, 0.8944272),
        Vec3::new(-0.23570226, -0.23570226, 0.94280905),
        Vec3::new(-0.4472136, 0.0, 0.8944272),
    ];
    // The same for a ply whose triangles meet at unequal angles (a tetrahedron, whose
    // vertex normals are not the average of its face normals):
    //   m = mi.load_dict({'type': 'ply', 'filename': 'tetra.ply'})
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
               property float z\nelement face 4\nproperty list uchar int vertex_indices\n\
               end_header\n0 0 1\n0.94 0 -0.33\n-0.47 0.82 -0.33\n-0.47 -0.82 -0.33\n\
               3 0 1 2\n3 0 2 3\n3 0 3 1\n3 1 3 2\n";
    let tetra = [
        Vec3::new(-1.545_869e-4, 2.470_719e-8, 1.0),
        Vec3::new(0.942_728_9, 3.735_653e-9, -0.333_559_8),
        Vec3::new(-0.469_997, 0.817_676_2, -0.332_428_4),
        Vec3::new(-0.469_997, -0.817_676_2, -0.332_428_4),
    ];
    let xml = scene(
        r#"<shape type="obj"><string name="filename" value="quad.obj"/></shape>
           <shape type="ply"><string name="filename" value="tetra.ply"/></shape>
           <shape type="ply"><string name="filename" value="tetra.ply"/>
             <boolean name="face_normals" value="true"/></shape>"#,
    );
    let (_d, r) = load_files(
        &[
            ("scene.xml", xml.as_bytes()),
            ("quad.obj", obj.as_bytes()),
            ("tetra.ply", ply.as_bytes()),
        ],
        &options(&[], false),
    );
    let desc = r.unwrap().desc;
    let normals = |i: usize| match &desc.shapes[i].geometry {
        GeometryDesc::Mesh(m) => m.normals.clone(),
        g => panic!("{g:?}"),
    };
    for (i, want) in [(0, &mitsuba[..]), (1, &tetra[..])] {
        let got = normals(i);
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(want) {
            assert_close(*g, *w, 1e-5);
        }
    }
    assert!(normals(2).is_empty(), "face_normals keeps the mesh flat");
}

#[test]
fn cylinders_are_open_tubes_with_mitsubas_frame_and_uvs() {
    // Mitsuba 3.9.1, for the tube from (1,2,3) to (1,2,5) of radius 0.5:
    //   s.bbox() = [0.5, 1.5, 3]..[1.5, 2.5, 5], s.surface_area() = 2π
    // and for the default cylinder, hits at (1,0,0.25), (0,1,0.5), (-1,0,0.75) have uv
    // (0, 0.25), (0.25, 0.5), (0.5, 0.75) and the normal pointing outwards:
    //   sc.ray_intersect(mi.Ray3f([2,0,0.25], [-1,0,0])).uv
    let desc = load(&scene(
        r#"<shape type="cylinder"><point name="p0" x="1" y="2" z="3"/>
             <point name="p1" x="1" y="2" z="5"/><float name="radius" value="0.5"/></shape>
           <shape type="cylinder"/>"#,
    ))
    .desc;
    let mesh = |i: usize| match &desc.shapes[i].geometry {
        GeometryDesc::Mesh(m) => m.clone(),
        g => panic!("{g:?}"),
    };
    let tube = mesh(0);
    let (lo, hi) = bbox(tube.positions.iter().copied());
    assert_close(lo, Vec3::new(0.5, 1.5, 3.0), 1e-5);
    assert_close(hi, Vec3::new(1.5, 2.5, 5.0), 1e-5);
    let area: f32 = tube
        .indices
        .iter()
        .map(|&[a, b, c]| {
            let p = |i: u32| tube.positions[i as usize];
            0.5 * (p(b) - p(a)).cross(p(c) - p(a)).length()
        })
        .sum();
    assert!((area / std::f32::consts::TAU - 1.0).abs() < 2e-4, "{area}");
    // Faces wind counter-clockwise seen from outside, as the normals point.
    for &[a, b, c] in &tube.indices {
        let p = |i: u32| tube.positions[i as usize];
        let n = (p(b) - p(a)).cross(p(c) - p(a));
        assert!(n.dot(tube.normals[a as usize]) > 0.0);
    }
    let unit = mesh(1);
    for (p, uv) in [
        (Vec3::new(1.0, 0.0, 0.0), Vec2::new(0.0, 0.0)),
        (Vec3::new(0.0, 1.0, 1.0), Vec2::new(0.25, 1.0)),
        (Vec3::new(-1.0, 0.0, 1.0), Vec2::new(0.5, 1.0)),
    ] {
        let i = unit
            .positions
            .iter()
            .position(|q| (*q - p).length() < 1e-5)
            .unwrap_or_else(|| panic!("no vertex at {p}"));
        assert!((unit.uvs[i] - uv).length() < 1e-5, "{p}: {}", unit.uvs[i]);
        assert_close(unit.normals[i], Vec3::new(p.x, p.y, 0.0), 1e-5);
    }
    let e = load_err(&scene(
        r#"<shape type="cylinder"><float name="radius" value="0"/></shape>"#,
    ));
    assert!(
        e.contains("scene.xml:2:1:") && e.contains("positive radius"),
        "{e}"
    );
}

#[test]
fn meshes_load_with_face_normals_and_flipped_uvs() {
    let obj =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0.25\nvt 1 0\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\n";
    let xml = scene(
        r#"<shape type="obj"><string name="filename" value="tri.obj"/></shape>
           <shape type="obj"><string name="filename" value="tri.obj"/>
             <boolean name="face_normals" value="true"/>
             <boolean name="flip_tex_coords" value="false"/></shape>"#,
    );
    let (_d, r) = load_files(
        &[("scene.xml", xml.as_bytes()), ("tri.obj", obj.as_bytes())],
        &options(&[], false),
    );
    let desc = r.unwrap().desc;
    let mesh = |i: usize| match &desc.shapes[i].geometry {
        GeometryDesc::Mesh(m) => m.clone(),
        g => panic!("{g:?}"),
    };
    assert_eq!(mesh(0).normals.len(), 3);
    assert!(mesh(1).normals.is_empty());
    // Mitsuba flips OBJ texture coordinates (v → 1 − v) unless told not to.
    assert_eq!(mesh(0).uvs[0].y, 0.75);
    assert_eq!(mesh(1).uvs[0].y, 0.25);

    let e = load_err(&scene(
        "<shape type=\"ply\"><string name=\"filename\" value=\"no.ply\"/></shape>",
    ));
    assert!(e.contains("scene.xml:2:1:") && e.contains("no.ply"), "{e}");
}

#[test]
fn render_settings_follow_film_sampler_and_integrator() {
    let desc = load(&scene(
        r#"<integrator type="path"><integer name="max_depth" value="5"/>
             <integer name="rr_depth" value="3"/>
             <boolean name="hide_emitters" value="false"/></integrator>
           <sensor type="perspective"><float name="fov" value="40"/>
             <sampler type="independent"><integer name="sample_count" value="7"/>
               <integer name="seed" value="9"/></sampler>
             <film type="hdrfilm"><integer name="width" value="30"/><integer name="height" value="20"/>
               <rfilter type="box"/></film></sensor>"#,
    )).desc;
    let r = desc.render;
    assert_eq!(
        (r.width, r.height, r.spp, r.seed, r.max_depth, r.rr_depth),
        (30, 20, 7, 9, 4, 3)
    );
    // Mitsuba's independent sampler stays independent; its low-discrepancy samplers become
    // Candela's Sobol' sampler, with a warning; no sampler keeps Candela's default.
    assert_eq!(r.sampler, SamplerKind::Independent);
    let (_dir, loaded) = load_files(
        &[(
            "scene.xml",
            scene(
                r#"<sensor type="perspective"><float name="fov" value="40"/>
                     <sampler type="ldsampler"/></sensor>"#,
            )
            .as_bytes(),
        )],
        &options(&[], false),
    );
    let loaded = loaded.unwrap();
    assert_eq!(loaded.desc.render.sampler, SamplerKind::SobolCmj);
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.to_string().contains("Sobol")),
        "{:?}",
        loaded
            .warnings
            .iter()
            .map(|w| w.to_string())
            .collect::<Vec<_>>()
    );
    assert_eq!(load(&scene("")).desc.render.sampler, SamplerKind::default());
    // Without an integrator, Mitsuba's default path tracer has unlimited depth.
    assert_eq!(load(&scene("")).desc.render.max_depth, 1024);
    use candela_scene::mitsuba::candela_max_depth;
    assert_eq!(candela_max_depth(1), Ok(0));
    assert_eq!(candela_max_depth(2), Ok(1));
    assert_eq!(candela_max_depth(-1), Ok(1024));
    assert!(candela_max_depth(0).is_err() && candela_max_depth(-2).is_err());
    let e = load_err(&scene(
        "<integrator type=\"path\"><integer name=\"max_depth\" value=\"0\"/></integrator>",
    ));
    assert!(
        e.contains("scene.xml:2:25:") && e.contains("max_depth 0"),
        "{e}"
    );
    // Both count scattering events, so rr_depth carries over as it is; Mitsuba's default
    // is Candela's.
    assert_eq!(load(&scene("")).desc.render.rr_depth, 5);
    let e = load_err(&scene(
        "<integrator type=\"path\"><integer name=\"rr_depth\" value=\"-1\"/></integrator>",
    ));
    assert!(
        e.contains("scene.xml:2:25:") && e.contains("rr_depth -1"),
        "{e}"
    );
}

#[test]
fn integrators_with_the_path_tracers_expectation_render_as_it() {
    // The volumetric path tracers (no media), the particle tracer and the differentiable
    // ones render what `path` renders in expectation, with their own default depth
    // (Mitsuba 3.9.1: `str(mi.load_dict({'type': 'prb'}))` is max_depth = 6, `path`'s
    // and `volpath`'s 4294967295, i.e. −1); `direct` is direct light only (max_depth 2).
    for (kind, depth) in [
        ("volpath", 1024),
        ("volpathmis", 1024),
        ("ptracer", 1024),
        ("prb", 5),
        ("prb_basic", 5),
        ("direct", 1),
    ] {
        let r = load(&scene(&format!(r#"<integrator type="{kind}"/>"#)))
            .desc
            .render;
        assert_eq!(
            (r.max_depth, r.rr_depth, r.hide_emitters),
            (depth, 5, false),
            "{kind}"
        );
    }
    let (_dir, loaded) = load_files(&[("scene.xml", scene(
                r#"<integrator type="volpath"><integer name="max_depth" value="4"/>
                     <integer name="rr_depth" value="2"/><boolean name="hide_emitters" value="true"/></integrator>"#,
            ).as_bytes())], &options(&[], false));
    let r = loaded.unwrap().desc.render;
    assert_eq!((r.max_depth, r.rr_depth, r.hide_emitters), (3, 2, true));
    // direct's sample counts change the noise only: read, and warned of.
    let (_dir, loaded) = load_files(
        &[(
            "scene.xml",
            scene(
                r#"<integrator type="direct"><integer name="emitter_samples" value="4"/>
                     <integer name="bsdf_samples" value="1"/></integrator>"#,
            )
            .as_bytes(),
        )],
        &options(&[], false),
    );
    let loaded = loaded.unwrap();
    assert_eq!(loaded.desc.render.max_depth, 1);
    assert!(
        loaded.warnings.len() == 1 && loaded.warnings[0].contains("emitter_samples"),
        "{:?}",
        loaded.warnings
    );
    // direct has no max_depth; other integrators are refused by name.
    let e = load_err(&scene(
        r#"<integrator type="direct"><integer name="max_depth" value="3"/></integrator>"#,
    ));
    assert!(
        e.contains("scene.xml:2:27:") && e.contains("max_depth"),
        "{e}"
    );
    let e = load_err(&scene(r#"<integrator type="stokes"/>"#));
    assert!(
        e.contains("scene.xml:2:1:") && e.contains("<integrator type=\"stokes\"> is not supported"),
        "{e}"
    );
}

#[test]
fn unsupported_elements_are_errors_naming_them_or_warnings_when_lenient() {
    for (body, what) in [
        (
            "<shape type=\"cube\"><bsdf type=\"hair\"/></shape>",
            "<bsdf type=\"hair\"> is not supported",
        ),
        (
            "<emitter type=\"sunsky\"/>",
            "<emitter type=\"sunsky\"> is not supported",
        ),
        (
            "<shape type=\"hair\"/>",
            "<shape type=\"hair\"> is not supported",
        ),
        (
            "<medium type=\"rayleigh\"/>",
            "<medium type=\"rayleigh\"> is not supported",
        ),
        (
            "<shape type=\"cube\"><float name=\"radius\" value=\"2\"/></shape>",
            "<float name=\"radius\"> is not supported in shape type=\"cube\"",
        ),
    ] {
        let xml = scene(body);
        let e = load_err(&xml);
        assert!(e.contains(what), "{e}");
        assert!(e.contains("scene.xml:2:"), "{e}");
        let (_d, r) = load_files(&[("scene.xml", xml.as_bytes())], &options(&[], true));
        let loaded = r.unwrap_or_else(|e| panic!("lenient: {e}"));
        assert!(
            loaded
                .warnings
                .iter()
                .any(|w| w.contains(what) && w.contains("scene.xml:2:")),
            "{:?}",
            loaded.warnings
        );
    }
}

#[test]
fn version_0_6_scenes_are_upgraded_as_mitsuba_3_does() {
    // Mitsuba 3.9.1 loads these names from a version 0.6.0 file as to_world,
    // sample_count, max_depth, fov_axis, int_ior (mi.traverse(b)['eta'] = 1.33 for
    // intIOR 1.33 / extIOR 1), and diffuse's diffuseReflectance as reflectance; a
    // <default>'s name is kept, so $myDepth still resolves.
    let desc = load(
        r#"<scene version="0.6.0"><default name="myDepth" value="3"/>
             <integrator type="path"><integer name="maxDepth" value="$myDepth"/></integrator>
             <sensor type="perspective"><float name="fov" value="40"/><string name="fovAxis" value="y"/>
               <transform name="toWorld"><translate x="1"/></transform>
               <sampler type="independent"><integer name="sampleCount" value="9"/></sampler></sensor>
             <shape type="sphere"><bsdf type="dielectric"><float name="intIOR" value="1.33"/>
               <float name="extIOR" value="1"/></bsdf></shape>
             <shape type="cube"><bsdf type="diffuse"><rgb name="diffuseReflectance" value="0.3"/></bsdf></shape>
           </scene>"#,
    ).desc;
    assert_eq!((desc.render.max_depth, desc.render.spp), (2, 9));
    assert_eq!(desc.camera.position, Vec3::X);
    assert!((desc.camera.fov_y_deg - 40.0).abs() < 1e-4);
    let bsdf = |i: usize| {
        let name = &desc.shapes[i].material;
        &desc
            .materials
            .iter()
            .find(|m| &m.name == name)
            .unwrap()
            .bsdf
    };
    match bsdf(0) {
        BsdfDesc::Dielectric { eta, .. } => assert!((eta - 1.33).abs() < 1e-6),
        b => panic!("{b:?}"),
    }
    match bsdf(1) {
        BsdfDesc::OneSided(inner) => match inner.as_ref() {
            BsdfDesc::Diffuse {
                albedo: TextureDesc::Constant(c),
            } => assert_eq!(*c, Vec3::splat(0.3)),
            b => panic!("{b:?}"),
        },
        b => panic!("{b:?}"),
    }
    // Mitsuba's own renaming of odd names, seen in its "unreferenced property" errors:
    // fooBAR → foo_bar, foo2Bar unchanged, FooBar → Foo_bar, uvScale → uv_scale.
    for (name, renamed) in [
        ("fooBAR", "foo_bar"),
        ("foo2Bar", "foo2Bar"),
        ("FooBar", "Foo_bar"),
        ("uvScale", "uv_scale"),
    ] {
        let e = load_err(&format!(
            r#"<scene version="0.6.0"><shape type="cube"><float name="{name}" value="1"/></shape></scene>"#
        ));
        assert!(e.contains(&format!("name=\"{renamed}\"")), "{e}");
    }
}

#[test]
fn malformed_input_is_an_error_with_its_position() {
    let e = load_err("<scene version=\"3.0.0\">\n<shape type=\"cube\">\n</scene>");
    assert!(e.contains("scene.xml:3:") && e.contains("XML"), "{e}");
    let e = load_err(&scene(
        "<sensor type=\"perspective\"><float name=\"fov\" value=\"wide\"/></sensor>",
    ));
    assert!(
        e.contains("scene.xml:2:28:") && e.contains("\"wide\""),
        "{e}"
    );
    let e = load_err(&scene(
        "<shape type=\"cube\"><transform name=\"to_world\"><skew/></transform></shape>",
    ));
    assert!(e.contains("scene.xml:2:47:") && e.contains("<skew>"), "{e}");
    let e = load_err("<scene version=\"three\"/>");
    assert!(
        e.contains("scene.xml:1:1:") && e.contains("\"three\""),
        "{e}"
    );
    let e = load_err("<shape type=\"cube\"/>");
    assert!(e.contains("<scene>"), "{e}");
    let e = load_scene_with(Path::new("/nonexistent/x.xml"), &LoadOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("/nonexistent/x.xml:1:1: cannot read"),
        "{e}"
    );
}

#[test]
fn one_sided_diffuse_is_black_from_behind_as_in_mitsuba() {
    // A 4x4 diffuse square (reflectance 0.5) lit by a point light of intensity 10 at
    // distance 2 and seen from distance 5, from the front and from behind. Centre pixel
    // of a 9x9 box-filtered Mitsuba 3.9.1 render (scalar_rgb, max_depth 2):
    //   front 0.394667, behind 0 (one-sided), behind with twosided 0.394667
    // (the closed form at the exact centre is 0.5/π · 10/2² = 0.3979; the pixel
    // averages a little falloff).
    let render = |z: f32, two_sided: bool| -> f32 {
        let mut bsdf =
            r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>"#.to_string();
        if two_sided {
            bsdf = format!("<bsdf type=\"twosided\">{bsdf}</bsdf>");
        }
        let desc = load(&scene(&format!(
            r#"<integrator type="path"><integer name="max_depth" value="2"/></integrator>
               <sensor type="perspective"><float name="fov" value="30"/>
                 <transform name="to_world"><lookat origin="0,0,{z}" target="0,0,0" up="0,1,0"/></transform>
                 <sampler type="independent"><integer name="sample_count" value="256"/></sampler>
                 <film type="hdrfilm"><integer name="width" value="9"/><integer name="height" value="9"/>
                   <rfilter type="box"/></film></sensor>
               <shape type="rectangle"><transform name="to_world"><scale value="2"/></transform>{bsdf}</shape>
               <emitter type="point"><point name="position" x="0" y="0" z="{}"/>
                 <rgb name="intensity" value="10"/></emitter>"#,
            z * 0.4
        ))).desc;
        let scene = candela_core::build::build(&desc).unwrap();
        let cancel = std::sync::atomic::AtomicBool::new(false);
        let film =
            candela_core::integrator::render(&scene, 0..desc.render.spp, &cancel, &|_| {}).film;
        film.pixel(4, 4).value().x
    };
    let mitsuba = 0.394667;
    let front = render(5.0, false);
    assert!((front / mitsuba - 1.0).abs() < 0.005, "{front}");
    assert_eq!(render(-5.0, false), 0.0);
    let back = render(-5.0, true);
    assert!((back / mitsuba - 1.0).abs() < 0.005, "{back}");
}

#[test]
fn thin_lens_rays_focus_where_mitsuba_focuses() {
    // Every Mitsuba ray through film uv (0.75, 0.25) of this thinlens sensor, whatever
    // its aperture sample, crosses the focus plane (4 along the view axis) at the same
    // point:
    //   s = mi.load_dict({'type': 'thinlens', 'fov': 50.0, 'aperture_radius': 0.2,
    //     'focus_distance': 4.0, 'to_world': ...look_at([1,2,3], [0,0,0], [0,1,0]),
    //     'film': {'type': 'hdrfilm', 'width': 200, 'height': 100}})
    //   r = s.sample_ray(0, 0.5, [0.75, 0.25], ap)[0]  -> r.o + r.d·t on the plane
    let focus = Vec3::new(0.736891, 0.256012, -0.738515);
    let desc = load(&scene(
        r#"<sensor type="thinlens"><float name="fov" value="50"/>
             <float name="aperture_radius" value="0.2"/><float name="focus_distance" value="4"/>
             <transform name="to_world"><lookat origin="1,2,3" target="0,0,0" up="0,1,0"/></transform>
             <film type="hdrfilm"><integer name="width" value="200"/><integer name="height" value="100"/></film>
           </sensor>"#,
    )).desc;
    let cam = Camera::new(&desc.camera, 200, 100);
    let (eye, fwd) = (
        Vec3::new(1.0, 2.0, 3.0),
        -Vec3::new(1.0, 2.0, 3.0).normalize(),
    );
    let mut spread = 0.0f32;
    for u in [
        Vec2::new(0.5, 0.5),
        Vec2::new(0.1, 0.9),
        Vec2::new(0.8, 0.3),
        Vec2::new(0.95, 0.05),
    ] {
        let ray = cam.generate_lens_ray(Vec2::new(150.0, 25.0), u);
        assert!((ray.o - eye).length() <= 0.2 + 1e-5);
        spread = spread.max((ray.o - eye).length());
        let t = (4.0 - (ray.o - eye).dot(fwd)) / ray.d.dot(fwd);
        assert_close(ray.o + ray.d * t, focus, 2e-4);
    }
    assert!(spread > 0.1, "the aperture is open");
    let e = load_err(&scene(
        r#"<sensor type="thinlens"><float name="fov" value="50"/></sensor>"#,
    ));
    assert!(
        e.contains("scene.xml:2:1:") && e.contains("aperture_radius"),
        "{e}"
    );
}

#[test]
fn the_example_scene_loads_cleanly_and_builds() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/mitsuba-cornell.xml"
    ));
    let loaded = load_scene_with(path, &LoadOptions::default()).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(loaded.desc.shapes.len(), 8);
    let scene = candela_core::build::build(&loaded.desc).unwrap();
    let b = scene.bounds();
    assert_close(b.min, Vec3::new(-1.0, 0.0, -1.0), 1e-5);
    assert_close(b.max, Vec3::new(1.0, 2.0, 1.0), 1e-5);
}

#[test]
fn clip_planes_that_would_cut_the_scene_are_warned_of() {
    let warnings = |props: &str| {
        let xml = scene(&format!(r#"<sensor type="perspective">{props}</sensor>"#));
        let (_dir, r) = load_files(&[("scene.xml", xml.as_bytes())], &options(&[], false));
        let loaded = r.unwrap_or_else(|e| panic!("{e}"));
        loaded
            .warnings
            .iter()
            .map(|w| w.to_string())
            .collect::<Vec<_>>()
    };
    // Mitsuba's defaults, or planes that cut less, say nothing.
    assert!(warnings("").is_empty());
    assert!(warnings(
        r#"<float name="near_clip" value="0.01"/><float name="far_clip" value="1e5"/>"#
    )
    .is_empty());
    let w = warnings(r#"<float name="near_clip" value="2"/><float name="far_clip" value="50"/>"#);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("scene.xml:2:") && w[0].contains("near_clip 2") && w[0].contains("nearer"),
        "{w:?}"
    );
    assert!(
        w[1].contains("far_clip 50") && w[1].contains("beyond"),
        "{w:?}"
    );
}

#[test]
fn orthographic_rays_match_mitsubas() {
    // Mitsuba's rays at film uv (1, 0.5), (0.5, 0), (0, 1) of a 200x100 film, unscaled and
    // with to_world scaled by 3 in x and y (its camera space spans [−1, 1] across):
    //   s = mi.load_dict({'type': 'orthographic', 'to_world': ...look_at([1,2,3], [0,0,0],
    //     [0,1,0]) [@ scale([3,3,1])], 'film': {'type': 'hdrfilm', 'width': 200, 'height': 100}})
    //   s.sample_ray(0, 0.5, uv, [0.5, 0.5])[0].o
    // Mitsuba's origins lie on the near clip plane, 0.01 along the ray; Candela's on the
    // camera's plane.
    let plain = [
        [1.94601, 1.99465, 2.67575],
        [0.912812, 2.41723, 2.73844],
        [0.133159, 1.57208, 3.56176],
    ];
    let scaled = [
        [3.84338, 1.99466, 2.04330],
        [0.743781, 3.26239, 2.23134],
        [-1.59518, 0.726924, 4.70130],
    ];
    let d = -Vec3::new(1.0, 2.0, 3.0).normalize();
    for (scale, want) in [("", plain), (r#"<scale x="3" y="3"/>"#, scaled)] {
        let rays = film_rays("orthographic", "", &format!("{scale}{LOOK_AT_ORIGIN}"));
        for (ray, want) in rays.iter().zip(want) {
            assert_close(ray.d, d, 1e-5);
            assert_close(ray.o + 0.01 * ray.d, Vec3::from(want), 1e-4);
        }
    }
    // Pixels must stay square.
    let e = load_err(&scene(
        r#"<sensor type="orthographic"><transform name="to_world"><scale x="2"/></transform></sensor>"#,
    ));
    assert!(e.contains("scene.xml:2:1:") && e.contains("square"), "{e}");
}

#[test]
fn textured_disks_carry_mitsubas_polar_uvs() {
    // Mitsuba 3.9.1's disk: a hit at (x, y) has uv (r, atan2(y, x)/2π in [0, 1)):
    //   sc.ray_intersect(mi.Ray3f([x, y, 1], [0, 0, -1])).uv
    // Candela's own disk maps uvs flat, so a textured one becomes a fan with these uvs; r
    // and φ interpolate linearly over each of its 128 triangles, to within 10⁻³ (u) and
    // half of 1/256 of the way round (v) near the centre.
    let desc = load(&scene(
        r#"<shape type="disk"><bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf></shape>
           <shape type="disk"><transform name="to_world"><translate z="-5"/></transform></shape>"#,
    )).desc;
    assert!(matches!(desc.shapes[0].geometry, GeometryDesc::Mesh(_)));
    assert!(matches!(desc.shapes[1].geometry, GeometryDesc::Disk));
    let scene = candela_core::build::build(&desc).unwrap();
    for (x, y, u, v) in [
        (0.0, 0.5, 0.5, 0.25),
        (-0.3, -0.4, 0.5, 0.647584),
        (0.2, -0.6, 0.632456, 0.801208),
        (0.7, 0.1, std::f32::consts::FRAC_1_SQRT_2, 0.0225836),
        (0.05, 0.9, 0.901388, 0.241167),
    ] {
        let ray = Ray::new(Vec3::new(x, y, 1.0), Vec3::NEG_Z);
        let si = scene.intersect(&ray, f32::INFINITY).expect("a hit");
        assert!((si.uv.x - u).abs() < 1e-3, "({x}, {y}): {}", si.uv);
        assert!((si.uv.y - v).abs() < 2e-3, "({x}, {y}): {}", si.uv);
    }
}
