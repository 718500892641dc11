//! The passes a scene asks for: the TOML `[render] aov` key and Mitsuba's `aov`
//! integrator.

use std::path::Path;

use candela_core::aov::{AovKind, AovSet};
use candela_scene::{load_scene_with, parse_toml_scene, LoadOptions, LoadedScene};

fn toml(text: &str) -> Result<AovSet, String> {
    parse_toml_scene(text, Path::new("scene.toml"))
        .map(|d| d.render.aovs)
        .map_err(|e| e.to_string())
}

fn mitsuba(integrator: &str, lenient: bool) -> Result<LoadedScene, String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.xml");
    std::fs::write(
        &path,
        format!("<scene version=\"3.0.0\">\n{integrator}\n</scene>"),
    )
    .unwrap();
    let options = LoadOptions {
        lenient,
        ..LoadOptions::default()
    };
    load_scene_with(&path, &options).map_err(|e| e.to_string())
}

fn set(kinds: &[AovKind]) -> AovSet {
    kinds.iter().copied().collect()
}

#[test]
fn toml_render_aov_lists_the_passes() {
    assert_eq!(toml("[render]\nspp = 4\n").unwrap(), AovSet::NONE);
    assert_eq!(
        toml("[render]\naov = [\"depth\", \"albedo\"]\n").unwrap(),
        set(&[AovKind::Albedo, AovKind::Depth])
    );
    let e = toml("[render]\naov = [\"albedo\", \"uv\"]\n").unwrap_err();
    assert!(
        e.starts_with("scene.toml:2:") && e.contains("unknown variant `uv`"),
        "{e}"
    );
}

#[test]
fn mitsuba_aov_integrator_maps_its_types_and_nests_the_beauty() {
    let loaded = mitsuba(
        r#"<integrator type="aov">
             <string name="aovs" value="dd.y:depth, nn:sh_normal,a:albedo"/>
             <integrator type="path" name="image"><integer name="max_depth" value="4"/></integrator>
           </integrator>"#,
        false,
    )
    .unwrap();
    let r = &loaded.desc.render;
    assert_eq!(
        r.aovs,
        set(&[AovKind::Albedo, AovKind::Normal, AovKind::Depth])
    );
    assert_eq!(r.max_depth, 3, "the nested path tracer's max_depth 4");
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("along the viewing axis")),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn mitsuba_aov_types_candela_lacks_are_refused_or_skipped() {
    let xml = r#"<integrator type="aov"><string name="aovs" value="u:uv,a:albedo"/></integrator>"#;
    let e = mitsuba(xml, false).unwrap_err();
    assert!(
        e.contains("scene.xml:") && e.contains("AOV type \"uv\""),
        "{e}"
    );
    let loaded = mitsuba(xml, true).unwrap();
    assert_eq!(loaded.desc.render.aovs, set(&[AovKind::Albedo]));
    let e = mitsuba(
        r#"<integrator type="aov"><string name="aovs" value="albedo"/></integrator>"#,
        false,
    )
    .unwrap_err();
    assert!(e.contains("not NAME:TYPE"), "{e}");
    let e = mitsuba(r#"<integrator type="aov"/>"#, false).unwrap_err();
    assert!(
        e.contains("scene.xml:2:1:") && e.contains("needs an `aovs` list"),
        "{e}"
    );
}
