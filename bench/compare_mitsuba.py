"""Candela against Mitsuba 3 on Mitsuba XML scenes that both read: the same file, the same
spp, resolution and max depth, the same number of threads.

For each scene and renderer it prints wall time, relMSE against a reference (a long
Mitsuba render, cached in bench/out/compare/, or an EXR given with --reference), relMSE at
equal time and time to equal error, as Markdown (also written to
bench/out/compare_mitsuba.md). Run through bench/compare_mitsuba.

Equal time and equal error are extrapolated from one measured run each, using that an
unbiased Monte Carlo estimate's MSE falls as 1/spp, and render time grows with spp:
relMSE at time T = relMSE · t / T, and the time to reach error E = t · relMSE / E.
"""

import argparse
import glob
import hashlib
import json
import os
import re
import statistics
import subprocess
import sys

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
SHARED = os.path.normpath(os.path.join(REPO, "..", "shared", "data", "mitsuba"))
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, images, machine, mitsuba_render, report  # noqa: E402

OUT = os.path.join(BENCH_DIR, "out", "compare")
CANDELA = os.path.join(REPO, "target", "release", "candela")
REF_SEED = 100_000  # far from the benchmark's seeds: independent noise
REF_PASS_SPP = 64
NAME = {"candela": "Candela", "llvm_ad_rgb": "Mitsuba 3 llvm_ad_rgb",
        "scalar_rgb": "Mitsuba 3 scalar_rgb"}


def default_scenes() -> list:
    scenes = sorted(glob.glob(os.path.join(SHARED, "*", "scene.xml")))
    if not scenes:
        print(f"[compare] skipping the shared scenes: {SHARED} not found", flush=True)
    return scenes + sorted(glob.glob(os.path.join(REPO, "scenes", "*.xml")))


def scene_params(path: str, spp: int, res: int) -> dict:
    """The `-D` values both renderers get: spp and resolution where the file has
    parameters for them, and the stock `path` integrator where it is a parameter (the
    shared scenes default to a custom one). Anything else keeps the file's value."""
    with open(path) as f:
        names = set(re.findall(r'<default\s+name="([^"]+)"', f.read()))
    params = {}
    if "integrator" in names:
        params["integrator"] = "path"
    if "spp" in names:
        params["spp"] = spp
    for key in ("res", "resx", "resy"):
        if key in names:
            params[key] = res
    return params


def fingerprint(path: str, params: dict) -> str:
    h = hashlib.sha256(json.dumps(params, sort_keys=True).encode())
    folder = os.path.dirname(path)
    for root, _, files in sorted(os.walk(folder)):
        for name in sorted(files):
            if name.endswith((".xml", ".obj", ".ply", ".exr", ".hdr", ".png", ".jpg")):
                with open(os.path.join(root, name), "rb") as f:
                    h.update(name.encode() + f.read())
    return h.hexdigest()[:16]


def reference(scene: str, tag: str, params: dict, a, variant: str) -> str:
    passes = max(1, a.ref_spp // REF_PASS_SPP)
    ref_params = dict(params, **({"spp": REF_PASS_SPP} if "spp" in params else {}))
    want = {"fingerprint": fingerprint(scene, ref_params), "passes": passes}
    path = os.path.join(OUT, f"{tag}_reference.exr")
    meta_path = path + ".json"
    if os.path.exists(path) and os.path.exists(meta_path):
        with open(meta_path) as f:
            if all(json.load(f).get(k) == v for k, v in want.items()):
                print(f"[compare] {tag}: reusing {os.path.relpath(path, REPO)}", flush=True)
                return path
    print(f"[compare] {tag}: rendering the reference, {passes} × {REF_PASS_SPP} spp with "
          f"{variant} (cached in bench/out/compare/)", flush=True)
    r = mitsuba_render.run(scene, path, variant=variant, threads=a.threads,
                           params=ref_params, seed=REF_SEED, passes=passes)
    with open(meta_path, "w") as f:
        json.dump(dict(want, variant=variant, mitsuba=r["mitsuba"]), f, indent=1)
    return path


def run_candela(scene: str, out: str, params: dict, a, seed: int) -> dict:
    defines = [x for k, v in params.items() for x in ("-D", f"{k}={v}")]
    cmd = [CANDELA, "render", scene, "-o", out, "--threads", str(a.threads),
           "--seed", str(seed)] + defines
    c0 = candela._children_cpu_s()
    p = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr}")
    m = candela.parse_summary(p.stdout)
    if m is None:
        raise RuntimeError(f"no summary line in candela's output:\n{p.stdout}")
    return {"time_s": float(m["secs"]), "cpu_s": candela._children_cpu_s() - c0,
            "out": out, "command": " ".join(cmd), "warnings": p.stderr.count("warning")}


