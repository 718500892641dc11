"""Candela against Mitsuba 3 on Mitsuba XML scenes that both read: the same file, the same
spp, resolution and max depth, the same number of threads.

For each scene and renderer it prints wall time, relMSE against a reference (a long
Mitsuba render, cached in bench/out/compare/, or an EXR given with --reference), relMSE at
equal time and time to equal error, as Markdown (also written to
bench/out/compare_mitsuba.md). Run through bench/compare_mitsuba.

Equal time and equal error are extrapolated from one measured run each, using that an
unbiased Monte Carlo estimate's MSE falls as 1/spp, and render time grows with spp:
relMSE at time T = relMSE · t / T, and the time to reach error E = t · relMSE / E. Both
are applied to the relMSE less the reference's own noise (estimated, see `noise_floor`).

By default every scene's pixel filter is replaced by a box (`--rfilter file` keeps the
file's): Mitsuba splats each sample into every pixel its filter reaches, Candela samples
the filter (filter importance sampling). Both have the same expected image, but splatting
averages neighbouring pixels' samples, so with a tent its per-pixel variance is ~2.6×
lower at equal spp (measured on the Cornell box) — a property of the filter, not of the
light transport. With a box both estimators are per-pixel averages and compare directly.
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


def peer_name(key: str) -> str:
    """A row's name from its key: "candela", a Mitsuba variant, or VARIANT+SAMPLER."""
    if key == "candela":
        return "Candela"
    variant, _, sampler = key.partition("+")
    return f"Mitsuba 3 {variant}" + (f", {sampler} sampler" if sampler else "")


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


def prepare(scene: str, tag: str, a) -> str:
    """The scene file both renderers read: the file itself with `--rfilter file`, else a
    copy in bench/out/compare/ whose `rfilter` is a box (added where the film has none:
    Mitsuba's default is a Gaussian) and whose relative file names are made absolute."""
    if a.rfilter == "file":
        return scene
    with open(scene) as f:
        xml = f.read()
    folder = os.path.dirname(scene)
    xml, n = re.subn(r"<rfilter\b[^>]*?/>|<rfilter\b[^>]*>.*?</rfilter>",
                     '<rfilter type="box"/>', xml, flags=re.S)
    if n == 0:
        xml, n = re.subn(r"</film>", '<rfilter type="box"/></film>', xml)
    if n == 0:
        raise RuntimeError("no <film> to give a box filter (use --rfilter file)")

    def absolute(m: re.Match) -> str:
        name = m.group(2)
        if "$" in name or os.path.isabs(name):
            return m.group(0)
        return m.group(1) + os.path.normpath(os.path.join(folder, name)) + '"'
    xml = re.sub(r'(<string\s+name="filename"\s+value=")([^"]*)"', absolute, xml)
    xml = re.sub(r'(<include\s+filename=")([^"]*)"', absolute, xml)
    out = os.path.join(OUT, f"{tag}_box.xml")
    with open(out, "w") as f:
        f.write(xml)
    return out


def fingerprint(path: str, params: dict, source: str) -> str:
    """Hash of the scene file read, the files beside the original `source`, and the
    parameters: a cached reference is reused only while all are unchanged."""
    h = hashlib.sha256(json.dumps(params, sort_keys=True).encode())
    with open(path, "rb") as f:
        h.update(f.read())
    folder = os.path.dirname(source)
    for root, _, files in sorted(os.walk(folder)):
        for name in sorted(files):
            if name.endswith((".xml", ".obj", ".ply", ".exr", ".hdr", ".png", ".jpg")):
                with open(os.path.join(root, name), "rb") as f:
                    h.update(name.encode() + f.read())
    return h.hexdigest()[:16]


