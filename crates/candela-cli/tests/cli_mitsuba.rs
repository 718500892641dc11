//! `candela render`/`info` on Mitsuba XML: `-D name=value`, `--lenient`, located errors.

mod common;
use common::candela;

const SCENE: &str = r#"<scene version="3.0.0">
    <default name="res" value="16"/>
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 1, 4" target="0, 1, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="2"/></sampler>
        <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/></film>
    </sensor>
    <shape type="sphere"><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
    <shape type="rectangle"><bsdf type="$material"/></shape>
</scene>"#;

#[test]
fn defines_set_parameters_and_lenient_skips_what_is_unsupported() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.xml");
    std::fs::write(&scene, SCENE).unwrap();
    let (scene, out) = (scene.to_str().unwrap(), dir.path().join("o.pfm"));
    let out = out.to_str().unwrap();

    // $material has no default: a located error, exit 2.
    let r = candela(&["render", scene, "-o", out]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("scene.xml:11:35: undefined parameter \"$material\""),
        "{err}"
    );

    let r = candela(&[
        "render",
        scene,
        "-o",
        out,
        "-D",
        "material=diffuse",
        "-D",
        "res=8",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(String::from_utf8_lossy(&r.stdout).starts_with("8x8, 2 spp"));

    // An unknown BSDF: an error naming it, or with --lenient a warning and an image.
    let r = candela(&["info", scene, "-D", "material=velvet"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("scene.xml:11:29: <bsdf type=\"velvet\"> is not supported"),
        "{err}"
    );
    let r = candela(&["render", scene, "-o", out, "-Dmaterial=velvet", "--lenient"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(err.contains("warning: ") && err.contains("velvet"), "{err}");

    let r = candela(&["info", scene, "-D", "oops"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("NAME=VALUE"));
}
