"""veach-bidir's Beckmann lamp: Candela's image mean against Mitsuba's reference, over seeds.

The lamp of ../shared/data/mitsuba/veach-bidir is a Beckmann roughconductor (Mitsuba's
default distribution). Candela once rendered it as GGX of the same α, which made the
image ≈ 1 % darker than Mitsuba's reference; it now renders Beckmann. This renders the
scene with Candela at several seeds, as written (Beckmann) and, with `--ggx`, with the
lamp's distribution set to ggx, and prints each image's mean ÷ the reference's mean per
channel, then the mean ratio over the seeds ± its standard error (the runs are
independent), min, max and how many runs fall below 1. A correct Beckmann gives 1 within
a few standard errors; the ggx variant shows the size of the old substitution.

With `--mitsuba` it also renders the scene with Mitsuba 3 llvm_ad_rgb itself, as written
and with ggx (`--passes` passes of 64 spp, seed 300 000), which measures the substitution
without Candela: 0.9892, 0.9889, 0.9887 of the reference with ggx, 1.0021, 1.0014, 1.0009
as written (bench/RESULTS.md, veach_beckmann).

Needs bench/compare_mitsuba to have run on veach-bidir first (it writes
bench/out/compare/veach-bidir_box.xml, a box-filter copy of the scene, and the 1024-spp
reference beside it), and a release build of Candela.

    bench/.venv/bin/python bench/veach_beckmann.py [--seeds 2-4,10-21] [--spp 64]
        [--sampler sobol|independent] [--ggx] [--mitsuba [--passes 16]]
"""

import argparse
import math
import os
import subprocess
import sys

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, images, machine, mitsuba_render  # noqa: E402

OUT = os.path.join(BENCH_DIR, "out", "compare")
CANDELA = os.path.join(REPO, "target", "release", "candela")
# Far from the reference's and the benchmark runs' seeds, so the noise is independent.
MITSUBA_SEED = 300_000
# The seeds of the 15-seed check in bench/RESULTS.md, veach_beckmann (the reference's are
# from 100 000).
DEFAULT_SEEDS = "2-4,10-21"


def parse_seeds(text: str) -> list:
    seeds = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        seeds += range(int(lo), int(hi or lo) + 1)
    return seeds


def summary(name: str, ratios: list) -> str:
    n = len(ratios)
    cols = []
    for c in range(3):
        r = [x[c] for x in ratios]
        mean = sum(r) / n
        se = math.sqrt(sum((v - mean) ** 2 for v in r) / (n - 1) / n) if n > 1 else float("nan")
        cols.append(f"{mean:.4f} ± {se:.4f} (min {min(r):.4f}, max {max(r):.4f}, "
                    f"{sum(v < 1 for v in r)} of {n} below 1)")
    return f"{name}: mean ÷ reference's over {n} seeds, R {cols[0]}; G {cols[1]}; B {cols[2]}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", default=DEFAULT_SEEDS, help="Candela seeds, e.g. 2-4,10-21")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--sampler", choices=["sobol", "independent"], default=None,
                    help="Candela's sampler (default: what the XML maps to)")
    ap.add_argument("--ggx", action="store_true", help="also render with the lamp as ggx")
    ap.add_argument("--mitsuba", action="store_true",
                    help="also render with Mitsuba, as written and with ggx")
    ap.add_argument("--passes", type=int, default=16, help="Mitsuba: passes of 64 spp each")
    a = ap.parse_args()
    scene = os.path.join(OUT, "veach-bidir_box.xml")
    reference = os.path.join(OUT, "veach-bidir_reference.exr")
    if not (os.path.exists(scene) and os.path.exists(reference)):
        sys.exit("run bench/compare_mitsuba on veach-bidir first (it writes the scene and reference)")
    with open(scene) as f:
        xml = f.read()
    if 'value="beckmann"' not in xml:
        sys.exit(f"{scene}: no beckmann distribution to replace")
    ggx_scene = os.path.join(OUT, "veach-bidir_box_ggx.xml")
    with open(ggx_scene, "w") as f:
        f.write(xml.replace('value="beckmann"', 'value="ggx"'))
    ref = images.load_exr(reference)
    ref_mean = images.mean_rgb(ref)
    print(f"# {machine.git_revision(REPO)}, load {machine.loadavg()}", flush=True)

    scenes = [("beckmann (as written)", scene)] + ([("ggx", ggx_scene)] if a.ggx else [])
    params = {"integrator": "path", "spp": a.spp, "resx": a.res, "resy": a.res}
    defines = [x for k, v in params.items() for x in ("-D", f"{k}={v}")]
    for name, path in scenes:
        ratios = []
        for seed in parse_seeds(a.seeds):
            tag = f"{name.split()[0]}_{a.sampler or 'xml'}"
            out = os.path.join(OUT, f"veach-bidir_candela_{tag}_seed{seed}.exr")
            cmd = [CANDELA, "render", path, "-o", out, "--threads", str(a.threads),
                   "--seed", str(seed), "--spp", str(a.spp)] + defines
            if a.sampler:
                cmd += ["--sampler", a.sampler]
            p = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
            if p.returncode != 0:
                sys.exit(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr}")
            m = candela.parse_summary(p.stdout)
            ratio = images.mean_rgb(images.load_exr(out)) / ref_mean
            ratios.append(ratio)
            print(f"Candela {name}, seed {seed}: {', '.join(f'{r:.4f}' for r in ratio)}"
                  f" ({m['secs'] if m else '?'} s)", flush=True)
        print(summary(f"Candela {name}", ratios), flush=True)
        print(f"  command: {' '.join(cmd[:1] + [os.path.relpath(c, REPO) if c.startswith('/') else c for c in cmd[1:]])}"
              f" (seed and output varying)", flush=True)

    if a.mitsuba:
        mparams = {"integrator": "path", "spp": 64, "resx": a.res, "resy": a.res}
        for name, path in [("beckmann (as written)", scene), ("ggx", ggx_scene)]:
            out = os.path.join(OUT, f"veach-bidir_{name.split()[0]}_{64 * a.passes}spp.exr")
            mitsuba_render.run(path, out, variant="llvm_ad_rgb", threads=a.threads,
                               params=mparams, seed=MITSUBA_SEED, passes=a.passes)
            x = images.load_exr(out)
            ratio = images.mean_rgb(x) / ref_mean
            z = images.mean_difference_z(x, ref)
            print(f"Mitsuba {name}, {64 * a.passes} spp: mean ÷ reference's = "
                  f"{', '.join(f'{r:.4f}' for r in ratio)}; z = {', '.join(f'{v:.1f}' for v in z)}",
                  flush=True)
    print(f"# load after: {machine.loadavg()}", flush=True)


if __name__ == "__main__":
    main()