def reference(scene: str, tag: str, params: dict, a, variant: str, source: str) -> str:
    passes = max(1, a.ref_spp // REF_PASS_SPP)
    ref_params = dict(params, **({"spp": REF_PASS_SPP} if "spp" in params else {}))
    want = {"fingerprint": fingerprint(scene, ref_params, source), "passes": passes}
    path = os.path.join(OUT, f"{tag}_reference.exr")
    meta_path = path + ".json"
    if os.path.exists(path) and os.path.exists(meta_path):
        with open(meta_path) as f:
            meta = json.load(f)
        if all(meta.get(k) == v for k, v in want.items()):
            print(f"[compare] {tag}: reusing {os.path.relpath(path, REPO)}", flush=True)
            return path
    print(f"[compare] {tag}: rendering the reference, {passes} × {REF_PASS_SPP} spp with "
          f"{variant} (cached in bench/out/compare/)", flush=True)
    r = mitsuba_render.run(scene, path, variant=variant, threads=a.threads,
                           params=ref_params, seed=REF_SEED, passes=passes,
                           render_spp=REF_PASS_SPP)
    with open(meta_path, "w") as f:
        json.dump(dict(want, variant=variant, mitsuba=r["mitsuba"]), f, indent=1)
    return path


def given_reference(a, source: str) -> str:
    """The EXR `--reference` names: 'tungsten' is the TungstenRender.exr beside the scene."""
    path = (os.path.join(os.path.dirname(source), "TungstenRender.exr")
            if a.reference == "tungsten" else a.reference)
    if not os.path.exists(path):
        raise RuntimeError(f"no reference image {path}")
    return path


def fit_to(ref, shape: tuple):
    """A reference larger by an integer factor (the 1024² Tungsten renders against a
    256² run) is averaged over blocks, which is the run's box-filtered pixel."""
    fy, fx = ref.shape[0] // shape[0], ref.shape[1] // shape[1]
    if (fy * shape[0], fx * shape[1]) != ref.shape[:2] or fy < 1 or fx < 1:
        raise RuntimeError(f"the reference is {ref.shape[1]}x{ref.shape[0]}, not a multiple "
                           f"of the {shape[1]}x{shape[0]} images")
    return ref.reshape(shape[0], fy, shape[1], fx, 3).mean(axis=(1, 3))


def noise_floor(relmse_mitsuba: float, spp: int, ref_spp: int) -> float:
    """The reference's own noise in a relMSE, where the reference is a Mitsuba render of
    ref_spp samples: an image of spp samples from the same estimator has relMSE
    v·(1 + spp/ref_spp) against it (independent seeds), so that share is
    relmse·r/(1 + r), r = spp/ref_spp, and it adds to every renderer's relMSE alike."""
    r = spp / ref_spp
    return relmse_mitsuba * r / (1 + r)


def measure_equal_time(scene: str, tag: str, params: dict, a, peers: list,
                       runs: dict) -> dict:
    """Checks the extrapolation: each Mitsuba row renders once more with its spp scaled
    so that it takes Candela's median time (key → spp, seconds, image)."""
    t_c = statistics.median(r["time_s"] for r in runs["candela"])
    found = {}
    for key, v, sampler in peers:
        t_v = statistics.median(r["warm_s"] or r["time_s"] for r in runs[key])
        spp = max(1, round(a.spp * t_c / t_v))
        if sampler in ("multijitter", "stratified"):
            spp = max(1, round(spp ** 0.5)) ** 2  # what Mitsuba would round it up to
        print(f"[compare] {tag}: mitsuba {key} at Candela's time: {spp} spp", flush=True)
        out = os.path.join(OUT, f"{tag}_{key}_equal_time.exr")
        r = mitsuba_render.run(scene, out, variant=v, threads=a.threads,
                               params=dict(params, **({"spp": spp} if "spp" in params else {})),
                               seed=1000, render_spp=spp,
                               warm_runs=1 if v.startswith("llvm") else 0, sampler=sampler)
        time_s = r["warm"][0]["wall_s"] if r["warm"] else r["renders"][0]["wall_s"]
        found[key] = {"spp": spp, "time_s": time_s, "out": out}
    return found


def run_candela(scene: str, out: str, params: dict, a, seed: int) -> dict:
    defines = [x for k, v in params.items() for x in ("-D", f"{k}={v}")]
    cmd = [CANDELA, "render", scene, "-o", out, "--threads", str(a.threads),
           "--seed", str(seed), "--spp", str(a.spp)] + defines
    if a.sampler:
        cmd += ["--sampler", a.sampler]
    c0 = candela._children_cpu_s()
    p = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr}")
    m = candela.parse_summary(p.stdout)
    if m is None:
        raise RuntimeError(f"no summary line in candela's output:\n{p.stdout}")
    return {"time_s": float(m["secs"]), "cpu_s": candela._children_cpu_s() - c0,
            "out": out, "command": " ".join(cmd), "warnings": p.stderr.count("warning")}


