"""Shared fixtures: a small scene written to a temp folder, the `candela` binary, and a
check that a native call releases the GIL."""

import os
import shutil
import threading
import time
from pathlib import Path
from typing import Callable

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


def _assert_releases_the_gil(call: Callable[[int], None]) -> None:
    """Calls ``call(0)``, ``call(1)``, … (each step twice the work of the last) until one
    call takes 0.3 s (at most 16 steps), while another thread ticks every 10 ms; that
    thread must tick throughout the long call. A thread starved of the GIL would tick
    about once per call."""
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.01)

    t = threading.Thread(target=tick)
    t.start()
    try:
        for step in range(16):
            start = time.monotonic()
            call(step)
            elapsed = time.monotonic() - start
            if elapsed > 0.3:
                break
    finally:
        done.set()
        t.join()
    during = [x for x in ticks if start <= x <= start + elapsed]
    assert elapsed > 0.2 and len(during) >= 0.2 * elapsed / 0.01, (elapsed, len(during))


@pytest.fixture
def assert_releases_the_gil() -> Callable[[Callable[[int], None]], None]:
    """See `_assert_releases_the_gil`."""
    return _assert_releases_the_gil
