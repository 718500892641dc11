"""Light samplers at equal spp: is the default (`bvh`) ever worse than `uniform` or
`power` beyond noise, and what does it cost per sample? (Issue 36.)

For each scene, renders SEEDS images with each `--light-sampler` in SAMPLERS (same spp,
resolution and threads; the samplers alternate within each seed, so a burst of load
elsewhere hits them alike) and measures
  - the error of one render: the sample variance across seeds of each pixel and channel,
    relative to (m² + ε), m the pixel's mean over every render of the scene by every
    sampler, ε = 10⁻² (relMSE's convention, `benchlib.images.relative_variances`). All
    the samplers are unbiased, so the variance is the whole error and no reference is
    needed (the Welch column checks that they agree);
  - the variance ratio of the first sampler (the candidate, `bvh`) to each other one,
    with its standard error from a bootstrap over 16×16-pixel tiles. **The test**: the
    candidate is *worse beyond noise* where ratio − 1 > 3 SE, *better* where 1 − ratio >
    3 SE, else *level*. 3 SE is a one-sided 0.13 % false alarm for one comparison, about
    6 % over the ~46 comparisons of the default scene list, so a lone "worse" near 3 SE is
    to be rerun with other seeds before it is believed;
  - unbiasedness: per 8×8 tile, the tile's mean luminance in each render is one
    observation, Welch's t-test between the candidate's and the other sampler's renders;
    the count of tiles with p < 0.001 (about α × tiles by chance; a bias fails many);
  - the cost: CPU seconds (user + system, all threads, the whole process, loading
    included) per sample, as the candidate's over the other's, summed over the seeds
    (a ratio from one run, so load hits both alike); efficiency = variance ratio × time
    ratio inverted (above 1: the candidate reaches a given error sooner);
  - with `--ipp`, instructions per camera path (callgrind, `bench/lanes/ipp.sh` at
    IPP_RES², 1 and 3 spp, one thread): load-independent cost per sample.

A sampler may be given as LABEL=SAMPLER@BINARY to compare binaries: e.g.
`--samplers bvh bvh-old=bvh@/path/to/old/candela` is the Welch comparison of a changed
sampler against the previous one, with its variance ratio; and LABEL=SAMPLER+ARGS (or
LABEL=SAMPLER@BINARY+ARGS) adds render arguments, e.g. `"power=bvh+--mis power"
balance=bvh` compares MIS heuristics.

Usage: bench/light_sampler.sh [--spp 16] [--seeds 8] [--size 128] [--threads 2]
                              [--samplers bvh uniform power] [--ipp] [--binary PATH]
                              [SCENE ...]
"""

import argparse
import os
import re
import subprocess
import sys
import time
import tomllib

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, machine, report, stats  # noqa: E402
from benchlib.images import read_pfm, relative_variances, tile_ratio, tile_sums  # noqa: E402

CANDELA = os.path.join(REPO, "target", "release", "candela")
OUT = os.path.join(BENCH_DIR, "out", "light_sampler")
# Every bench scene, and the example scenes where the choice of light can matter (several
# lights, shaped lights, an environment) or whose single light shows what a pick costs.
SCENES = sorted(
    os.path.join("bench/scenes", f) for f in os.listdir(os.path.join(BENCH_DIR, "scenes"))
    if f.endswith((".xml", ".toml"))
) + ["scenes/cornell.toml", "scenes/many_lights.toml", "scenes/textured-light.toml",
     "scenes/environment.toml", "scenes/ies-room.toml", "scenes/isometric.toml",
     "scenes/dof.toml", "scenes/plastics.toml"]
BOOTSTRAP = 400
NOISE_SE = 3.0
WELCH_TILE = 8
WELCH_ALPHA = 0.001
IPP_RES = 32
LUMA = np.array([0.2126, 0.7152, 0.0722])


def resolution(scene: str, size: int) -> str:
    """The scene's own aspect with its longer side `size` (Mitsuba scenes: square)."""
    if scene.endswith(".toml"):
        with open(os.path.join(REPO, scene), "rb") as f:
            w, h = tomllib.load(f).get("render", {}).get("resolution", [512, 512])
    else:
        w = h = 1
    k = size / max(w, h)
    return f"{max(8, round(w * k))}x{max(8, round(h * k))}"


def light_count(binary: str, scene: str) -> int:
    p = subprocess.run([binary, "info", scene], cwd=REPO, capture_output=True, text=True,
                       check=True)
    m = re.search(r"^lights\s+(\d+)", p.stdout, re.M)
    return int(m.group(1)) if m else -1


def config(spec: str, binary: str) -> tuple:
    """(label, sampler, binary, extra arguments) from SAMPLER or
    LABEL=SAMPLER[@BINARY][+ARGS]."""
    label, _, rest = spec.partition("=")
    if not rest:
        label, rest = "", label
    rest, _, args = rest.partition("+")
    sampler, _, other = rest.partition("@")
    return label or sampler, sampler, other or binary, args.split()


def render(cfg: tuple, scene: str, seed: int, res: str, a) -> tuple:
    """One render: its image and the CPU seconds of the whole process."""
    label, sampler, binary, args = cfg
    # One folder per run (its process id), so that runs side by side do not share files.
    out = os.path.join(OUT, str(os.getpid()),
                       f"{os.path.basename(scene)}_{label}_{seed}.pfm")
    cmd = [binary, "render", scene, "-o", out, "--spp", str(a.spp), "--seed", str(seed),
           "--threads", str(a.threads), "--res", res, "--light-sampler", sampler] + args
    r0 = os.times()
    candela.run(cmd, cwd=REPO)
    r1 = os.times()
    cpu = (r1.children_user - r0.children_user) + (r1.children_system - r0.children_system)
    return read_pfm(out), cpu