def compare(scene: str, a, variants: list) -> str:
    tag = os.path.basename(os.path.dirname(scene)) if scene.endswith("scene.xml") \
        else os.path.splitext(os.path.basename(scene))[0]
    params = scene_params(scene, a.spp, a.res)
    ref_variant = "llvm_ad_rgb" if "llvm_ad_rgb" in variants else "scalar_rgb"
    ref_path = a.reference or reference(scene, tag, params, a, ref_variant)
    runs = {k: [] for k in ["candela"] + variants}
    for rep in range(a.repeats):
        out = os.path.join(OUT, f"{tag}_candela_{rep}.exr")
        print(f"[compare] {tag} run {rep + 1}/{a.repeats}: candela", flush=True)
        runs["candela"].append(run_candela(scene, out, params, a, rep))
        for v in variants:
            print(f"[compare] {tag} run {rep + 1}/{a.repeats}: mitsuba {v}", flush=True)
            out = os.path.join(OUT, f"{tag}_{v}_{rep}.exr")
            r = mitsuba_render.run(scene, out, variant=v, threads=a.threads, params=params,
                                   seed=rep, warm_runs=1 if v.startswith("llvm") else 0,
                                   cold_kernel_cache=v.startswith("llvm"))
            warm = r["warm"][0]["wall_s"] if r["warm"] else None
            runs[v].append({"time_s": r["renders"][0]["wall_s"], "warm_s": warm,
                            "cpu_s": r["renders"][0]["cpu_s"], "out": out})

    import mitsuba as mi  # EXR I/O only
    mi.set_variant("scalar_rgb")
    ref = images.load_exr(ref_path)
    stats = {}
    for key, rs in runs.items():
        imgs = [images.load_exr(r["out"]) for r in rs]
        if imgs[0].shape != ref.shape:
            raise RuntimeError(f"{key} rendered {imgs[0].shape}, the reference is {ref.shape}")
        # Mitsuba's llvm variant: the warm time (kernels compiled) is the fair one for
        # equal-time figures; the cold one is shown too.
        times = [r["warm_s"] or r["time_s"] for r in rs] if key != "candela" \
            else [r["time_s"] for r in rs]
        stats[key] = {"t": statistics.median(times),
                      "t_cold": statistics.median(r["time_s"] for r in rs),
                      "relmse": statistics.mean(images.relmse(x, ref) for x in imgs),
                      "z": images.mean_difference_z(imgs[0], ref)}
    c = stats["candela"]
    rows = []
    for key in ["candela"] + variants:
        s = stats[key]
        at_candela_time = s["relmse"] * s["t"] / c["t"]
        to_candela_error = s["t"] * s["relmse"] / c["relmse"]
        candela_to_this = c["t"] * c["relmse"] / s["relmse"]
        rows.append([NAME[key], report.fmt(s["t"]), report.fmt(s["t_cold"]),
                     f"{s['relmse']:.5f}", f"{at_candela_time:.5f}",
                     report.fmt(to_candela_error),
                     "—" if key == "candela" else report.fmt(candela_to_this),
                     "—" if key == "candela" else report.fmt(s["relmse"] * s["t"]
                                                             / (c["relmse"] * c["t"])),
                     report.fmt_rgb(s["z"], 1)])
    defines = " ".join(f"-D {k}={v}" for k, v in params.items())
    rel = os.path.relpath(scene, REPO)
    return "\n".join([
        f"#### `{rel}` ({defines or 'file defaults'}), {a.threads} threads",
        "",
        report.table(["renderer", "time s", "cold s", "relMSE", "relMSE at Candela's time",
                      "s to Candela's error", "Candela s to this error",
                      "efficiency ÷ Candela's", "mean z vs ref (R, G, B)"], rows),
        "",
        f"Reference: {os.path.relpath(ref_path, REPO) if not a.reference else a.reference}. "
        f"Candela: `{runs['candela'][0]['command'].replace(REPO + '/', '')}`.",
        "",
    ])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenes", nargs="*", help="Mitsuba XML files (default: the shared "
                    "scenes in ../shared/data/mitsuba and scenes/*.xml)")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--reference", help="an EXR to use as the reference (one scene only)")
    ap.add_argument("--variants", default="llvm_ad_rgb,scalar_rgb")
    ap.add_argument("--skip-build", action="store_true")
    a = ap.parse_args()
    variants = [v for v in a.variants.split(",") if v]
    if "llvm_ad_rgb" in variants and mitsuba_render.libllvm_path() is None:
        print("[compare] no libLLVM (run bench/setup.sh): skipping llvm_ad_rgb", flush=True)
        variants.remove("llvm_ad_rgb")
    os.makedirs(OUT, exist_ok=True)
    if not a.skip_build:
        subprocess.run(["cargo", "build", "--release", "-p", "candela-cli"], cwd=REPO,
                       check=True)
    scenes = [os.path.abspath(s) for s in a.scenes] or default_scenes()
    m = machine.describe(REPO)
    parts = [f"Machine: {m['cpu']}, nproc {m['nproc']}, {m['memory_gib']} GiB; {m['os']}; "
             f"date {m['date']}; candela git {m['git']}; load before {machine.loadavg()}.",
             f"Command: `bench/compare_mitsuba {' '.join(sys.argv[1:])}`", ""]
    for scene in scenes:
        parts.append(compare(scene, a, variants))
    parts.append(
        "*time s*: render only (Candela's summary line; Mitsuba's `mi.render`, for "
        "llvm_ad_rgb the second render in the process, kernels compiled); *cold s*: "
        "Mitsuba's first render including JIT compilation. *relMSE*: mean over runs of "
        f"(x − ref)²/(ref² + {images.RELMSE_EPS}), reference noise included. *relMSE at "
        "Candela's time* = relMSE · t / t_Candela; *s to Candela's error* = "
        "t · relMSE / relMSE_Candela; *efficiency ÷ Candela's* = (relMSE · t) / "
        "(relMSE_Candela · t_Candela): above 1, Candela reaches equal error sooner. "
        "*mean z*: mean image difference to the reference in standard errors (|z| > 3.3 "
        "flags a bias at α = 0.001, reference differences included).")
    md = "\n".join(parts)
    print("\n" + md)
    with open(os.path.join(BENCH_DIR, "out", "compare_mitsuba.md"), "w") as f:
        f.write(md + "\n")


if __name__ == "__main__":
    main()
