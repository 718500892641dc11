"""The Python API: loading and its errors, rendering to NumPy (bit for bit the CLI's
image), writing, info, exact merges of sample ranges, pickling, interruption."""

import pickle
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import candela


def read_pfm(path: Path) -> np.ndarray:
    data = path.read_bytes()
    parts = data.split(b"\n", 3)
    assert parts[0] == b"PF"
    w, h = map(int, parts[1].split())
    assert float(parts[2]) < 0, "little-endian"
    return np.frombuffer(parts[3], dtype="<f4").reshape(h, w, 3)[::-1]


def test_render_is_a_float32_array_equal_to_the_cli_bit_for_bit(scene_path, candela_bin, tmp_path):
    scene = candela.load(scene_path)
    img = candela.render(scene, spp=8, seed=5)
    assert img.dtype == np.float32 and img.shape == (16, 24, 3)
    assert img.mean() > 0
    out = tmp_path / "cli.pfm"
    subprocess.run(
        [candela_bin, "render", scene_path, "--spp", "8", "--seed", "5", "-o", out], check=True,
        capture_output=True,
    )
    assert np.array_equal(img.view(np.uint32), read_pfm(out).view(np.uint32))
    # Another seed, another image; threads do not matter.
    assert not np.array_equal(img, candela.render(scene, spp=8, seed=6))
    assert np.array_equal(img, candela.render(scene, spp=8, seed=5, threads=1))


def test_load_errors_are_located_and_params_are_defines(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[render]\nresolution = [4, 4]\nspp = \"many\"\n")
    with pytest.raises(candela.SceneError) as e:
        candela.load(bad)
    assert str(e.value).startswith(f"{bad}:3:"), str(e.value)
    with pytest.raises(candela.SceneError):
        candela.load(tmp_path / "missing.toml")
    xml = tmp_path / "s.xml"
    xml.write_text(
        '<scene version="3.0.0"><default name="res" value="8"/>'
        '<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="$res"/>'
        '<integer name="height" value="$res"/></film></sensor></scene>'
    )
    assert candela.load(xml).resolution == (8, 8)
    assert candela.load(xml, res=6).resolution == (6, 6)


def test_sample_ranges_merge_exactly_in_any_order(scene_path):
    scene = candela.load(scene_path)
    whole = candela.render(scene, spp=8)
    for bounds in ([0, 4, 8], [0, 1, 7, 8], [0, 3, 4, 5, 8], list(range(9))):
        films = [candela.render(scene, spp=8, samples=range(a, b)) for a, b in zip(bounds, bounds[1:])]
        merged = candela.merge(films[::-1])
        assert merged.complete and merged.samples == [(0, 8)]
        assert np.array_equal(merged.image().view(np.uint32), whole.view(np.uint32)), bounds
    half = candela.render(scene, spp=8, samples=range(0, 4))
    assert not half.complete
    with pytest.raises(candela.MergeError, match="overlap"):
        candela.merge([half, candela.render(scene, spp=8, samples=range(2, 6))])
    with pytest.raises(candela.MergeError, match="seed 1 differs"):
        candela.merge([half, candela.render(scene, spp=8, seed=1, samples=range(4, 8))])
    with pytest.raises(ValueError):
        candela.render(scene, spp=8, samples=range(4, 9))


def test_films_pickle_and_save_as_parts_the_cli_merges(scene_path, candela_bin, tmp_path):
    scene = candela.load(scene_path)
    a = candela.render(scene, spp=8, samples=range(0, 3))
    b = pickle.loads(pickle.dumps(candela.render(scene, spp=8, samples=range(3, 8))))
    a.save(tmp_path / "a.exr")
    candela.write(tmp_path / "b.exr", b)
    subprocess.run(
        [candela_bin, "merge", tmp_path / "a.exr", tmp_path / "b.exr", "-o", tmp_path / "m.exr"],
        check=True, capture_output=True,
    )
    merged = candela.read_film(tmp_path / "m.exr")
    assert np.array_equal(merged.image(), candela.render(scene, spp=8))
    assert merged.fingerprint == a.fingerprint
    assert candela.info(scene)["fingerprint"] == candela.render(scene, samples=range(0, 1)).fingerprint


def test_write_formats_and_info(scene_path, tmp_path):
    scene = candela.load(scene_path)
    img = candela.render(scene, spp=2)
    candela.write(tmp_path / "o.pfm", img)
    assert np.array_equal(read_pfm(tmp_path / "o.pfm"), img)
    candela.write(tmp_path / "o.png", img, exposure=1.0, tonemap="aces")
    assert (tmp_path / "o.png").read_bytes()[:4] == b"\x89PNG"
    candela.write(tmp_path / "o.exr", img)
    with pytest.raises(ValueError, match="unsupported output format"):
        candela.write(tmp_path / "o.jpg", img)
    with pytest.raises(ValueError):
        candela.write(tmp_path / "o.png", img, tonemap="nonsense")
    i = candela.info(scene)
    assert i["resolution"] == (24, 16) and i["spp"] == 4 and i["lights"] == 2
    assert i["materials"] == ["white"]


def test_progress_bar_reaches_100(scene_path, capsys):
    candela.render(candela.load(scene_path), spp=4, progress=True)
    assert "100%" in capsys.readouterr().err


INTERRUPT = r"""
import sys, time, candela
scene = candela.load(sys.argv[1])
print("started", flush=True)
t = time.monotonic()
try:
    candela.render(scene, spp=1_000_000)
except KeyboardInterrupt:
    print(f"interrupted after {time.monotonic() - t:.2f}", flush=True)
    img = candela.render(scene, spp=1)   # the module still works
    print("ok", img.shape, flush=True)
"""


def test_ctrl_c_stops_the_render_cleanly(scene_path):
    p = subprocess.Popen(
        [sys.executable, "-c", INTERRUPT, str(scene_path)], stdout=subprocess.PIPE, text=True
    )
    assert p.stdout.readline().strip() == "started"
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=60)
    assert "interrupted after" in out and "ok (16, 24, 3)" in out, out
    assert p.returncode == 0


def test_the_gil_is_released_while_rendering(scene_path, assert_releases_the_gil):
    scene = candela.load(scene_path)
    # Long enough a render to count ticks in, whatever the machine's speed: the sample
    # count doubles from 512 until one render takes 0.3 s.
    assert_releases_the_gil(lambda step: candela.render(scene, spp=512 << step, threads=1))
