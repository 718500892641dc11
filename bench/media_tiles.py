"""Candela against Mitsuba 3 `volpath`, tile by tile, over independent renders (issue #39).

For each scene, `--seeds` renders of `--spp` samples by Candela and by Mitsuba 3
`llvm_ad_rgb` (the same file with a box pixel filter, as bench/compare_mitsuba prepares
it; seeds 1..K for both, independent streams). Each render's mean per 16×16 tile and
channel is one observation; Welch's t-test compares Candela's K tile means with
Mitsuba's, tile-channel by tile-channel.

Why K renders and not one image against a reference: a single low-spp image of a scene
lit through fog has heavy-tailed pixels (rare paths that find the lit region carry most
of the light), so a tile's pixel mean is usually below its expectation and the one-image
z-test leans negative even for an unbiased renderer. A tile's mean over a whole render
(256 pixels × spp samples) is close to normal, and its spread is measured across the K
renders, so the t-test holds for any pixel distribution.

It also prints each renderer's equal-spp relMSE without a reference: the per-pixel
variance of one render across the seeds over (m² + 0.01), m the pixel's mean over all
2K renders (for unbiased renders this is their whole error; the Welch test checks the
bias), and the time and CPU per sample (Candela: its render time; Mitsuba: its render
after the first in the process, JIT excluded). Images are kept in bench/out/media_tiles/.

    bench/.venv/bin/python bench/media_tiles.py --seeds 16 --spp 32 --res 128 \\
        bench/scenes/media-fog.xml bench/scenes/media-room.xml
"""

import argparse
import os
import statistics
import sys

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, images, machine, mitsuba_render, report, stats  # noqa: E402
import compare_mitsuba  # noqa: E402  (its box-filter copy and -D parameters)

OUT = os.path.join(BENCH_DIR, "out", "media_tiles")
CANDELA = os.path.join(REPO, "target", "release", "candela")
TILE = images.TILE
# Per tile-channel significance: a tile-channel is flagged below it; the scene passes
# when no p-value is below the Šidák level for the whole image at ALPHA_FAMILY (a false
# failure once in a hundred scene comparisons).
ALPHA_TILE = 0.001
ALPHA_FAMILY = 0.01


