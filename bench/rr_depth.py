"""Where Russian roulette should start: efficiency of `--rr-depth` values on scenes.

For each scene and each rr_depth, renders SEEDS independent images (same spp, resolution
and thread count) and measures
  - the per-pixel variance of one render, as the sample variance across the seeds of
    each pixel and channel, relative to (m² + ε) with m the pixel's mean over all renders
    of the scene and ε = 10⁻² (relMSE's convention, benchlib.images.RELMSE_EPS). Roulette
    is unbiased, so this variance is the whole of the error;
  - the cost: the integrator's seconds (from candela's summary line) and its rays.
Efficiency is 1 / (relative variance × cost), shown against the first rr_depth given.
Its uncertainty (±, one standard error) comes from a bootstrap over 16×16-pixel tiles.
Rays are the steadier cost on a loaded machine; seconds include the per-path costs that
do not scale with rays.

Usage: bench/rr_depth.sh [--rr 3,5] [--spp 16] [--seeds 8] [--res 256x256]
                          [--threads 1] [SCENE ...]   (default: the example scenes)
"""

import argparse
import os
import re
import subprocess
import sys
import time

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, machine, report  # noqa: E402
from benchlib.images import TILE, read_pfm, relative_variances, tile_ratio, tile_sums  # noqa: E402

CANDELA = os.path.join(REPO, "target", "release", "candela")
OUT = os.path.join(BENCH_DIR, "out", "rr_depth")
SCENES = ["scenes/cornell.toml", "scenes/mitsuba-cornell.xml", "scenes/glass_sphere.toml",
          "scenes/rough_metals.toml", "scenes/microfacets.toml", "scenes/environment.toml",
          "scenes/ies-room.toml", "scenes/many_lights.toml", "scenes/dof.toml",
          "scenes/instances.toml"]
BOOTSTRAP = 200


def render(scene: str, rr: int, seed: int, a) -> tuple:
    out = os.path.join(OUT, f"{os.path.basename(scene)}_rr{rr}_{seed}.pfm")
    cmd = [CANDELA, "render", scene, "-o", out, "--spp", str(a.spp), "--seed", str(seed),
           "--threads", str(a.threads), "--res", a.res, "--rr-depth", str(rr)]
    m = candela.run(cmd, cwd=REPO)
    secs = float(m["secs"])
    return read_pfm(out), secs, float(m["rays"]) * 1e6 * secs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rr", default="3,5", help="rr_depth values; the first is the baseline")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--res", default="256x256")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--skip-build", action="store_true")
    ap.add_argument("scenes", nargs="*", default=SCENES)
    a = ap.parse_args()
    rrs = [int(v) for v in a.rr.split(",")]
    if not a.skip_build:
        subprocess.run(["cargo", "build", "--release", "-p", "candela-cli"], cwd=REPO,
                       check=True)
    os.makedirs(OUT, exist_ok=True)
    print(f"[rr_depth] {machine.cpu_model()}, load {machine.loadavg()}, "
          f"git {machine.git_revision(REPO)}", flush=True)
    t0 = time.time()
    rng = np.random.default_rng(1)
    rows = []
    for scene in a.scenes:
        runs = {rr: [render(scene, rr, s + 1, a) for s in range(a.seeds)] for rr in rrs}
        rel = relative_variances({rr: [img for img, _, _ in runs[rr]] for rr in rrs})
        per_rr = {}
        for rr in rrs:
            per_rr[rr] = dict(tiles=tile_sums(rel[rr]),
                              secs=np.mean([s for _, s, _ in runs[rr]]),
                              rays=np.mean([r for _, _, r in runs[rr]]))
        n_tiles = len(per_rr[rrs[0]]["tiles"])
        base = per_rr[rrs[0]]
        row = [os.path.basename(scene)]
        for rr in rrs:
            r = per_rr[rr]
            var_ratio, se = tile_ratio(base["tiles"], r["tiles"], rng, BOOTSTRAP)
            rel_var = r["tiles"].sum() / (n_tiles * TILE * TILE)
            eff_s = var_ratio * base["secs"] / r["secs"]
            eff_ray = var_ratio * base["rays"] / r["rays"]
            row += [f"{rel_var:.3e}", f"{r['rays'] / 1e6:.2f}", f"{r['secs']:.2f}",
                    f"{eff_ray:.3f} ± {se * base['rays'] / r['rays']:.3f}", f"{eff_s:.2f}"]
        rows.append(row)
        print(f"[rr_depth] {row}", flush=True)
    header = ["scene"]
    for rr in rrs:
        header += [f"rr {rr}: rel. var.", "M rays", "s", "eff./ray", "eff./s"]
    print()
    print(f"`bench/rr_depth.sh --rr {a.rr} --spp {a.spp} --seeds {a.seeds} --res {a.res} "
          f"--threads {a.threads}`, {machine.cpu_model()}, load after "
          f"{machine.loadavg()}, {time.time() - t0:.0f} s")
    print()
    print(report.table(header, rows))


if __name__ == "__main__":
    main()
