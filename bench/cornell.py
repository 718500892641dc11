"""Cornell box benchmark: Candela against Mitsuba 3 (llvm_ad_rgb, scalar_rgb) at 512×512,
64 spp, max depth 8 (Candela's convention; Mitsuba's max_depth 9), 2 threads.

Prints a markdown table (time, ratio to Candela, throughput, relMSE against a cached
high-spp Mitsuba reference, mean radiance with z-tests) and writes it, with the raw
figures, to bench/out/. Run through bench/cornell.sh, or directly with bench/.venv/bin/python.
"""

import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from benchlib import candela, images, machine, mitsuba_render, report  # noqa: E402

SCENE_TOML = "scenes/cornell.toml"
SCENE_XML = os.path.join(BENCH_DIR, "scenes", "cornell.xml")
OUT = os.path.join(BENCH_DIR, "out")
CANDELA = os.path.join(REPO, "target", "release", "candela")
# Reference seeds start far from the benchmark's so the reference's noise is independent.
REF_SEED = 100_000
REF_PASS_SPP = 64


def build_candela() -> None:
    print("[cornell] cargo build --release -p candela-cli", flush=True)
    subprocess.run(["cargo", "build", "--release", "-p", "candela-cli"], cwd=REPO, check=True)


def scene_fingerprint() -> str:
    """Hash of everything the reference depends on, so a stale cache is not reused."""
    h = hashlib.sha256()
    with open(SCENE_XML, "rb") as f:
        h.update(f.read())
    obj_dir = os.path.join(REPO, "scenes", "cornell")
    for name in sorted(os.listdir(obj_dir)):
        with open(os.path.join(obj_dir, name), "rb") as f:
            h.update(name.encode() + f.read())
    return h.hexdigest()[:16]