def tile_means(img: np.ndarray) -> np.ndarray:
    h, w = img.shape[0] // TILE * TILE, img.shape[1] // TILE * TILE
    return img[:h, :w].reshape(h // TILE, TILE, w // TILE, TILE, 3).mean(axis=(1, 3))


def render_candela(scene: str, params: dict, a, seed: int, out: str) -> dict:
    defines = [x for k, v in params.items() for x in ("-D", f"{k}={v}")]
    cmd = [CANDELA, "render", scene, "-o", out, "--threads", str(a.threads), "--seed",
           str(seed), "--spp", str(a.spp)] + defines
    c0 = candela._children_cpu_s()
    m = candela.run(cmd)
    return {"wall_s": float(m["secs"]), "cpu_s": candela._children_cpu_s() - c0,
            "command": " ".join(cmd).replace(REPO + "/", "")}


def compare(scene: str, a) -> str:
    tag = os.path.splitext(os.path.basename(scene))[0]
    params = compare_mitsuba.scene_params(scene, a.spp, a.res)
    box = compare_mitsuba.prepare(scene, tag, argparse.Namespace(rfilter="box"))
    runs = {"candela": [], "mitsuba": []}
    imgs = {"candela": [], "mitsuba": []}
    for seed in range(1, a.seeds + 1):
        print(f"[media_tiles] {tag} seed {seed}/{a.seeds}", flush=True)
        out = os.path.join(OUT, f"{tag}_candela_{seed}.exr")
        runs["candela"].append(render_candela(box, params, a, seed, out))
        imgs["candela"].append(images.load_exr(out))
        out = os.path.join(OUT, f"{tag}_mitsuba_{seed}.exr")
        r = mitsuba_render.run(box, out, variant="llvm_ad_rgb", threads=a.threads,
                               params=params, seed=seed, render_spp=a.spp,
                               warm_runs=1 if seed == 1 else 0)
        first = r["warm"][0] if r["warm"] else r["renders"][0]
        runs["mitsuba"].append({"wall_s": first["wall_s"], "cpu_s": first["cpu_s"]})
        imgs["mitsuba"].append(images.load_exr(out))
    h, w = imgs["candela"][0].shape[:2]
    samples = h * w * a.spp

    tiles = {k: np.array([tile_means(x) for x in v]) for k, v in imgs.items()}
    ty, tx = tiles["candela"].shape[1:3]
    t_map = np.zeros((ty, tx, 3))
    p_min = 1.0
    flagged = 0
    for j in range(ty):
        for i in range(tx):
            for c in range(3):
                t, p = stats.welch(tiles["candela"][:, j, i, c], tiles["mitsuba"][:, j, i, c])
                t_map[j, i, c] = t
                p_min = min(p_min, p)
                flagged += p < ALPHA_TILE
    n_tests = t_map.size
    sidak = 1.0 - (1.0 - ALPHA_FAMILY) ** (1.0 / n_tests)
    relvar = images.relative_variances(imgs)
    rel = {k: float(v.mean()) for k, v in relvar.items()}
    # The ratio's uncertainty from a bootstrap over tiles (pixels of a tile share noise).
    rng = np.random.default_rng(1)
    ratio, ratio_se = images.tile_ratio(images.tile_sums(relvar["candela"]),
                                        images.tile_sums(relvar["mitsuba"]), rng)
    per = {k: {"wall": statistics.median(r["wall_s"] for r in v) / samples * 1e9,
               "cpu": statistics.median(r["cpu_s"] for r in v) / samples * 1e9}
           for k, v in runs.items()}
    np.set_printoptions(precision=1, suppress=True, linewidth=160)
    print(f"{tag}: Welch t per tile, luminance-like mean of channels:\n"
          f"{t_map.mean(axis=-1)}", flush=True)
    rows = [[name, report.fmt(rel[k], 5), report.fmt(rel[k] / rel["mitsuba"], 3),
             report.fmt(per[k]["wall"], 0), report.fmt(per[k]["cpu"], 0)]
            for k, name in (("candela", "Candela"), ("mitsuba", "Mitsuba 3 llvm_ad_rgb"))]
    verdict = "pass" if p_min >= sidak else "**fail**"
    rel_scene = os.path.relpath(scene, REPO)
    return "\n".join([
        f"#### `{rel_scene}`: {w}×{h}, {a.spp} spp, seeds 1–{a.seeds} each, "
        f"{a.threads} threads, box filter",
        "",
        report.table(["renderer", "relMSE (variance)", "÷ Mitsuba", "wall ns/sample",
                      "CPU ns/sample"], rows),
        "",
        f"relMSE ratio Candela ÷ Mitsuba {ratio:.3f} ± {ratio_se:.3f} (bootstrap over "
        f"tiles). Per-tile Welch test, {n_tests} tile-channels of {TILE}×{TILE}: "
        f"{flagged} with p < {ALPHA_TILE} (expected by chance {ALPHA_TILE * n_tests:.2f}), "
        f"smallest p {p_min:.2g}, max |t| {np.abs(t_map).max():.2f}; against the Šidák "
        f"level {sidak:.2g} (α = {ALPHA_FAMILY} for the image): {verdict}. "
        f"Candela: `{runs['candela'][0]['command']}`.",
        "",
    ])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    os.makedirs(compare_mitsuba.OUT, exist_ok=True)
    import mitsuba as mi  # EXR I/O
    mi.set_variant("scalar_rgb")
    m = machine.describe(REPO)
    parts = [f"Machine: {m['cpu']}, nproc {m['nproc']}; date {m['date']}; candela git "
             f"{m['git']}; load before {machine.loadavg()}.",
             f"Command: `bench/.venv/bin/python bench/media_tiles.py {' '.join(sys.argv[1:])}`",
             ""]
    for scene in a.scenes:
        parts.append(compare(os.path.abspath(scene), a))
    parts.append(f"Load after: {machine.loadavg()}.")
    print("\n" + "\n".join(parts))


if __name__ == "__main__":
    main()
