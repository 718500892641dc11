"""Render a Mitsuba 3 scene in a fresh process, with the thread count pinned and the
first render (which, in the LLVM variants, traces and JIT-compiles its kernel) timed
apart from later ones.

As a module it is the child: `python -m benchlib.mitsuba_render --scene ... --out ...`
prints one JSON object on its last line. `run()` is the parent side: it starts the child
with the environment a variant needs and returns that object. A fresh process per variant
keeps the variants from sharing a thread pool or JIT state, and lets the parent kill a
render that hangs.

Each pass k renders with seed `seed + k`; with several passes the image written is their
mean (how a high-spp reference is built without one huge LLVM wavefront).
"""

import argparse
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from typing import Optional

BENCH_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV_PYTHON = os.path.join(BENCH_DIR, ".venv", "bin", "python")
LIBLLVM_PATH_FILE = os.path.join(BENCH_DIR, ".venv", "libllvm_path")


def libllvm_path() -> Optional[str]:
    """The libLLVM that bench/setup.sh found, or the environment's DRJIT_LIBLLVM_PATH."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return os.environ["DRJIT_LIBLLVM_PATH"]
    try:
        with open(LIBLLVM_PATH_FILE) as f:
            path = f.read().strip()
        return path if os.path.exists(path) else None
    except OSError:
        return None


def run(scene: str, out: str, *, variant: str, threads: int, spp: int = 0,
        max_depth: int = 0, res: int = 0, params: Optional[dict] = None, seed: int = 0,
        passes: int = 1, warm_runs: int = 0, cold_kernel_cache: bool = False,
        render_spp: int = 0, sampler: Optional[str] = None, timeout_s: float = 3600) -> dict:
    """Render in a child process and return its JSON report (see `_child`).

    The scene's parameters are `params` (name → value, as `-D` gives them) when given,
    otherwise `spp`, `max_depth` and `res` (the benchmark scenes' parameters).
    `render_spp` > 0 overrides the scene's sample count in `mi.render` (for scenes
    without an `$spp` parameter). `sampler` replaces the type of the scene's one
    `<sampler>` (e.g. "multijitter"), keeping its parameters.
    `cold_kernel_cache` points Dr.Jit's on-disk kernel cache (~/.drjit) at an empty
    directory, so that the first render really compiles its kernels."""
    if params is None:
        params = {"spp": spp, "max_depth": max_depth, "res": res}
    env = dict(os.environ)
    if variant.startswith("llvm"):
        path = libllvm_path()
        if path is None:
            raise RuntimeError("no libLLVM: run bench/setup.sh or set DRJIT_LIBLLVM_PATH")
        env["DRJIT_LIBLLVM_PATH"] = path
    cmd = [VENV_PYTHON, "-m", "benchlib.mitsuba_render", "--scene", scene, "--out", out,
           "--variant", variant, "--threads", str(threads), "--params", json.dumps(params),
           "--seed", str(seed),
           "--passes", str(passes), "--warm-runs", str(warm_runs),
           "--spp", str(render_spp)] + (["--sampler", sampler] if sampler else [])
    with tempfile.TemporaryDirectory(prefix="drjit-home-") as home:
        if cold_kernel_cache:
            env["HOME"] = home
        t0 = time.perf_counter()
        p = subprocess.run(cmd, cwd=BENCH_DIR, env=env, capture_output=True, text=True,
                           timeout=timeout_s)
        process_s = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr}{p.stdout}")
    # Mitsuba's log may leave a colour reset code before the report on its line.
    last = p.stdout.strip().splitlines()[-1]
    report = json.loads(last[last.find("{"):])
    report["process_s"] = process_s
    report["command"] = cmd
    return report


def _cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _os_threads() -> int:
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return -1


def _with_sampler(path: str, sampler: str) -> str:
    """The scene file's text with its one `<sampler type="...">` set to `sampler`; the
    file's directory goes first on Mitsuba's file resolver, so relative paths in the text
    resolve as in the file."""
    import mitsuba as mi

    with open(path) as f:
        text, n = re.subn(r'(<sampler\s+type=")[^"]*(")', rf"\g<1>{sampler}\g<2>", f.read())
    if n != 1:
        raise SystemExit(f"{path}: expected one <sampler type=...>, found {n}")
    mi.file_resolver().prepend(os.path.dirname(os.path.abspath(path)))
    return text


def _child(a: argparse.Namespace) -> dict:
    t0 = time.perf_counter()
    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant(a.variant)
    mi.set_log_level(mi.LogLevel.Warn)
    # Mitsuba 3 renders on Dr.Jit's thread pool in every variant, scalar ones included.
    dr.set_thread_count(a.threads)
    if dr.thread_count() != a.threads:
        raise SystemExit(f"asked for {a.threads} threads, Dr.Jit has {dr.thread_count()}")
    import_s = time.perf_counter() - t0

    t0 = time.perf_counter()
    params = json.loads(a.params)
    params = {k: str(v) for k, v in params.items()}
    if a.sampler:
        scene = mi.load_string(_with_sampler(a.scene, a.sampler), **params)
    else:
        scene = mi.load_file(a.scene, **params)
    load_s = time.perf_counter() - t0

    def timed_render(seed: int):
        from . import machine
        load = machine.loadavg()
        c0, t0 = _cpu_s(), time.perf_counter()
        img = mi.render(scene, seed=seed, spp=a.spp)
        dr.eval(img)
        dr.sync_thread()
        arr = np.array(img, dtype=np.float64)
        wall = time.perf_counter() - t0
        return arr, {"seed": seed, "wall_s": wall, "cpu_s": _cpu_s() - c0,
                     "os_threads": _os_threads(), "load": load}

    acc, renders = None, []
    for k in range(a.passes):
        arr, info = timed_render(a.seed + k)
        acc = arr if acc is None else acc + arr
        renders.append(info)
    mean = acc / a.passes
    # Extra renders after the first: their time excludes JIT compilation (the kernels are
    # cached in memory by then), their images are not kept.
    warm = [timed_render(a.seed + a.passes + k)[1] for k in range(a.warm_runs)]

    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    mi.Bitmap(mean.astype(np.float32)).write(a.out)
    return {
        "variant": a.variant, "mitsuba": mi.__version__, "drjit": dr.__version__,
        "threads": dr.thread_count(), "params": params, "passes": a.passes, "import_s": import_s, "load_s": load_s,
        "renders": renders, "warm": warm, "out": a.out,
        "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--params", required=True,
                    help="the scene's parameters as a JSON object, e.g. {\"spp\": 64}")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--passes", type=int, default=1)
    ap.add_argument("--warm-runs", type=int, default=0)
    ap.add_argument("--spp", type=int, default=0,
                    help="samples per pixel for mi.render (0: the scene's sample_count)")
    ap.add_argument("--sampler", help="replace the scene's sampler type (e.g. multijitter)")
    report = _child(ap.parse_args())
    sys.stdout.flush()
    print(json.dumps(report), flush=True)
    # Dr.Jit's pool can keep the interpreter from exiting promptly (seen with one
    # thread); everything is written, so leave without running atexit handlers.
    os._exit(0)


if __name__ == "__main__":
    main()
