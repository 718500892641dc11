//! Media in the scene formats: Mitsuba's `<medium>` (homogeneous and heterogeneous with a
//! `.vol` grid), `<phase>`, the `null` BSDF, shape and sensor media, and the TOML
//! equivalents; both formats describe the same scene the same way, and bad references
//! are located errors.

use std::path::Path;

use candela_core::desc::*;
use candela_scene::mitsuba::parse_mitsuba;
use candela_scene::vol::write_vol;
use candela_scene::{parse_toml_scene, LoadOptions};
use glam::{Mat4, Vec3};

fn grid() -> GridDesc {
    GridDesc {
        res: [2, 2, 2],
        channels: 1,
        data: vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0],
    }
}

const XML: &str = r#"<scene version="3.0.0">
  <integrator type="volpath"><integer name="max_depth" value="9"/></integrator>
  <medium type="homogeneous" id="fog">
    <rgb name="sigma_t" value="0.5, 1, 2"/>
    <float name="albedo" value="0.9"/>
    <float name="scale" value="2"/>
    <phase type="hg"><float name="g" value="0.6"/></phase>
  </medium>
  <sensor type="perspective">
    <ref id="fog"/>
  </sensor>
  <shape type="sphere">
    <bsdf type="null"/>
    <medium type="heterogeneous" name="interior">
      <volume name="sigma_t" type="gridvolume">
        <string name="filename" value="d.vol"/>
        <transform name="to_world"><scale value="2"/></transform>
      </volume>
      <volume name="albedo" type="constvolume"><rgb name="value" value="0.5"/></volume>
      <float name="scale" value="3"/>
      <phase type="isotropic"/>
    </medium>
    <ref name="exterior" id="fog"/>
  </shape>
  <shape type="cube"><bsdf type="diffuse"/></shape>
</scene>"#;

const TOML: &str = r#"
[render]
max_depth = 8  # Mitsuba's 9: it counts the camera vertex

[camera]
medium = "fog"

[media.fog]
type = "homogeneous"
sigma_t = [0.5, 1, 2]
albedo = 0.9
scale = 2
g = 0.6

[media.smoke]
type = "grid"
file = "d.vol"
albedo = 0.5
scale = 3
transform = [{ scale = 2 }]

[materials.boundary]
type = "null"

[materials.white]
type = "diffuse"

[[shape]]
type = "sphere"
material = "boundary"
interior = "smoke"
exterior = "fog"

[[shape]]
type = "cube"
material = "white"
"#;

fn with_vol(f: impl FnOnce(&Path)) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("d.vol"),
        write_vol(&grid(), Vec3::ZERO, Vec3::ONE),
    )
    .unwrap();
    f(dir.path());
}

/// What matters of a description's media, in a comparable form.
fn summary(d: &SceneDesc) -> String {
    let media: Vec<String> = d
        .media
        .media
        .iter()
        .map(|m| {
            let kind = match &m.kind {
                MediumKindDesc::Homogeneous { sigma_t, albedo } => {
                    format!("homogeneous σt {sigma_t} albedo {albedo}")
                }
                MediumKindDesc::Grid {
                    sigma_t,
                    albedo,
                    scale,
                    to_world,
                } => format!(
                    "grid {:?} {:?} albedo {:?} scale {scale} to_world {to_world}",
                    sigma_t.res, sigma_t.data, albedo
                ),
            };
            format!("{kind} phase {:?}", m.phase)
        })
        .collect();
    let interior = |s: &ShapeMediaDesc| {
        let name = |n: &Option<String>| {
            n.as_ref().map(|n| {
                let m = d.media.media.iter().find(|m| &m.name == n).unwrap();
                matches!(m.kind, MediumKindDesc::Grid { .. })
            })
        };
        format!(
            "shape {} inside grid {:?} outside grid {:?}",
            s.shape,
            name(&s.interior),
            name(&s.exterior)
        )
    };
    let mut media = media;
    media.sort();
    format!(
        "{media:?} {:?} camera medium {} depth {}",
        d.media.shapes.iter().map(interior).collect::<Vec<_>>(),
        d.media.camera.is_some(),
        d.render.max_depth
    )
}

#[test]
fn mitsuba_and_toml_describe_the_same_media() {
    with_vol(|dir| {
        let xml = parse_mitsuba(XML, &dir.join("s.xml"), &LoadOptions::default()).unwrap();
        let toml = parse_toml_scene(TOML, &dir.join("s.toml")).unwrap();
        assert!(xml.warnings.is_empty(), "{:?}", xml.warnings);
        let (a, b) = (summary(&xml.desc), summary(&toml));
        assert_eq!(a, b);
        assert!(
            a.contains("homogeneous σt [1, 2, 4] albedo [0.9, 0.9, 0.9]"),
            "{a}"
        );
        assert!(a.contains("scale 3"), "{a}");
        assert_eq!(
            xml.desc.media.camera.as_deref(),
            Some("fog"),
            "the sensor's <ref> is its medium"
        );
        // Both build, and render with the volumetric integrator.
        for d in [&xml.desc, &toml] {
            let scene = candela_core::build::build(d).unwrap();
            let media = scene.media.as_ref().expect("media");
            assert_eq!(media.media.len(), 2);
            assert!(media.camera.is_some());
            assert!(media
                .surfaces
                .iter()
                .any(|s| s.null && s.interface.is_some()));
        }
        let grid_to_world = xml.desc.media.media.iter().find_map(|m| match &m.kind {
            MediumKindDesc::Grid { to_world, .. } => Some(*to_world),
            _ => None,
        });
        assert_eq!(grid_to_world, Some(Mat4::from_scale(Vec3::splat(2.0))));
    });
}

#[test]
fn bad_media_references_are_located() {
    with_vol(|dir| {
        let opts = LoadOptions::default();
        let xml = XML.replace(
            r#"<ref name="exterior" id="fog"/>"#,
            r#"<ref name="exterior" id="mist"/>"#,
        );
        let e = parse_mitsuba(&xml, &dir.join("s.xml"), &opts)
            .err()
            .unwrap()
            .to_string();
        assert!(e.ends_with("no <medium> has the id \"mist\""), "{e}");
        assert!(e.contains("s.xml:23:5:"), "{e}");
        let xml = XML.replace("d.vol", "missing.vol");
        let e = parse_mitsuba(&xml, &dir.join("s.xml"), &opts)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("missing.vol: cannot read"), "{e}");
        let xml = XML.replace(
            r#"<phase type="isotropic"/>"#,
            r#"<phase type="rayleigh"/>"#,
        );
        let e = parse_mitsuba(&xml, &dir.join("s.xml"), &opts)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("s.xml:21:7:") && e.contains("isotropic and hg are"),
            "{e}"
        );

        let toml = TOML.replace("exterior = \"fog\"", "exterior = \"mist\"");
        let d = parse_toml_scene(&toml, &dir.join("s.toml")).unwrap();
        let e = candela_core::build::build(&d).err().unwrap().to_string();
        assert!(
            e.starts_with("") && e.ends_with("unknown medium \"mist\""),
            "{e}"
        );
        let toml = TOML.replace("g = 0.6", "g = 0.6\ndensity = 3");
        let e = parse_toml_scene(&toml, &dir.join("s.toml"))
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("s.toml:14:1") && e.contains("unknown field `density`"),
            "{e}"
        );
        let toml = TOML.replace("file = \"d.vol\"", "file = \"nope.vol\"");
        let e = parse_toml_scene(&toml, &dir.join("s.toml"))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("s.toml:17:8: cannot load grid"), "{e}");
    });
}
