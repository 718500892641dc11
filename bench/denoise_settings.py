"""What Open Image Denoise's settings and the guides' sample count change (issue #38): on
one bundled scene, a 16-spp render denoised with the guides rendered at 16, 64 and 256
spp, each prefiltered with `cleanAux` (what `--denoise` does, at the beauty's spp), passed
as they are with `cleanAux` (clean guides need no prefilter), or passed as noisy guides
(`cleanAux` off); then, with `--denoise`'s guides, OIDN's `inputScale` in place of its
own HDR auto-exposure, and `quality` balanced instead of high. Last, the raw 256-spp and
the `--denoise` image with each pixel's error negated at random: the same relMSE, with the
errors' spatial structure made white, to tell what HDR-FLIP weighs.

OIDN is driven through `pyoidn` directly, so that every setting can be chosen; the images
come from the candela Python package (the same pixels as `candela render`, seed 2; the
reference seed 1). Errors as in bench/denoise.py: relMSE with the worst 1 % of pixels
dropped, plain relMSE, HDR-FLIP with flip-evaluator's defaults. Times are wall seconds of
the AOV pass and of the filters (all of them: prefilters included).

References are cached in --out (`NAME-WxH-refSPP.npy`), so a second run costs only the
16- and 256-spp renders, the AOV passes and the filters. Needs a Python with the candela
package, pyoidn, numpy and flip-evaluator (`pip install "./crates/candela-py[denoise]"
flip-evaluator`).
"""

import argparse
import os
import re
import sys
import tempfile
import time

import numpy as np
import pyoidn

import candela

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
from benchlib import machine, report  # noqa: E402
from denoise import flip_hdr, per_pixel_relmse, relmse_dropped  # noqa: E402

REPO = os.path.dirname(here)


def load_scene(folder, name, res):
    """scenes/NAME.toml at `res`, copied into `folder` beside links to the scenes' assets."""
    for entry in os.listdir(os.path.join(REPO, "scenes")):
        if os.path.isdir(os.path.join(REPO, "scenes", entry)):
            os.symlink(os.path.join(REPO, "scenes", entry), os.path.join(folder, entry))
    text = open(os.path.join(REPO, "scenes", name + ".toml")).read()
    text, n = re.subn(r"resolution = \[\d+, \d+\]", f"resolution = [{res[0]}, {res[1]}]", text)
    assert n == 1, name
    # Paths up out of scenes/ (the sky in ../assets) resolve from the copy's parent.
    text = text.replace('"../assets/', f'"{REPO}/assets/')
    path = os.path.join(folder, name + ".toml")
    open(path, "w").write(text)
    return candela.load(path)