def compare(scene: str, a, peers: list) -> str:
    """One scene's table; `peers` are the Mitsuba rows, (key, variant, sampler or None
    for the file's)."""
    tag = os.path.basename(os.path.dirname(scene)) if scene.endswith("scene.xml") \
        else os.path.splitext(os.path.basename(scene))[0]
    source = scene
    params = scene_params(scene, a.spp, a.res)
    scene = prepare(scene, tag, a)
    variants = [v for _, v, _ in peers]
    ref_variant = "llvm_ad_rgb" if "llvm_ad_rgb" in variants else "scalar_rgb"
    ref_path = given_reference(a, source) if a.reference else \
        reference(scene, tag, params, a, ref_variant, source)
    keys = [key for key, _, _ in peers]
    runs = {k: [] for k in ["candela"] + keys}
    for rep in range(a.repeats):
        out = os.path.join(OUT, f"{tag}_candela_{rep}.exr")
        print(f"[compare] {tag} run {rep + 1}/{a.repeats}: candela", flush=True)
        runs["candela"].append(run_candela(scene, out, params, a, rep))
        for key, v, sampler in peers:
            print(f"[compare] {tag} run {rep + 1}/{a.repeats}: mitsuba {key}", flush=True)
            out = os.path.join(OUT, f"{tag}_{key}_{rep}.exr")
            r = mitsuba_render.run(scene, out, variant=v, threads=a.threads, params=params,
                                   seed=rep, render_spp=a.spp,
                                   warm_runs=1 if v.startswith("llvm") else 0,
                                   cold_kernel_cache=v.startswith("llvm"), sampler=sampler)
            warm = r["warm"][0]["wall_s"] if r["warm"] else None
            runs[key].append({"time_s": r["renders"][0]["wall_s"], "warm_s": warm,
                            "cpu_s": r["renders"][0]["cpu_s"], "out": out})
    equal_time = measure_equal_time(scene, tag, params, a, peers, runs) \
        if a.measure_equal_time else {}

    import mitsuba as mi  # EXR I/O only
    mi.set_variant("scalar_rgb")
    ref = images.load_exr(ref_path)
    shape = images.load_exr(runs["candela"][0]["out"]).shape
    if ref.shape != shape:
        ref = fit_to(ref, shape[:2])
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
    # The reference samples as the file says: its noise is estimated from the rows that
    # do too.
    same_sampler = [key for key, _, sampler in peers if sampler is None]
    floor = 0.0
    if not a.reference and same_sampler:
        floor = noise_floor(statistics.mean(stats[k]["relmse"] for k in same_sampler), a.spp,
                            max(1, a.ref_spp // REF_PASS_SPP) * REF_PASS_SPP)
    for s in stats.values():
        s["net"] = max(s["relmse"] - floor, 1e-12)
    c = stats["candela"]
    rows = []
    for key in ["candela"] + keys:
        s = stats[key]
        at_candela_time = s["net"] * s["t"] / c["t"]
        to_candela_error = s["t"] * s["net"] / c["net"]
        candela_to_this = c["t"] * c["net"] / s["net"]
        rows.append([peer_name(key), report.fmt(s["t"]), report.fmt(s["t_cold"]),
                     f"{s['relmse']:.5f}", f"{s['net']:.5f}", f"{at_candela_time:.5f}",
                     report.fmt(to_candela_error),
                     "—" if key == "candela" else report.fmt(candela_to_this),
                     "—" if key == "candela" else report.fmt(s["net"] * s["t"]
                                                             / (c["net"] * c["t"])),
                     report.fmt_rgb(s["z"], 1)])
    measured = []
    for v, e in equal_time.items():
        m = images.relmse(images.load_exr(e["out"]), ref) - floor
        measured.append(f"{peer_name(v)} at {e['spp']} spp took {e['time_s']:.2f} s (Candela "
                        f"{c['t']:.2f} s): relMSE − ref noise {m:.5f}, extrapolated "
                        f"{stats[v]['net'] * stats[v]['t'] / c['t']:.5f}")
    defines = " ".join(f"-D {k}={v}" for k, v in params.items())
    rel = os.path.relpath(source, REPO)
    return "\n".join([
        f"#### `{rel}` ({defines or 'file defaults'}), {a.spp} spp, "
        f"{shape[1]}×{shape[0]}, {a.threads} threads, "
        + ("box filter for both" if a.rfilter == "box" else "the file's filter"),
        "",
        report.table(["renderer", "time s", "cold s", "relMSE", "relMSE − ref noise",
                      "relMSE at Candela's time",
                      "s to Candela's error", "Candela s to this error",
                      "efficiency ÷ Candela's", "mean z vs ref (R, G, B)"], rows),
        "",
        f"Reference: {os.path.relpath(ref_path, REPO)}"
        + (f" (estimated noise in every relMSE: {floor:.5f}). " if not a.reference
           else " (taken as converged: nothing subtracted). ") +
        f"Candela: `{runs['candela'][0]['command'].replace(REPO + '/', '')}`.",
        "",
    ] + ([("Measured at equal time (one run each, to check the extrapolation): "
           + "; ".join(measured) + "."), ""] if measured else []) + [
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
    ap.add_argument("--reference", help="an EXR to use as the reference (one scene only; "
                    "block-averaged when an integer multiple of the resolution), or "
                    "'tungsten': the TungstenRender.exr beside each scene")
    ap.add_argument("--rfilter", choices=["box", "file"], default="box",
                    help="box: both render a copy of the scene with a box pixel filter "
                    "(default); file: the file's own filter")
    ap.add_argument("--variants", default="llvm_ad_rgb,scalar_rgb")
    ap.add_argument("--skip-build", action="store_true")
    ap.add_argument("--sampler",
                    help="Candela's --sampler (default: what the XML's <sampler> maps to)")
    ap.add_argument("--mitsuba-stratified", default="llvm_ad_rgb:multijitter",
                    help="extra Mitsuba rows as VARIANT:SAMPLER[,...], the file's <sampler> "
                    "replaced by that type (e.g. multijitter); '' for none")
    ap.add_argument("--measure-equal-time", action="store_true",
                    help="also render each Mitsuba variant once at the spp that takes "
                    "Candela's time, to check the extrapolated equal-time relMSE")
    ap.add_argument("--output", default=os.path.join(BENCH_DIR, "out", "compare_mitsuba.md"),
                    help="where the markdown is written besides stdout")
    a = ap.parse_args()
    variants = [v for v in a.variants.split(",") if v]
    extra = [tuple(x.split(":", 1)) for x in a.mitsuba_stratified.split(",") if x]
    if mitsuba_render.libllvm_path() is None:
        if "llvm_ad_rgb" in variants:
            print("[compare] no libLLVM (run bench/setup.sh): skipping llvm_ad_rgb",
                  flush=True)
            variants.remove("llvm_ad_rgb")
        extra = [(v, s) for v, s in extra if not v.startswith("llvm")]
    peers = [(v, v, None) for v in variants] + [(f"{v}+{s}", v, s) for v, s in extra]
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
        try:
            parts.append(compare(scene, a, peers))
        except Exception as e:  # one scene failing must not lose the others' figures
            print(f"[compare] {scene} failed: {e}", flush=True)
            parts += [f"#### `{os.path.relpath(scene, REPO)}`: not compared: "
                      f"{str(e).strip().splitlines()[-1]}", ""]
    parts.append(
        "*time s*: render only (Candela's summary line; Mitsuba's `mi.render`, for "
        "llvm_ad_rgb the second render in the process, kernels compiled); *cold s*: "
        "Mitsuba's first render including JIT compilation. *relMSE*: mean over runs of "
        f"(x − ref)²/(ref² + {images.RELMSE_EPS}), reference noise included; *relMSE − "
        "ref noise* subtracts the reference's own noise, estimated from the Mitsuba runs "
        "as relMSE·r/(1 + r), r = spp/ref_spp (same estimator as the reference), and is "
        "what the next columns use. Extrapolated with relMSE ∝ 1/time, not measured "
        "(exact in expectation for independent samples; a stratified sampler's relMSE "
        "falls faster, so where its error is below Candela's the extrapolation favours "
        "it): "
        "*relMSE at Candela's time* = relMSE · t / t_Candela; *s to Candela's error* = "
        "t · relMSE / relMSE_Candela; *efficiency ÷ Candela's* = (relMSE · t) / "
        "(relMSE_Candela · t_Candela): above 1, Candela reaches equal error sooner. "
        "*mean z*: mean image difference to the reference in standard errors (|z| > 3.3 "
        "flags a bias at α = 0.001, reference differences included).")
    md = "\n".join(parts)
    print("\n" + md)
    os.makedirs(os.path.dirname(os.path.abspath(a.output)), exist_ok=True)
    with open(a.output, "w") as f:
        f.write(md + "\n")


if __name__ == "__main__":
    main()
