"""Where the time per sample goes against Mitsuba 3, bounce by bounce (issue 35).

For each scene and each `max_depth` (Mitsuba's parameter; Candela's loader maps it to one
bounce less, so both stop at the same vertex), the render wall time per sample of Mitsuba 3
`llvm_ad_rgb` (the fastest of `--warm` warm renders, JIT compilation left out) and of
Candela (the fastest of `--repeats` renders, its summary line's render time: loading and
the BVH build left out), Candela's rays per sample (its summary line's rays/s × seconds ÷
samples), and the increment of each over the previous depth. Depth 1 is the camera ray and
what it sees (no light sampling); depth 2 adds the first vertex's next event estimation
and its BSDF-sampled ray; each depth after that one more vertex of the paths still alive.
The increments say whether the gap is per camera sample or per bounce.

Usage: bench/depth_cost.sh [--scenes a.xml …] [--depths 1 2 3 5 8] [--res 256] [--spp 64]
"""

import argparse
import os
import sys

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, machine, mitsuba_render, report  # noqa: E402

OUT = os.path.join(BENCH_DIR, "out", "depth_cost")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+",
                    default=[os.path.join(BENCH_DIR, "scenes", s + ".xml")
                             for s in ("spot-point-room", "cornell-textured", "many-lights")])
    ap.add_argument("--depths", type=int, nargs="+", default=[1, 2, 3, 5, 8])
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--warm", type=int, default=2, help="Mitsuba's timed warm renders")
    ap.add_argument("--repeats", type=int, default=2, help="Candela's timed renders")
    ap.add_argument("--binary", default=os.path.join(REPO, "target", "release", "candela"))
    a = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    samples = a.res * a.res * a.spp
    rows = []
    for scene in map(os.path.abspath, a.scenes):
        name = os.path.splitext(os.path.basename(scene))[0]
        prev = None
        for depth in a.depths:
            params = {"spp": a.spp, "res": a.res, "max_depth": depth}
            r = mitsuba_render.run(scene, os.path.join(OUT, f"{name}-mitsuba.exr"),
                                   variant="llvm_ad_rgb", threads=a.threads, params=params,
                                   seed=1, warm_runs=a.warm)
            m_ns = min(w["wall_s"] for w in r["warm"]) / samples * 1e9
            best = None
            for _ in range(a.repeats):
                cmd = [a.binary, "render", scene, "-o", os.path.join(OUT, f"{name}-candela.pfm"),
                       "--spp", str(a.spp), "--seed", "1", "--threads", str(a.threads),
                       "-D", f"res={a.res}", "-D", f"max_depth={depth}"]
                s = candela.run(cmd)
                if best is None or float(s["secs"]) < float(best["secs"]):
                    best = s
            if float(best["secs"]) < 0.1:
                sys.exit(f"{name} at max_depth {depth} rendered in {best['secs']} s: too short "
                         "to time (the summary line has 10 ms steps); raise --res or --spp")
            c_ns = float(best["secs"]) / samples * 1e9
            rays = float(best["rays"]) * 1e6 * float(best["secs"]) / samples
            dm, dc = ((m_ns - prev[0], c_ns - prev[1]) if prev else (m_ns, c_ns))
            rows.append([name, depth, report.fmt(m_ns, 0), report.fmt(c_ns, 0),
                         report.fmt(c_ns / m_ns, 2), report.fmt(rays, 2),
                         report.fmt(dm, 0), report.fmt(dc, 0),
                         report.fmt(dc / dm, 2) if dm > 0 else "–"])
            print(" | ".join(map(str, rows[-1])), flush=True)
            prev = (m_ns, c_ns)
    header = ["scene", "max_depth", "Mitsuba ns/sample", "Candela ns/sample", "÷ Mitsuba",
              "Candela rays/sample", "Mitsuba +ns", "Candela +ns", "increment ÷ Mitsuba"]
    print(f"\n{a.res}×{a.res}, {a.spp} spp, {a.threads} threads; {machine.describe(REPO)}\n")
    print(report.table(header, rows, "lrrrrrrrr"))


if __name__ == "__main__":
    main()