def oidn(color, albedo=None, normal=None, prefilter=False, clean_aux=False, input_scale=None,
         quality=pyoidn.OIDN_QUALITY_HIGH, threads=0):
    """OIDN's `RT` filter on the CPU, HDR; guides prefiltered by their own filters first
    if `prefilter`. Returns the denoised image and the seconds all filters took."""
    h, w, _ = color.shape
    start = time.perf_counter()

    def run(images, hdr, clean):
        out = np.zeros_like(images[0][1])
        with pyoidn.Device() as device:
            if threads:
                device.set_int("numThreads", threads)
            device.commit()
            with pyoidn.Filter(device, pyoidn.OIDN_FILTER_TYPE_RT) as f:
                for name, image in images:
                    f.set_image(name, image, pyoidn.OIDN_FORMAT_FLOAT3, w, h)
                f.set_image(pyoidn.OIDN_IMAGE_OUTPUT, out, pyoidn.OIDN_FORMAT_FLOAT3, w, h)
                f.set_bool("hdr", hdr)
                f.set_bool("cleanAux", clean)
                f.set_int("quality", quality)
                if hdr and input_scale is not None:
                    f.set_float("inputScale", input_scale)
                f.commit()
                f.execute()
            error = device.get_error()
            assert error is None, error
        return out

    images = [(pyoidn.OIDN_IMAGE_COLOR, np.ascontiguousarray(color, np.float32))]
    for name, guide in ((pyoidn.OIDN_IMAGE_ALBEDO, albedo), (pyoidn.OIDN_IMAGE_NORMAL, normal)):
        if guide is not None:
            guide = np.ascontiguousarray(guide, np.float32)
            images.append((name, run([(name, guide)], False, False) if prefilter else guide))
    out = run(images, True, clean_aux)
    return out, time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="cornell", help="a bundled scene's name")
    ap.add_argument("--res", default="256x256", help="WxH (default 256x256)")
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--guide-spp", default="16,64,256")
    ap.add_argument("--threads", type=int, default=0, help="default: all cores")
    ap.add_argument("--out", default=os.path.join(here, "out/denoise"))
    a = ap.parse_args()
    res = tuple(int(v) for v in a.res.split("x"))
    t = a.threads or None
    os.makedirs(a.out, exist_ok=True)
    info = machine.describe(REPO)
    print(f"{info['date']}, {info['git']}, {info['cpu']} ({info['nproc']} threads), "
          f"load before {machine.loadavg()}", flush=True)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        scene = load_scene(folder, a.scene, res)
        cache = os.path.join(a.out, f"{a.scene}-{res[0]}x{res[1]}-ref{a.ref_spp}.npy")
        if not os.path.exists(cache):
            np.save(cache, candela.render(scene, spp=a.ref_spp, seed=1, threads=t))
        ref = np.load(cache).astype(np.float64)

        def row(label, x, secs=""):
            assert np.isfinite(x).all(), label
            flip_mean, params = flip_hdr(x, ref)
            rows.append([label, secs, f"{relmse_dropped(x, ref):.5f}",
                         f"{float(per_pixel_relmse(x, ref).mean()):.5f}", f"{flip_mean:.4f}"])
            print(" | ".join(rows[-1]), flush=True)
            return params

        start = time.perf_counter()
        raw16 = candela.render(scene, spp=16, seed=2, threads=t)
        params = row("raw 16 spp", raw16, f"{time.perf_counter() - start:.2f}")
        start = time.perf_counter()
        raw256 = candela.render(scene, spp=256, seed=2, threads=t)
        row("raw 256 spp", raw256, f"{time.perf_counter() - start:.2f}")
        out, secs = oidn(raw16, threads=a.threads)
        row("beauty alone", out, f"{secs:.2f}")
        guides = {}
        for n in (int(v) for v in a.guide_spp.split(",")):
            start = time.perf_counter()
            p = candela.render_aovs(scene, spp=n, seed=2, threads=t)
            aov_secs = time.perf_counter() - start
            guides[n] = (p["albedo"], p["normal"])
            for label, kw in (("prefiltered, cleanAux", dict(prefilter=True, clean_aux=True)),
                              ("as they are, cleanAux", dict(clean_aux=True)),
                              ("as they are, noisy (cleanAux off)", {})):
                out, secs = oidn(raw16, *guides[n], threads=a.threads, **kw)
                row(f"guides of {n} spp, {label}", out, f"{aov_secs:.2f} + {secs:.2f}")
        albedo, normal = guides[min(guides)]
        for scale in (0.25, 1.0, 4.0, 16.0):
            out, secs = oidn(raw16, albedo, normal, True, True, input_scale=scale, threads=a.threads)
            row(f"`--denoise`, inputScale {scale:g} (not auto)", out, f"{secs:.2f}")
        out, secs = oidn(raw16, albedo, normal, True, True, quality=pyoidn.OIDN_QUALITY_BALANCED,
                         threads=a.threads)
        row("`--denoise`, quality balanced (not high)", out, f"{secs:.2f}")
        # The raw 256-spp and the `--denoise` image's errors, each pixel's error (its
        # three channels together) kept or negated at random: relMSE is unchanged (but
        # where the clamp at 0 bites), and the errors' spatial structure becomes white
        # noise. What FLIP says then is about the errors' size; the rest of its verdict
        # is about their structure.
        out, _ = oidn(raw16, albedo, normal, True, True, threads=a.threads)
        signs = np.random.default_rng(7).choice([-1.0, 1.0], size=(*ref.shape[:2], 1))
        for label, x in (("raw 256 spp", raw256), ("`--denoise`", out)):
            row(f"{label}, each pixel's error negated at random",
                np.maximum(ref + signs * (x - ref), 0.0))
    print(f"load after {machine.loadavg()}\n")
    print(f"{a.scene} {res[0]}×{res[1]}, 16 spp unless said, against {a.ref_spp} spp; HDR-FLIP "
          f"exposures {params['startExposure']:.2f} to {params['stopExposure']:.2f} in "
          f"{params['numExposures']} steps\n")
    print(report.table(["image", "time (s): AOV + filters", "relMSE, worst 1 % dropped",
                        "relMSE", "HDR-FLIP"], rows, "lrrrr"))


if __name__ == "__main__":
    main()
