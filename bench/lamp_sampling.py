"""Near lamps by area or in solid angle: efficiency of `--lamp-sampling` on scenes.

For each scene, renders SEEDS images with `--lamp-sampling area` and SEEDS with
`--lamp-sampling solid-angle` (same spp, resolution and thread count; the two modes
alternate, so a burst of load elsewhere hits both alike) and measures
  - the error of one render: the sample variance across the seeds of each pixel and
    channel, relative to (m² + ε), m the pixel's mean over every render of the scene and
    ε = 10⁻² (relMSE's convention, benchlib.images.RELMSE_EPS). Both modes are unbiased,
    so the variance is the whole of the error, and no reference image is needed;
  - the cost: the integrator's seconds (candela's summary line), the median over seeds.
Efficiency of solid angle against area = (area's variance × seconds) ÷ (solid angle's):
above 1, drawing near lamps in solid angle reaches a given error sooner. The variance
ratio's standard error (±) comes from a bootstrap over 16×16-pixel tiles.

Usage: bench/lamp_sampling.sh [--spp 64] [--seeds 6] [--downscale 2 | --res WxH]
                              [--threads 2] [--max-depth N] [--skip-build] [SCENE ...]
"""

import argparse
import os
import statistics
import subprocess
import sys
import time
import tomllib

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, machine, report  # noqa: E402
from benchlib.images import read_pfm, relative_variances, tile_ratio, tile_sums  # noqa: E402

CANDELA = os.path.join(REPO, "target", "release", "candela")
OUT = os.path.join(BENCH_DIR, "out", "lamp_sampling")
SCENES = ["scenes/cornell.toml", "scenes/plastics.toml", "bench/scenes/softbox.toml",
          "scenes/many_lights.toml", "scenes/microfacets.toml", "scenes/rough_metals.toml"]
MODES = ["area", "solid-angle"]
BOOTSTRAP = 200


def resolution(scene: str, a) -> str:
    if a.res:
        return a.res
    downscale = a.downscale
    with open(os.path.join(REPO, scene), "rb") as f:
        w, h = tomllib.load(f).get("render", {}).get("resolution", [512, 512])
    return f"{max(1, w // downscale)}x{max(1, h // downscale)}"


def render(scene: str, mode: str, seed: int, res: str, a) -> tuple:
    out = os.path.join(OUT, f"{os.path.basename(scene)}_{mode}_{seed}.pfm")
    cmd = [CANDELA, "render", scene, "-o", out, "--spp", str(a.spp), "--seed", str(seed),
           "--threads", str(a.threads), "--res", res, "--lamp-sampling", mode]
    if a.max_depth is not None:
        cmd += ["--max-depth", str(a.max_depth)]
    secs = float(candela.run(cmd, cwd=REPO)["secs"])
    return read_pfm(out), secs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--downscale", type=int, default=2,
                    help="divides a TOML scene's resolution")
    ap.add_argument("--res", help="WIDTHxHEIGHT instead (needed for other formats)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--max-depth", type=int, help="override the scenes' max_depth")
    ap.add_argument("--skip-build", action="store_true")
    ap.add_argument("scenes", nargs="*", default=SCENES)
    a = ap.parse_args()
    if a.seeds < 2:
        ap.error("--seeds must be at least 2 (the error is the variance across seeds)")
    if not a.skip_build:
        subprocess.run(["cargo", "build", "--release", "-p", "candela-cli"], cwd=REPO,
                       check=True)
    os.makedirs(OUT, exist_ok=True)
    print(f"[lamp_sampling] {machine.cpu_model()}, load {machine.loadavg()}, "
          f"git {machine.git_revision(REPO)}", flush=True)
    t0 = time.time()
    rng = np.random.default_rng(1)
    rows = []
    for scene in a.scenes:
        res = resolution(scene, a)
        runs = {mode: [] for mode in MODES}
        for seed in range(1, a.seeds + 1):
            for mode in MODES:
                runs[mode].append(render(scene, mode, seed, res, a))
        rel = relative_variances({mode: [img for img, _ in runs[mode]] for mode in MODES})
        per_mode = {mode: dict(tiles=tile_sums(rel[mode]), rel=float(rel[mode].mean()),
                               secs=statistics.median(s for _, s in runs[mode]))
                    for mode in MODES}
        area, solid = per_mode["area"], per_mode["solid-angle"]
        ratio, se = tile_ratio(area["tiles"], solid["tiles"], rng, BOOTSTRAP)
        # candela prints seconds to 0.01 s: a render shorter than that has no ratio.
        timed = min(area["secs"], solid["secs"]) > 0
        time_ratio = solid["secs"] / area["secs"] if timed else float("nan")
        rows.append([scene, res, f"{area['rel']:.4e}", f"{area['secs']:.2f}",
                     f"{solid['rel']:.4e}", f"{solid['secs']:.2f}",
                     f"{ratio:.3f} ± {se:.3f}", f"{time_ratio:.3f}",
                     f"**{ratio / time_ratio:.2f}**" if timed else "n/a"])
        print(f"[lamp_sampling] {rows[-1]}", flush=True)
    header = ["scene", "res", "area: rel. var.", "s", "solid angle: rel. var.", "s",
              "variance ratio", "time ratio", "efficiency"]
    depth = f" --max-depth {a.max_depth}" if a.max_depth is not None else ""
    print()
    print(f"`bench/lamp_sampling.sh --spp {a.spp} --seeds {a.seeds} --downscale "
          f"{a.downscale} --threads {a.threads}{depth}`, {machine.cpu_model()}, "
          f"load after {machine.loadavg()}, git {machine.git_revision(REPO)}, "
          f"{time.time() - t0:.0f} s")
    print()
    print(report.table(header, rows))


if __name__ == "__main__":
    main()
