"""Shared fixtures: a small scene written to a temp folder, and the `candela` binary."""

import os
import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]

# A floor, an emitting sphere and a point light (the CLI tests' scene), 24x16.
SCENE = """
[render]
resolution = [24, 16]
spp = 8
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
"""


@pytest.fixture
def scene_path(tmp_path: Path) -> Path:
    p = tmp_path / "scene.toml"
    p.write_text(SCENE)
    return p


@pytest.fixture(scope="session")
def candela_bin() -> Path:
    """The CLI built from this checkout (CANDELA_BIN, else target/release/candela)."""
    env = os.environ.get("CANDELA_BIN")
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    for p in [Path(env)] if env else [target / "release" / "candela", REPO / "target/release/candela"]:
        if p.exists():
            return p
    found = shutil.which("candela")
    if found:
        return Path(found)
    pytest.skip("skipped: no candela binary (cargo build --release first)")
