"""Shared fixtures: a small scene written to a temp folder, and the `candela` binary."""

import os
import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]

# A floor, an emitting sphere and a point light, 24x16: the CLI tests' scene, read from
# their source so that the two suites render the same thing.
_COMMON = (REPO / "crates/candela-cli/tests/common/mod.rs").read_text()
SCENE = _COMMON.split('pub const SCENE: &str = r#"', 1)[1].split('"#;', 1)[0]


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