def reference(a, variants) -> tuple:
    """The cached reference image (rendered once), and its metadata."""
    variant = "llvm_ad_rgb" if "llvm_ad_rgb" in variants else "scalar_rgb"
    passes = max(1, a.ref_spp // REF_PASS_SPP)
    want = {"scene": scene_fingerprint(), "spp": passes * REF_PASS_SPP,
            "mitsuba_max_depth": a.max_depth + 1, "res": a.res}
    path = os.path.join(OUT, f"reference_{want['spp']}spp.exr")
    meta_path = path + ".json"
    if os.path.exists(path) and os.path.exists(meta_path):
        with open(meta_path) as f:
            meta = json.load(f)
        if all(meta.get(k) == v for k, v in want.items()):
            print(f"[cornell] reusing {os.path.relpath(path, REPO)}", flush=True)
            return path, meta
    print(f"[cornell] rendering the reference: {passes} × {REF_PASS_SPP} spp with "
          f"{variant} (once; cached in bench/out/)", flush=True)
    r = mitsuba_render.run(SCENE_XML, path, variant=variant, threads=a.threads,
                           spp=REF_PASS_SPP, max_depth=a.max_depth + 1, res=a.res,
                           seed=REF_SEED, passes=passes)
    meta = dict(want, variant=variant, mitsuba=r["mitsuba"], seed=REF_SEED,
                render_s=sum(x["wall_s"] for x in r["renders"]))
    with open(meta_path, "w") as f:
        json.dump(meta, f, indent=1)
    return path, meta


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=3,
                    help="runs of each renderer, interleaved; the table shows the median")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--max-depth", type=int, default=8,
                    help="Candela's convention (scattering events); Mitsuba gets this + 1")
    ap.add_argument("--res", type=int, default=512)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--variants", default="llvm_ad_rgb,scalar_rgb")
    ap.add_argument("--skip-build", action="store_true")
    ap.add_argument("--sampler",
                    help="Candela's --sampler (default: the scene's, i.e. Candela's default)")
    ap.add_argument("--mitsuba-stratified", default="llvm_ad_rgb:multijitter",
                    help="extra Mitsuba rows as VARIANT:SAMPLER[,...] (a Mitsuba sampler "
                         "other than the scene's independent one); '' for none")
    a = ap.parse_args()
    variants = [v for v in a.variants.split(",") if v]
    extra = [tuple(x.split(":", 1)) for x in a.mitsuba_stratified.split(",") if x]
    if mitsuba_render.libllvm_path() is None:
        if "llvm_ad_rgb" in variants:
            print("[cornell] no libLLVM (run bench/setup.sh): skipping llvm_ad_rgb", flush=True)
            variants.remove("llvm_ad_rgb")
        extra = [(v, s) for v, s in extra if not v.startswith("llvm")]
    # A peer row: its key, Mitsuba variant and Mitsuba sampler (None: the scene's).
    peers = [(v, v, None) for v in variants] + [(f"{v}+{s}", v, s) for v, s in extra]
    os.makedirs(OUT, exist_ok=True)
    if not a.skip_build:
        build_candela()

    ref_path, ref_meta = reference(a, variants)
    res = (a.res, a.res)
    runs = {"candela": []} | {key: [] for key, _, _ in peers}
    for rep in range(a.repeats):
        # Interleaved so that a burst of load from elsewhere hits every renderer alike.
        out = os.path.join(OUT, f"candela_{rep}.exr")
        print(f"[cornell] run {rep + 1}/{a.repeats}: candela", flush=True)
        runs["candela"].append(candela.render(
            CANDELA, SCENE_TOML, out, spp=a.spp, max_depth=a.max_depth, threads=a.threads,
            res=res, seed=rep, cwd=REPO, sampler=a.sampler).__dict__ | {"out": out})
        for key, v, sampler in peers:
            print(f"[cornell] run {rep + 1}/{a.repeats}: mitsuba {key}", flush=True)
            out = os.path.join(OUT, f"mitsuba_{key}_{rep}.exr")
            runs[key].append(mitsuba_render.run(
                SCENE_XML, out, variant=v, threads=a.threads, spp=a.spp,
                max_depth=a.max_depth + 1, res=a.res, seed=rep, warm_runs=1,
                cold_kernel_cache=v.startswith("llvm"), sampler=sampler))

    import mitsuba as mi  # for EXR I/O only
    mi.set_variant("scalar_rgb")
    ref = images.load_exr(ref_path)
    md = render_report(a, peers, runs, ref, ref_meta)
    print()
    print(md)
    with open(os.path.join(OUT, "cornell.md"), "w") as f:
        f.write(md + "\n")
    with open(os.path.join(OUT, "cornell.json"), "w") as f:
        json.dump({"args": vars(a), "runs": runs, "reference": ref_meta}, f, indent=1,
                  default=str)
    print("\n[cornell] wrote bench/out/cornell.md and bench/out/cornell.json")


