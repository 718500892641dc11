//! Mitsuba XML in loader tests: a document around a body, loaded as `scene.xml`.

use candela_scene::{LoadOptions, LoadedScene};

use crate::files::load_files;

/// `body` inside a Mitsuba 3 `<scene>` element.
pub fn scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>")
}

/// Loads the document `xml` as `scene.xml`; panics with the error if it fails.
pub fn load(xml: &str) -> LoadedScene {
    let (_dir, r) = load_files(&[("scene.xml", xml.as_bytes())], &LoadOptions::default());
    r.unwrap_or_else(|e| panic!("{e}"))
}

/// The error of loading the document `xml` as `scene.xml`, which must fail; asserts that
/// the message names the file with a position (`scene.xml:…`).
pub fn load_err(xml: &str) -> String {
    let (_dir, r) = load_files(&[("scene.xml", xml.as_bytes())], &LoadOptions::default());
    let e = r.expect_err("should fail").to_string();
    assert!(e.contains("scene.xml:"), "{e}");
    e
}
