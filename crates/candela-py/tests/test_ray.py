"""Distribution on Ray: a local Ray with 2 workers renders 4 chunks that merge to the
single-process render bit for bit, also when a worker is killed mid-render (the task
is retried)."""

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import candela

ray = pytest.importorskip("ray", reason="skipped: ray not installed (pip install candela[ray])")
from candela.distributed import chunk_ranges, render_distributed  # noqa: E402


@pytest.fixture(scope="module")
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def test_chunks_cover_the_samples_once():
    assert chunk_ranges(10, 4) == [range(0, 2), range(2, 5), range(5, 7), range(7, 10)]
    with pytest.raises(ValueError):
        chunk_ranges(3, 4)


def test_four_chunks_on_two_workers_equal_the_single_render(local_ray, scene_path):
    film = render_distributed(str(scene_path), spp=8, chunks=4)
    whole = candela.render(candela.load(scene_path), spp=8)
    assert film.complete
    assert np.array_equal(film.image().view(np.uint32), whole.view(np.uint32))


def test_a_killed_worker_is_retried_and_the_result_is_still_exact(local_ray, scene_path, tmp_path):
    log = tmp_path / "tasks"
    log.mkdir()
    spp = 16384  # long enough chunks (a second or more each, even on a quiet machine) to be killed mid-render
    result = {}

    def run():
        result["film"] = render_distributed(str(scene_path), spp=spp, chunks=4, task_log=str(log))

    t = threading.Thread(target=run)
    t.start()
    deadline = time.monotonic() + 60
    while not any(log.iterdir()) and time.monotonic() < deadline:
        time.sleep(0.02)
    victim = next(log.iterdir())
    time.sleep(0.05)  # the task has started rendering
    pid = int(victim.read_text().split()[0])
    os.kill(pid, signal.SIGKILL)
    t.join(timeout=300)
    assert "film" in result, "the distributed render did not finish"
    attempts = sorted(p.name.split(".")[0] for p in log.iterdir())
    killed_range = victim.name.split(".")[0]
    assert attempts.count(killed_range) >= 2, f"{killed_range} was not retried: {attempts}"
    whole = candela.render(candela.load(scene_path), spp=spp)
    assert np.array_equal(result["film"].image().view(np.uint32), whole.view(np.uint32))


def test_the_command_line_entry_point_shipping_the_scene(scene_path, tmp_path):
    """`--ship` uploads the scene's folder as the job's working_dir (no shared paths)."""
    out = tmp_path / "out.exr"
    p = subprocess.run(
        [sys.executable, "-m", "candela.distributed", str(scene_path), "--spp", "8",
         "--chunks", "4", "--workers", "2", "--ship", "-o", str(out)],
        capture_output=True, text=True, timeout=300,
    )
    assert p.returncode == 0, p.stderr
    assert "8 spp in 4 chunks" in p.stdout
    film = candela.read_film(out)
    assert np.array_equal(film.image(), candela.render(candela.load(scene_path), spp=8))