def render_report(a, peers, runs, ref, ref_meta) -> str:
    pixels = a.res * a.res * a.spp
    name = {"candela": "Candela"} | {
        key: f"Mitsuba 3 {v}" + (f", {s} sampler" if s else "") for key, v, s in peers}
    keys = [key for key, _, _ in peers]
    # The reference is rendered with the scene's independent sampler: its noise share is
    # estimated from the rows that sample as it does.
    independent_keys = [key for key, _, s in peers if s is None]
    t_candela = statistics.median(r["render_s"] for r in runs["candela"])
    rows, stat_rows, side_rows, first_images = [], [], [], {}
    equal_error = {}  # key -> (time used, relMSE)
    for key in ["candela"] + keys:
        rs = runs[key]
        if key == "candela":
            times = [r["render_s"] for r in rs]
            procs = [r["process_s"] for r in rs]
            cpus = [r["cpu_s"] for r in rs]
            loads = [r["load_before"].split()[0] for r in rs]
            mrays = report.fmt(statistics.median(r["mrays_per_s"] for r in rs))
            warm = "—"
        else:
            times = [r["renders"][0]["wall_s"] for r in rs]
            procs = [r["process_s"] for r in rs]
            cpus = [r["renders"][0]["cpu_s"] for r in rs]
            loads = [r["renders"][0]["load"].split()[0] for r in rs]
            mrays = "n/a"
            warm = report.fmt(statistics.median(r["warm"][0]["wall_s"] for r in rs))
        imgs = [images.load_exr(r["out"]) for r in rs]
        first_images[key] = imgs[0]
        t = statistics.median(times)
        warm_t = t if key == "candela" else statistics.median(
            (r["warm"][0]["wall_s"] if r["warm"] else r["renders"][0]["wall_s"]) for r in rs)
        equal_error[key] = (warm_t, statistics.mean(images.relmse(x, ref) for x in imgs))
        cpu = statistics.median(cpus)
        cpu_candela = statistics.median(r["cpu_s"] for r in runs["candela"])
        rows.append([name[key], report.fmt(t), report.fmt(min(times)), warm,
                     report.fmt(t / t_candela), report.fmt(cpu), report.fmt(cpu / cpu_candela),
                     report.fmt(statistics.median(procs)),
                     report.fmt(pixels / t / 1e6), mrays,
                     f"{statistics.mean(images.relmse(x, ref) for x in imgs):.5f}",
                     " ".join(loads)])
        z = images.mean_difference_z(imgs[0], ref)
        stat_rows.append([name[key], report.fmt_rgb(images.mean_rgb(imgs[0])),
                          report.fmt_rgb(z, 2),
                          "yes" if max(abs(z)) < images.Z_CRIT else "**NO**"])
        side_rows.append(f"{name[key]}: red wall on the {images.red_wall_side(imgs[0])}")
    stat_rows.append([f"reference ({ref_meta['spp']} spp {ref_meta['variant']})",
                      report.fmt_rgb(images.mean_rgb(ref)), "—", "—"])
    cross = []
    for v in keys:
        z = images.mean_difference_z(first_images["candela"], first_images[v])
        cross.append([f"Candela − {name[v]}", report.fmt_rgb(z, 2),
                      "yes" if max(abs(z)) < images.Z_CRIT else "**NO**"])

    # Time to equal error. The Mitsuba reference shares the Mitsuba renders' estimator, so
    # it adds relMSE_M·r/(1 + r), r = spp/ref_spp, to every relMSE; that share is taken
    # off. Each Mitsuba variant's time to Candela's error follows from its independent
    # samples, whose relMSE falls exactly as 1/time in expectation: t·relMSE/relMSE_C.
    r = a.spp / ref_meta["spp"]
    mitsuba_relmse = [equal_error[v][1] for v in independent_keys]
    ref_noise = statistics.median(mitsuba_relmse) * r / (1 + r) if mitsuba_relmse else 0.0
    t_c, e_c = equal_error["candela"]
    e_c_net = max(e_c - ref_noise, 1e-12)
    ee_rows = []
    for key in ["candela"] + keys:
        t, e = equal_error[key]
        e_net = max(e - ref_noise, 1e-12)
        t_eq = t * e_net / e_c_net
        ee_rows.append([name[key], report.fmt(t), f"{e:.5f}", f"{e_net:.5f}",
                        report.fmt(t_eq), report.fmt(t_eq / t_c)])

    m = machine.describe(REPO)
    mi_run = runs[keys[0]][0] if keys else None
    lines = [
        f"### Cornell box, {a.res}×{a.res}, {a.spp} spp, max depth {a.max_depth} "
        f"(Mitsuba max_depth {a.max_depth + 1}), {a.threads} threads",
        "",
        f"Machine: {m['cpu']}, nproc {m['nproc']}, {m['memory_gib']} GiB; {m['os']}; "
        f"date {m['date']}; candela git {m['git']}"
        + (f"; Mitsuba {mi_run['mitsuba']} / Dr.Jit {mi_run['drjit']}" if mi_run else ""),
        "",
        report.table(["renderer", "render s (median)", "min s", "warm s", "× Candela",
                      "CPU s", "CPU × Candela", "process s", "M paths/s", "M rays/s", "relMSE", "load1 per run"],
                     rows),
        "",
        f"Median of {a.repeats} interleaved runs, each Mitsuba run in a fresh process with "
        f"Dr.Jit's thread pool set to {a.threads}. *render s*: Candela's own summary (render "
        "only, no load/BVH/write); for Mitsuba the first `mi.render` in the process "
        "(llvm_ad_rgb: with an empty kernel cache, so JIT compilation is included). "
        "*warm s*: a second `mi.render` in the same process (kernels compiled). "
        "*× Candela*: render time ÷ Candela's (>1: Candela is faster). *CPU s*: user + "
        "system CPU seconds of all threads over the same span (for Candela: its whole "
        "process, which adds a little load/BVH/write time); on a loaded machine this is "
        "the steadier measure, and ≈ wall × threads on an idle one. *process s*: whole "
        "process (start, load, render, write). *M paths/s* = pixels × spp ÷ render s. "
        f"*relMSE* (mean over runs) against the reference below, ε = {images.RELMSE_EPS}; "
        f"it includes the reference's own noise (≈ {a.spp / ref_meta['spp']:.3g} × a "
        f"{a.spp}-spp image's, its seeds being independent of theirs). "
        "*load1*: 1-minute load average just before each run (2 cores: load ≫ 2 means "
        "the timing was disturbed).",
        "",
        "Time to equal error (Candela's relMSE at its spp):",
        "",
        report.table(["renderer", "time s", "relMSE", "relMSE − ref noise",
                      "s to Candela's error", "÷ Candela's time"], ee_rows),
        "",
        f"*time s*: median render time (Mitsuba llvm_ad_rgb: the warm render, kernels "
        f"compiled). *relMSE − ref noise*: minus {ref_noise:.2e}, the share of the "
        f"{ref_meta['spp']}-spp Mitsuba reference's own noise (Mitsuba relMSE × r/(1 + r), "
        f"r = {r:.3g}). *s to Candela's error* = time × net relMSE ÷ Candela's net relMSE: "
        "exact in expectation for Mitsuba's independent samples (relMSE ∝ 1/time). "
        "For a stratified sampler relMSE falls faster than 1/time, so where its error is "
        "below Candela's the true time to Candela's error is longer than this figure: the "
        "ratio is then a bound that favours Mitsuba. "
        "*÷ Candela's time* above 1 means Candela reaches that error sooner.",
        "",
        "Mean radiance (first run's image) and z of the mean pixel difference against the "
        f"reference, per channel (agree: all |z| < {images.Z_CRIT}, α = 0.001 two-sided):",
        "",
        report.table(["image", "mean RGB", "z vs reference", "agree"], stat_rows, "llll"),
        "",
        report.table([f"pair ({a.spp} spp each)", "z", "agree"], cross, "lll") if cross else "",
        "",
        "Orientation: " + "; ".join(side_rows) + ".",
        "",
        "Commands:",
        "",
        "```",
        " ".join(["bench/setup.sh && bench/cornell.sh"] + sys.argv[1:]),
        " ".join(os.path.relpath(c, REPO) if c.startswith(REPO) else c
                 for c in runs["candela"][0]["command"]),
    ]
    for key, v, _ in peers:
        cmd = runs[key][0]["command"]
        lines.append("(cd bench && " + ("DRJIT_LIBLLVM_PATH=… " if v.startswith("llvm") else "")
                     + " ".join(os.path.relpath(c, BENCH_DIR) if c.startswith(BENCH_DIR) else c
                                for c in cmd) + ")")
    lines.append("```")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
