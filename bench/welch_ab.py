"""Two candela binaries render the same expected image: per-tile Welch tests.

Each binary renders the scene `--renders` times with different seeds; per square tile,
each render's mean luminance is one observation, and Welch's t-test compares the two
binaries' observations tile by tile (as `crates/candela-core/tests/mis_consistency.rs`).
A change of sampling that keeps the image unbiased fails about α × tiles tiles by
chance; a bias fails many. Also prints how many pixels differ at all (0 for a change
that should leave the image bit for bit as it was) and each binary's mean per-pixel
variance over the renders (the noise each leaves at this spp).

Usage: bench/welch_ab.sh --a /work/bin/candela-main --b target/release/candela \
    --scene bench/scenes/hdr-sky-sun.xml [--res 64] [--spp 16] [--renders 8] [-- ARGS]
"""

import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, BENCH_DIR)

from benchlib import images, stats  # noqa: E402

LUMA = np.array([0.2126, 0.7152, 0.0722])


def renders(binary: str, a, seed_base: int, tmp: str) -> np.ndarray:
    out = []
    for k in range(a.renders):
        path = os.path.join(tmp, f"{os.path.basename(binary)}-{k}.pfm")
        subprocess.run([binary, "render", a.scene, "-o", path, "--spp", str(a.spp),
                        "--res", f"{a.res}x{a.res}", "--seed", str(seed_base + k),
                        "--threads", str(a.threads)] + a.args,
                       check=True, capture_output=True)
        out.append(images.read_pfm(path))
    return np.array(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--a", required=True)
    ap.add_argument("--b", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--renders", type=int, default=8)
    ap.add_argument("--tile", type=int, default=8)
    ap.add_argument("--alpha", type=float, default=0.001)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("args", nargs="*", help="extra arguments for both binaries")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ra = renders(a.a, a, 1000, tmp)
        rb = renders(a.b, a, 2000, tmp)
        same_seed = renders(a.b, a, 1000, tmp)[:1]
    t = a.res // a.tile
    lum = lambda r: (r @ LUMA).reshape(len(r), t, a.tile, t, a.tile).mean(axis=(2, 4))
    ta, tb = lum(ra).reshape(len(ra), -1), lum(rb).reshape(len(rb), -1)
    p = np.array([stats.welch(ta[:, i], tb[:, i])[1] for i in range(ta.shape[1])])
    fails = int((p < a.alpha).sum())
    differ = int((np.abs(same_seed[0] - ra[0]).max(axis=-1) > 0).sum())
    var = [float(r.var(axis=0, ddof=1).mean()) for r in (ra, rb)]
    print(f"{os.path.basename(a.scene)}: {fails} of {len(p)} tiles fail at α = {a.alpha} "
          f"(expected by chance {a.alpha * len(p):.2f}); smallest p {p.min():.2g}; "
          f"same seed: {differ} of {a.res * a.res} pixels differ; "
          f"mean pixel variance A {var[0]:.4g}, B {var[1]:.4g} (B/A {var[1] / var[0]:.3f})")


if __name__ == "__main__":
    main()
