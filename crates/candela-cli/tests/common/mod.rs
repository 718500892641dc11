//! Helpers shared by the CLI's end-to-end tests (each test binary uses its own subset).
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// A small lit scene: a floor, an emitting sphere and a point light, 24×16 at 4 spp.
pub const SCENE: &str = r#"
[render]
resolution = [24, 16]
spp = 4
max_depth = 3

[camera]
type = "pinhole"
position = [0, 1, 4]
look_at = [0, 1, 0]
fov = 45

[materials.white]
type = "diffuse"
albedo = 0.7

[[shape]]
type = "rectangle"
material = "white"
transform = [{ rotate = { axis = [1, 0, 0], angle = -90 } }, { scale = 3 }]

[[shape]]
type = "sphere"
center = [0, 1, 0]
radius = 0.5
material = "white"
emission = [4, 3, 2]

[[light]]
type = "point"
position = [1, 3, 1]
intensity = 5
"#;

/// The `candela` binary, ready for arguments.
pub fn command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_candela"))
}

/// Runs `candela` with `args` to completion.
pub fn candela(args: &[&str]) -> Output {
    command().args(args).output().expect("candela runs")
}

/// A path as an argument.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}
