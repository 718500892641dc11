//! The `light_sampler`, `ris_candidates` and `lamp_sampling` render keys.

use std::path::Path;

use candela_core::desc::{LampSampling, LightSamplerKind, DEFAULT_RIS_CANDIDATES};
use candela_scene::parse_toml_scene;

fn parse(text: &str) -> Result<candela_core::desc::SceneDesc, String> {
    parse_toml_scene(text, Path::new("scene.toml")).map_err(|e| e.to_string())
}

#[test]
fn every_light_sampler_name_loads() {
    for (name, kind) in [
        ("uniform", LightSamplerKind::Uniform),
        ("power", LightSamplerKind::Power),
        ("array", LightSamplerKind::Array),
        ("ris", LightSamplerKind::Ris),
        ("bvh", LightSamplerKind::Bvh),
        ("ris-bvh", LightSamplerKind::RisBvh),
    ] {
        let desc = parse(&format!("[render]\nlight_sampler = \"{name}\"\n")).unwrap();
        assert_eq!(desc.render.light_sampler, kind, "{name}");
        assert_eq!(desc.render.ris_candidates, DEFAULT_RIS_CANDIDATES);
    }
    let desc = parse("[render]\nlight_sampler = \"ris\"\nris_candidates = 32\n").unwrap();
    assert_eq!(desc.render.ris_candidates, 32);
}

#[test]
fn bad_light_sampler_values_point_at_the_value() {
    assert_eq!(
        parse("[render]\nlight_sampler = \"ris_bvh\"\n").unwrap_err(),
        "scene.toml:2:17: unknown variant `ris_bvh`, expected one of `uniform`, `power`, \
         `array`, `ris`, `bvh`, `ris-bvh`"
    );
    let zero = parse("[render]\nris_candidates = 0\n").unwrap_err();
    assert!(zero.starts_with("scene.toml:2:18: "), "{zero}");
    let negative = parse("[render]\nris_candidates = -3\n").unwrap_err();
    assert!(negative.starts_with("scene.toml:2:18: "), "{negative}");
}

#[test]
fn lamp_sampling_loads_and_defaults_to_area() {
    assert_eq!(
        parse("[render]\n").unwrap().render.lamp_sampling,
        LampSampling::Area
    );
    for (name, kind) in [
        ("area", LampSampling::Area),
        ("solid-angle", LampSampling::SolidAngle),
    ] {
        let desc = parse(&format!("[render]\nlamp_sampling = \"{name}\"\n")).unwrap();
        assert_eq!(desc.render.lamp_sampling, kind, "{name}");
    }
    assert_eq!(
        parse("[render]\nspp = 4\nlamp_sampling = \"solid_angle\"\n").unwrap_err(),
        "scene.toml:3:17: unknown variant `solid_angle`, expected `area` or `solid-angle`"
    );
}
