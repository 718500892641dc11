"""Candela against Mitsuba 3 at equal spp on Mitsuba XML scenes (issue 36's targets).

For each scene: a reference rendered by Mitsuba (`--ref-variant`, `--ref-spp` samples in
passes of 256, cached in bench/out/equal_spp/), then for each seed in `--seeds` one render
of `--spp` samples by Mitsuba `llvm_ad_rgb` and by each Candela configuration
(`--candela NAME=ARGS`, e.g. `splat=--filter-sampling splat`). It prints, as Markdown,
each renderer's relMSE against the reference averaged over the seeds (also with the
worst 0.1 % of pixels dropped, for scenes ruled by rare bright paths), its ratio to
Mitsuba's, and CPU time per sample (user + system of all threads, over pixels × spp;
Mitsuba's from a second, warm render, so JIT compilation is left out; Candela's is the
whole process, loading included). For issue 35's speed targets it also prints the render
wall time per sample (Mitsuba's warm render; Candela's render time from its summary line,
loading and the BVH build left out, as Mitsuba's warm render leaves them out), its ratio
to Mitsuba's, and the time-to-equal-error lead, Mitsuba's time × relMSE ÷ Candela's (by
the relMSE with the worst 0.1 % dropped, which rare fireflies do not rule), with the
geometric mean over scenes of each Candela configuration.

Usage: bench/equal_spp.sh [--scenes a.xml b.xml] [--spp 64] [--res 128] [--seeds 1 2 3 4]
"""

import argparse
import os
import resource
import subprocess
import sys

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, images, machine, mitsuba_render, report  # noqa: E402

OUT = os.path.join(BENCH_DIR, "out", "equal_spp")
CANDELA = os.path.join(REPO, "target", "release", "candela")
REF_SEED = 100_000
REF_PASS_SPP = 256
MITSUBA = "Mitsuba 3 llvm_ad_rgb"


def trimmed_relmse(x: np.ndarray, ref: np.ndarray, drop: float = 0.001) -> float:
    """relMSE over pixels with the worst `drop` fraction of pixels left out."""
    e = ((x - ref) ** 2 / (ref ** 2 + images.RELMSE_EPS)).mean(axis=-1).ravel()
    keep = int(round(len(e) * (1.0 - drop)))
    return float(np.sort(e)[:keep].mean())


def children_cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def reference(scene: str, a) -> np.ndarray:
    name = os.path.splitext(os.path.basename(scene))[0]
    path = os.path.join(OUT, f"{name}-ref-{a.ref_variant}-{a.res}-{a.ref_spp}.exr")
    if not os.path.exists(path):
        print(f"[equal_spp] reference {path} ({a.ref_spp} spp)", flush=True)
        mitsuba_render.run(scene, path, variant=a.ref_variant, threads=a.threads,
                           params={"spp": REF_PASS_SPP, "res": a.res}, seed=REF_SEED,
                           passes=a.ref_spp // REF_PASS_SPP, timeout_s=7200)
    return images.load_exr(path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+",
                    default=[os.path.join(BENCH_DIR, "scenes", s)
                             for s in ("cornell-textured.xml", "thin-lens.xml")])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--ref-variant", default="llvm_ad_rgb")
    ap.add_argument("--binary", default=CANDELA,
                    help="the candela binary (default: this checkout's release build)")
    ap.add_argument("--candela", action="append", default=None,
                    help="NAME=ARGS: a Candela configuration (repeatable)")
    a = ap.parse_args()
    configs = [c.split("=", 1) for c in (a.candela or ["default="])]
    os.makedirs(OUT, exist_ok=True)
    samples = a.res * a.res * a.spp
    rows = []
    leads = {}  # Candela configuration -> list of (time ratio, lead), a scene each
    for scene in map(os.path.abspath, a.scenes):
        name = os.path.splitext(os.path.basename(scene))[0]
        ref = reference(scene, a)
        errs = {}  # renderer -> list of (relmse, trimmed, cpu ns, wall ns per sample)
        for seed in a.seeds:
            out = os.path.join(OUT, f"{name}-mitsuba-{seed}.exr")
            r = mitsuba_render.run(scene, out, variant="llvm_ad_rgb", threads=a.threads,
                                   params={"spp": a.spp, "res": a.res}, seed=seed,
                                   warm_runs=1)
            img = images.load_exr(out)
            ns = r["warm"][0]["cpu_s"] / samples * 1e9
            wall_ns = r["warm"][0]["wall_s"] / samples * 1e9
            errs.setdefault(MITSUBA, []).append(
                (images.relmse(img, ref), trimmed_relmse(img, ref), ns, wall_ns))
            for cname, args in configs:
                out = os.path.join(OUT, f"{name}-candela-{cname}-{seed}.pfm")
                cmd = [a.binary, "render", scene, "-o", out, "--spp", str(a.spp),
                       "--seed", str(seed), "--threads", str(a.threads),
                       "-D", f"res={a.res}"] + args.split()
                c0 = children_cpu_s()
                m = candela.run(cmd)
                ns = (children_cpu_s() - c0) / samples * 1e9
                wall_ns = float(m["secs"]) / samples * 1e9
                img = images.read_pfm(out)
                errs.setdefault(f"Candela {cname}", []).append(
                    (images.relmse(img, ref), trimmed_relmse(img, ref), ns, wall_ns))
        base, base_t, _, base_wall = (np.mean([x[i] for x in errs[MITSUBA]]) for i in range(4))
        for who, e in errs.items():
            m, t, ns, wall = (np.mean([x[i] for x in e]) for i in range(4))
            lead = (base_wall * base_t) / (wall * t)
            if who != MITSUBA:
                leads.setdefault(who, []).append((wall / base_wall, lead))
            rows.append([name, who, report.fmt(m, 5), report.fmt(m / base, 3),
                         report.fmt(t, 5), report.fmt(t / base_t, 3), report.fmt(ns, 0),
                         report.fmt(wall, 0), report.fmt(wall / base_wall, 3),
                         report.fmt(lead, 3)])
            print("|".join(str(c) for c in rows[-1]), flush=True)
    header = ["scene", "renderer", "relMSE", "÷ Mitsuba", "relMSE −0.1 %", "÷ Mitsuba",
              "CPU ns/sample", "render ns/sample", "time ÷ Mitsuba", "lead"]
    info = machine.describe(REPO)
    print(f"\n{a.res}×{a.res}, {a.spp} spp, seeds {a.seeds}, reference {a.ref_variant} "
          f"{a.ref_spp} spp; {info}\n")
    print(report.table(header, rows, "llrrrrrrrr"))
    for who, v in leads.items():
        ratio, lead = np.array(v).T
        print(f"\n{who}: render time per sample ÷ Mitsuba's, geometric mean "
              f"{np.exp(np.log(ratio).mean()):.3f} (worst {ratio.max():.3f}); "
              f"time-to-equal-error lead (−0.1 %), geometric mean "
              f"{np.exp(np.log(lead).mean()):.3f}")


if __name__ == "__main__":
    main()
