"""Where Candela's extra error against Mitsuba 3 lies on the sky scenes (issue 36 item 3).

Renders `bench/scenes/hdr-sky-sun.xml` or `sun-sky-glass.xml` (their camera, ground and
three spheres are the same) by Mitsuba 3 `llvm_ad_rgb` and by Candela configurations over
several seeds, at equal spp and at each `--max-depth` given (Mitsuba's count: 2 is direct
light only), against a Mitsuba reference of the same depth. Pixels are split by what the
camera ray hits first (ground, diffuse sphere, rough aluminium sphere, glass sphere,
sky), found by casting the pixel-centre rays analytically. For each region it prints the
region's share of the image's relMSE (the sum over its pixels ÷ all pixels, so the rows
add up to the image's relMSE), the same with the worst 0.1 % of the image's pixels left
out, and the squared bias: the relMSE of the mean over the seeds, less what its
variance explains (an estimate, noisy where the error is ruled by rare paths).

Usage: bench/env_paths.sh --scene bench/scenes/hdr-sky-sun.xml --max-depth 2 8 \
    --candela default= --candela power="--mis power"
"""

import argparse
import os
import sys

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, images, mitsuba_render, report  # noqa: E402

OUT = os.path.join(BENCH_DIR, "out", "env_paths")
CANDELA = os.path.join(REPO, "target", "release", "candela")
REF_SEED = 100_000
REF_PASS_SPP = 256
REGIONS = ("sky", "ground", "diffuse", "aluminium", "glass")
SPHERES = ((-1.1, 0.5, 0.0), (0.0, 0.5, 0.0), (1.1, 0.5, 0.0))  # diffuse, Al, glass


def regions(res: int) -> np.ndarray:
    """Index into REGIONS of what each pixel centre's camera ray hits first (the scenes'
    camera: from (0, 1.5, 5) towards (0, 0.4, 0), 30° vertical field of view)."""
    o = np.array([0.0, 1.5, 5.0])
    fwd = np.array([0.0, 0.4, 0.0]) - o
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    t = np.tan(np.radians(15.0))
    s = (np.arange(res) + 0.5) / res * 2.0 - 1.0
    x, y = np.meshgrid(s * t, -s * t)
    d = fwd + x[..., None] * right + y[..., None] * up
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    best = np.full((res, res), np.inf)
    label = np.zeros((res, res), dtype=int)
    with np.errstate(divide="ignore", invalid="ignore"):
        tg = -o[1] / d[..., 1]  # the ground plane y = 0, a square of half-size 8
        p = o + tg[..., None] * d
        ok = (tg > 0) & (np.abs(p[..., 0]) <= 8) & (np.abs(p[..., 2]) <= 8)
        best = np.where(ok, tg, best)
        label = np.where(ok, 1, label)
        for k, c in enumerate(SPHERES):
            oc = o - np.array(c)
            b = (d * oc).sum(-1)
            disc = b * b - (oc @ oc - 0.25)
            th = -b - np.sqrt(disc)
            hit = (disc > 0) & (th > 0) & (th < best)
            best = np.where(hit, th, best)
            label = np.where(hit, 2 + k, label)
    return label


def per_pixel(x: np.ndarray, ref: np.ndarray) -> np.ndarray:
    return ((x - ref) ** 2 / (ref ** 2 + images.RELMSE_EPS)).mean(axis=-1)


def reference(scene: str, depth: int, a) -> np.ndarray:
    name = os.path.splitext(os.path.basename(scene))[0]
    path = os.path.join(OUT, f"{name}-ref-d{depth}-{a.res}-{a.ref_spp}.exr")
    if not os.path.exists(path):
        print(f"[env_paths] reference {path}", flush=True)
        mitsuba_render.run(scene, path, variant="llvm_ad_rgb", threads=a.threads,
                           params={"spp": REF_PASS_SPP, "res": a.res, "max_depth": depth},
                           seed=REF_SEED, passes=a.ref_spp // REF_PASS_SPP, timeout_s=7200)
    return images.load_exr(path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default=os.path.join(BENCH_DIR, "scenes", "hdr-sky-sun.xml"))
    ap.add_argument("--max-depth", type=int, nargs="+", default=[2, 8])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5, 6, 7, 8])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--candela", action="append", default=None,
                    help="NAME=ARGS: a Candela configuration (repeatable)")
    a = ap.parse_args()
    configs = [c.split("=", 1) for c in (a.candela or ["default="])]
    os.makedirs(OUT, exist_ok=True)
    scene = os.path.abspath(a.scene)
    name = os.path.splitext(os.path.basename(scene))[0]
    label = regions(a.res)
    n = label.size
    rows = []
    for depth in a.max_depth:
        ref = reference(scene, depth, a)
        imgs = {}
        for seed in a.seeds:
            out = os.path.join(OUT, f"{name}-d{depth}-mitsuba-{seed}.exr")
            if not os.path.exists(out):  # Mitsuba's renders do not change: kept
                mitsuba_render.run(scene, out, variant="llvm_ad_rgb", threads=a.threads,
                                   params={"spp": a.spp, "res": a.res,
                                           "max_depth": depth}, seed=seed)
            imgs.setdefault("Mitsuba", []).append(images.load_exr(out))
            for cname, args in configs:
                out = os.path.join(OUT, f"{name}-d{depth}-candela-{cname}-{seed}.pfm")
                candela.run([CANDELA, "render", scene, "-o", out, "--spp", str(a.spp),
                             "--seed", str(seed), "--threads", str(a.threads),
                             "-D", f"res={a.res}", "-D", f"max_depth={depth}"]
                            + args.split())
                imgs.setdefault(f"Candela {cname}", []).append(images.read_pfm(out))
        for who, xs in imgs.items():
            e = np.array([per_pixel(x, ref) for x in xs])  # seeds × H × W
            keep = np.ones_like(e, dtype=bool)
            for s in range(len(xs)):  # the worst 0.1 % of each image's pixels
                worst = np.argsort(e[s].ravel())[::-1][: int(round(n * 0.001))]
                keep[s].ravel()[worst] = False
            mean = np.mean(xs, axis=0)
            var_of_mean = np.var(xs, axis=0, ddof=1) / len(xs)
            bias2 = (per_pixel(mean, ref)
                     - (var_of_mean / (ref ** 2 + images.RELMSE_EPS)).mean(axis=-1))
            cells = [f"{name} d{depth}", who, report.fmt(e.mean(), 5),
                     report.fmt((e * keep).sum() / keep.sum(), 5)]
            for r in range(len(REGIONS)):
                m = label == r
                cells.append(f"{e[:, m].sum() / e.size:.5f} / "
                             f"{(e * keep)[:, m].sum() / keep.sum():.5f} / "
                             f"{bias2[m].sum() / n:+.5f}")
            rows.append(cells)
            print(" | ".join(cells), flush=True)
    header = ["scene", "renderer", "relMSE", "−0.1 %"] + [
        f"{r} ({(label == i).sum()} px): all / −0.1 % / bias²" for i, r in enumerate(REGIONS)]
    print(f"\n{a.res}², {a.spp} spp, seeds {a.seeds}, reference Mitsuba llvm {a.ref_spp} spp\n")
    print(report.table(header, rows, "ll" + "r" * (len(header) - 2)))


if __name__ == "__main__":
    main()