def welch_fails(x: list, y: list) -> tuple:
    """Tiles (WELCH_TILE² pixels) whose mean luminance differs at α = WELCH_ALPHA between
    two sets of renders, and the number of tiles."""
    def tiles(imgs):
        lum = np.array(imgs) @ LUMA
        n, h, w = lum.shape
        t = WELCH_TILE
        lum = lum[:, :h // t * t, :w // t * t]
        return lum.reshape(n, h // t, t, w // t, t).mean(axis=(2, 4)).reshape(n, -1)
    tx, ty = tiles(x), tiles(y)
    p = np.array([stats.welch(tx[:, i], ty[:, i])[1] for i in range(tx.shape[1])])
    return int((p < WELCH_ALPHA).sum()), len(p)


def ipp(cfg: tuple, scene: str) -> int:
    _, sampler, binary, args = cfg
    p = subprocess.run([os.path.join(BENCH_DIR, "lanes", "ipp.sh"), binary, scene,
                        str(IPP_RES), "1", "3", "--light-sampler", sampler] + args,
                       cwd=REPO, capture_output=True, text=True, check=True)
    return int(p.stdout.strip().splitlines()[-1])


def verdict(ratio: float, se: float) -> str:
    if ratio - 1.0 > NOISE_SE * se:
        return "**worse**"
    if 1.0 - ratio > NOISE_SE * se:
        return "better"
    return "level"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--size", type=int, default=128, help="the image's longer side")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--samplers", nargs="+", default=["bvh", "uniform", "power"],
                    help="the candidate first, then what it is compared with")
    ap.add_argument("--ipp", action="store_true", help="also callgrind instructions/path")
    ap.add_argument("--binary", default=CANDELA)
    ap.add_argument("scenes", nargs="*", default=SCENES)
    a = ap.parse_args()
    if a.seeds < 2:
        ap.error("--seeds must be at least 2 (the error is the variance across seeds)")
    os.makedirs(os.path.join(OUT, str(os.getpid())), exist_ok=True)
    cfgs = {c[0]: c for c in (config(spec, a.binary) for spec in a.samplers)}
    labels = list(cfgs)
    cand, others = labels[0], labels[1:]
    print(f"[light_sampler] {machine.cpu_model()}, load {machine.loadavg()}, "
          f"git {machine.git_revision(REPO)}, binary {a.binary}", flush=True)
    t0 = time.time()
    rng = np.random.default_rng(1)
    rows = []
    for scene in a.scenes:
        res = resolution(scene, a.size)
        w, h = (int(v) for v in res.split("x"))
        samples = w * h * a.spp
        runs = {s: [] for s in labels}
        for seed in range(1, a.seeds + 1):
            for s in labels:
                runs[s].append(render(cfgs[s], scene, seed, res, a))
        imgs = {s: [img for img, _ in runs[s]] for s in labels}
        cpu = {s: sum(c for _, c in runs[s]) for s in labels}
        rel = relative_variances(imgs)
        tiles = {s: tile_sums(rel[s]) for s in labels}
        counts = {s: ipp(cfgs[s], scene) for s in labels} if a.ipp else {}
        row = [scene, light_count(a.binary, scene), res,
               f"{rel[cand].mean():.3e}",
               f"{cpu[cand] / a.seeds / samples * 1e9:.0f}"]
        if a.ipp:
            row.append(str(counts[cand]))
        for o in others:
            ratio, se = tile_ratio(tiles[cand], tiles[o], rng, BOOTSTRAP)
            # os.times counts in ticks: a run too short for one has no time ratio.
            t_ratio = cpu[cand] / cpu[o] if min(cpu[cand], cpu[o]) > 0 else float("nan")
            fails, n_tiles = welch_fails(imgs[cand], imgs[o])
            row += [f"{ratio:.3f} ± {se:.3f}", verdict(ratio, se), f"{t_ratio:.2f}",
                    f"{1.0 / (ratio * t_ratio):.2f}"]
            if a.ipp:
                row.append(f"{counts[cand] / counts[o]:.2f}")
            row.append(f"{fails}/{n_tiles}")
        rows.append(row)
        print(f"[light_sampler] {row}", flush=True)
    header = ["scene", "lights", "res", f"{cand} rel. var.", f"{cand} CPU ns/sample"]
    if a.ipp:
        header.append(f"{cand} instr./path")
    for o in others:
        header += [f"var ÷ {o}", "", f"CPU ÷ {o}", "efficiency"]
        if a.ipp:
            header.append(f"instr. ÷ {o}")
        header.append("Welch fails")
    print()
    print(f"`bench/light_sampler.sh --spp {a.spp} --seeds {a.seeds} --size {a.size} "
          f"--threads {a.threads} --samplers {' '.join(a.samplers)}"
          f"{' --ipp' if a.ipp else ''}`, {machine.cpu_model()}, load after "
          f"{machine.loadavg()}, git {machine.git_revision(REPO)}, "
          f"{time.time() - t0:.0f} s")
    print()
    print(report.table(header, rows))


if __name__ == "__main__":
    main()
