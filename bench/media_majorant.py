"""Two Candela binaries on one scene, tile by tile: what a change to volume tracking
(here the coarse majorant grid, issue #39) does to the image, the noise and the time.

Both binaries render `--seeds` independent renders of `--spp` samples, interleaved (so
that both see the same machine load). Per 16×16 tile and channel, Welch's t-test
compares the K tile means of one binary with the other's (as bench/media_tiles.py does
against Mitsuba): an unbiased change fails no tile beyond chance. It prints each
binary's equal-spp relMSE from the variance across seeds (see media_tiles.py) and the
median render time per sample. Instructions per path come from bench/lanes/ipp.sh.

    bench/.venv/bin/python bench/media_majorant.py BEFORE_BINARY [AFTER_BINARY] \\
        [--scene bench/scenes/media-smoke.toml] [--seeds 12] [--spp 16] [--res 128x96]
"""

import argparse
import os
import statistics
import sys

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, images, machine, report  # noqa: E402
from media_tiles import ALPHA_FAMILY, ALPHA_TILE, tile_means, welch_p  # noqa: E402

OUT = os.path.join(BENCH_DIR, "out", "media_majorant")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before")
    ap.add_argument("after", nargs="?", default=os.path.join(REPO, "target", "release",
                                                              "candela"))
    ap.add_argument("--scene", default=os.path.join(BENCH_DIR, "scenes", "media-smoke.toml"))
    ap.add_argument("--seeds", type=int, default=12)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--res", default="128x96")
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    import mitsuba as mi  # EXR I/O only
    mi.set_variant("scalar_rgb")
    load_before = machine.loadavg()
    bins = {"before": a.before, "after": a.after}
    imgs = {k: [] for k in bins}
    secs = {k: [] for k in bins}
    for seed in range(1, a.seeds + 1):
        for key, binary in bins.items():
            out = os.path.join(OUT, f"{key}_{seed}.exr")
            m = candela.run([binary, "render", a.scene, "-o", out, "--spp", str(a.spp),
                             "--res", a.res, "--seed", str(seed), "--threads",
                             str(a.threads)])
            secs[key].append(float(m["secs"]))
            imgs[key].append(images.load_exr(out))
    tiles = {k: np.array([tile_means(x) for x in v]) for k, v in imgs.items()}
    ty, tx = tiles["before"].shape[1:3]
    ps = [welch_p(tiles["after"][:, j, i, c], tiles["before"][:, j, i, c])[1]
          for j in range(ty) for i in range(tx) for c in range(3)]
    sidak = 1.0 - (1.0 - ALPHA_FAMILY) ** (1.0 / len(ps))
    relvar = images.relative_variances(imgs)
    rel = {k: float(v.mean()) for k, v in relvar.items()}
    ratio, ratio_se = images.tile_ratio(images.tile_sums(relvar["after"]),
                                        images.tile_sums(relvar["before"]),
                                        np.random.default_rng(1))
    h, w = imgs["before"][0].shape[:2]
    per = {k: statistics.median(v) / (h * w * a.spp) * 1e9 for k, v in secs.items()}
    rows = [[k, os.path.relpath(bins[k], REPO), report.fmt(rel[k], 5),
             report.fmt(rel[k] / rel["before"], 3), report.fmt(per[k], 0),
             report.fmt(per[k] / per["before"], 3)] for k in bins]
    m = machine.describe(REPO)
    print(f"Machine: {m['cpu']}, nproc {m['nproc']}; date {m['date']}; candela git "
          f"{m['git']}; load before {load_before}, after {machine.loadavg()}.")
    print(f"`{os.path.relpath(a.scene, REPO)}`, {w}×{h}, {a.spp} spp, seeds 1–{a.seeds} "
          f"each, {a.threads} threads, interleaved.\n")
    print(report.table(["", "binary", "relMSE (variance)", "÷ before", "render ns/sample",
                        "÷ before"], rows))
    flagged = sum(p < ALPHA_TILE for p in ps)
    print(f"\nrelMSE after ÷ before {ratio:.3f} ± {ratio_se:.3f} (bootstrap over tiles).")
    print(f"Per-tile Welch test, {len(ps)} tile-channels: {flagged} with p < {ALPHA_TILE} "
          f"(expected by chance {ALPHA_TILE * len(ps):.2f}), smallest p {min(ps):.2g}; "
          f"Šidák level {sidak:.2g}: {'pass' if min(ps) >= sidak else '**fail**'}.")


if __name__ == "__main__":
    main()
