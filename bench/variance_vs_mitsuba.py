"""Candela's noise against Mitsuba 3's at equal spp, without a reference image.

For a Mitsuba XML scene both renderers read, renders SEEDS images with Mitsuba
`llvm_ad_rgb` and with each Candela configuration (`--candela NAME=ARGS`), and compares
the variance of one render across seeds, per pixel and channel, relative to (m² + ε),
m the pixel's mean over every render of every renderer and ε = 10⁻² (relMSE's
convention: `benchlib.images.relative_variances`). Where both converge to the same
image (checked: per 8×8 tile Welch's t-test of the tiles' mean luminance, α = 0.001),
this variance is their whole relMSE at this spp, so "÷ M" is the relMSE ratio of
`bench/equal_spp.sh` with the reference's noise and the bias terms left out, and its
± is a bootstrap over 16×16-pixel tiles (the same tiles for both).

Usage: bench/variance_vs_mitsuba.sh --scene bench/scenes/cornell-textured.xml
           [--spp 64] [--res 128] [--seeds 16] [--candela NAME=ARGS ...]
"""

import argparse
import os
import sys

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, images, machine, mitsuba_render, report  # noqa: E402
from light_sampler import welch_fails  # noqa: E402

OUT = os.path.join(BENCH_DIR, "out", "variance_vs_mitsuba")
CANDELA = os.path.join(REPO, "target", "release", "candela")
MITSUBA = "Mitsuba 3 llvm_ad_rgb"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", required=True)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--binary", default=CANDELA)
    ap.add_argument("--candela", action="append", default=None,
                    help="NAME=ARGS: a Candela configuration (repeatable)")
    a = ap.parse_args()
    configs = [c.split("=", 1) for c in (a.candela or ["default="])]
    os.makedirs(OUT, exist_ok=True)
    scene = os.path.abspath(a.scene)
    name = os.path.splitext(os.path.basename(scene))[0]
    groups = {MITSUBA: []}
    for seed in range(1, a.seeds + 1):
        out = os.path.join(OUT, f"{name}-mitsuba-{a.res}-{a.spp}-{seed}.exr")
        if not os.path.exists(out):
            mitsuba_render.run(scene, out, variant="llvm_ad_rgb", threads=a.threads,
                               params={"spp": a.spp, "res": a.res}, seed=seed)
        groups[MITSUBA].append(images.load_exr(out))
        for cname, args in configs:
            out = os.path.join(OUT, f"{name}-candela-{cname}-{seed}.pfm")
            candela.run([a.binary, "render", scene, "-o", out, "--spp", str(a.spp),
                         "--seed", str(seed), "--threads", str(a.threads),
                         "-D", f"res={a.res}"] + args.split())
            groups.setdefault(f"Candela {cname}", []).append(images.read_pfm(out))
    rel = images.relative_variances(groups)
    tiles = {k: images.tile_sums(v) for k, v in rel.items()}
    rng = np.random.default_rng(1)
    rows = []
    for who in groups:
        ratio, se = images.tile_ratio(tiles[who], tiles[MITSUBA], rng, 400)
        fails, n = welch_fails(groups[who], groups[MITSUBA])
        mean = np.mean(groups[who], axis=0).mean()
        rows.append([who, f"{rel[who].mean():.5f}", f"{ratio:.3f} ± {se:.3f}",
                     f"{fails}/{n}", f"{mean:.5f}"])
        print("|".join(rows[-1]), flush=True)
    print(f"\n`bench/variance_vs_mitsuba.sh --scene {a.scene} --spp {a.spp} --res {a.res} "
          f"--seeds {a.seeds}` + {' '.join('--candela ' + '='.join(c) for c in configs)}; "
          f"{machine.describe(REPO)}\n")
    print(report.table(["renderer", "rel. variance", "÷ M", "Welch fails vs M",
                        "mean"], rows))


if __name__ == "__main__":
    main()
