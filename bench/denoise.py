"""Denoising benchmark (issue #38): on the Cornell box and other bundled scenes, a 16-spp
render denoised by Intel Open Image Denoise (`candela render --denoise`, guided by the
albedo and normal passes, and `--denoise=color`, the beauty alone) against the raw 16-
and 256-spp renders, each compared with a reference of the same scene (4096 spp unless
--ref-spp).

Errors: relMSE with the worst 1 % of pixels dropped (per-pixel relMSE, mean over the
channels, ε = 1e-2; a denoiser rightly softens the edges of directly seen lamps, which
plain relMSE punishes out of all proportion; plain relMSE is printed too) and HDR-FLIP
(`flip-evaluator` from PyPI, its default exposure range and 67 pixels per degree).
Low-frequency error (--samplers runs): "binned relMSE" is the relMSE of the images
averaged over 4×4 pixel bins (the error a viewer sees from afar: white noise loses 16× of
its power to the binning, blue noise more), and "LF power" the mean power of the
luminance error's spectrum below 1/8 cycle per pixel over its mean at all frequencies
(about 1 for white noise, below 1 for blue).
Times are candela's own: the path tracer, plus the AOV pass and the denoiser where they
ran (loading, building and writing excluded), on all the machine's cores (or --threads).
Scenes render at their own resolution (--scale for a fraction of it); references are
kept in --out and reused, so `--scenes cornell` then `--scenes glass_sphere` run one
reference at a time.

Run through bench/denoise.sh, which makes target/oidn-venv with pyoidn, numpy and
flip-evaluator and points OIDN_DIR at the wheel's library.
"""

import argparse
import os
import re
import subprocess
import sys

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
from benchlib import machine, report  # noqa: E402
from benchlib.images import RELMSE_EPS, read_pfm  # noqa: E402

REPO = os.path.dirname(here)
# Bundled scenes at their own resolutions (--scale for a fraction): the Cornell box, the
# glass sphere and the plastics by default, the others by --scenes.
SCENES = [
    ("scenes/cornell.toml", (512, 512)),
    ("scenes/glass_sphere.toml", (320, 240)),
    ("scenes/plastics.toml", (480, 160)),
    ("scenes/textured-light.toml", (480, 270)),
    ("scenes/many_lights.toml", (400, 300)),
    ("scenes/ies-room.toml", (480, 320)),
    ("scenes/environment.toml", (480, 270)),
    ("scenes/media.toml", (320, 240)),
]
SUMMARY = re.compile(r"(\d+)x(\d+), (\d+) spp, ([\d.]+) s,")
PASSES = re.compile(r"passes [a-z, ]+ in ([\d.]+) s")
DENOISED = re.compile(r"denoised \([^)]*\) in ([\d.]+) s")
DROP = 0.01


def render(binary, scene, out, res, spp, seed, threads, extra=()):
    """Renders and returns candela's time: path tracer + AOV pass + denoiser."""
    cmd = [binary, "render", scene, "-o", out, "--spp", str(spp), "--seed", str(seed),
           "--res", f"{res[0]}x{res[1]}", *extra]
    if threads:
        cmd += ["--threads", str(threads)]
    p = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr}{p.stdout}")
    total = 0.0
    for pattern in (SUMMARY, PASSES, DENOISED):
        m = pattern.search(p.stdout)
        if m:
            total += float(m.groups()[-1])
    return total


def per_pixel_relmse(x, ref):
    return ((x - ref) ** 2 / (ref ** 2 + RELMSE_EPS)).mean(axis=-1).ravel()


def relmse_dropped(x, ref):
    e = np.sort(per_pixel_relmse(x, ref))
    return float(e[: int(round(len(e) * (1.0 - DROP)))].mean())


def flip_hdr(x, ref):
    """HDR-FLIP's mean error and the exposure range it chose from the reference."""
    import flip_evaluator as flip
    _, mean, params = flip.evaluate(np.ascontiguousarray(ref, dtype=np.float32),
                                    np.ascontiguousarray(np.maximum(x, 0.0), dtype=np.float32),
                                    "HDR", applyMagma=False)
    return float(mean), params


def binned_relmse(x, ref, b=4):
    """relMSE of the images averaged over b×b bins (the edges that do not fill a bin cut)."""
    h, w = (ref.shape[0] // b) * b, (ref.shape[1] // b) * b
    def bin_(img):
        return img[:h, :w].reshape(h // b, b, w // b, b, -1).mean(axis=(1, 3))
    return float(per_pixel_relmse(bin_(x), bin_(ref)).mean())


def low_frequency_power(x, ref, cutoff=0.125):
    """Mean power of the luminance error's spectrum at 0 < |f| <= cutoff (cycles per pixel)
    over its mean at every frequency but 0: about 1 for white noise."""
    w = np.array([0.2126, 0.7152, 0.0722])
    e = (x - ref) @ w
    power = np.abs(np.fft.fft2(e)) ** 2
    fy = np.fft.fftfreq(e.shape[0])[:, None]
    fx = np.fft.fftfreq(e.shape[1])[None, :]
    f = np.sqrt(fx ** 2 + fy ** 2)
    return float(power[(f > 0) & (f <= cutoff)].mean() / power[f > 0].mean())


def name_of(scene):
    """scenes/cornell.toml -> cornell."""
    return os.path.splitext(os.path.basename(scene))[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", default=os.path.join(REPO, "target/release/candela"))
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--out", default=os.path.join(here, "out/denoise"))
    ap.add_argument("--scale", type=float, default=1.0,
                    help="resolution as a fraction of each scene's own (default 1)")
    ap.add_argument("--threads", type=int, default=0,
                    help="candela's threads (default: all cores)")
    ap.add_argument("--scenes", default="cornell,glass_sphere,plastics",
                    help="comma-separated names of the scenes to run, in order: "
                         + ", ".join(name_of(scene) for scene, _ in SCENES))
    ap.add_argument("--seed", type=int, default=2,
                    help="seed of every image but the reference (seed 1)")
    ap.add_argument("--samplers", default="",
                    help="comma-separated --sampler values to run each variant with (default: "
                         "the renderer's default only); adds the low-frequency error columns")
    ap.add_argument("--variants", default="raw16,raw256,denoised16,color16,denoised64",
                    help="which images to make, of raw16, raw256, denoised16 (albedo + "
                         "normal), color16 (beauty alone), denoised64")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    info = machine.describe(REPO)
    print(f"{info['date']}, {info['git']}, {info['cpu']} ({info['nproc']} threads), "
          f"load before {machine.loadavg()}", flush=True)
    known = {
        "raw16": ("raw", 16, ()),
        "raw256": ("raw", 256, ()),
        "denoised16": ("denoised, albedo + normal", 16, ("--denoise",)),
        "color16": ("denoised, beauty alone", 16, ("--denoise=color",)),
        "denoised64": ("denoised, albedo + normal", 64, ("--denoise",)),
    }
    samplers = [x for x in a.samplers.split(",") if x] or [None]
    variants = []
    for sampler in samplers:
        for v in a.variants.split(","):
            label, spp, extra = known[v]
            if sampler:
                label, extra = f"{sampler}, {label}", (*extra, "--sampler", sampler)
            variants.append((label, spp, extra))
    spectral = bool(a.samplers)
    rows = []
    scenes = {name_of(scene): (scene, own) for scene, own in SCENES}
    for name in a.scenes.split(","):
        scene, own = scenes[name]
        res = (round(own[0] * a.scale), round(own[1] * a.scale))
        tag = f"{name}-{res[0]}x{res[1]}"
        ref_path = os.path.join(a.out, f"{tag}-ref{a.ref_spp}.pfm")
        if not os.path.exists(ref_path):
            t = render(a.binary, scene, ref_path, res, a.ref_spp, 1, a.threads)
            print(f"{name}: reference {a.ref_spp} spp in {t:.1f} s", flush=True)
        ref = read_pfm(ref_path)
        for label, spp, extra in variants:
            out = os.path.join(a.out, f"{tag}-{spp}-{'-'.join(extra) or 'raw'}-s{a.seed}.pfm")
            t = render(a.binary, scene, out, res, spp, a.seed, a.threads, extra)
            x = read_pfm(out)
            assert np.isfinite(x).all(), out
            plain = float(per_pixel_relmse(x, ref).mean())
            flip_mean, params = flip_hdr(x, ref)
            row = [f"{name} {res[0]}×{res[1]}", label, spp, f"{t:.2f}",
                   f"{relmse_dropped(x, ref):.5f}", f"{plain:.5f}", f"{flip_mean:.4f}"]
            if spectral:
                row += [f"{binned_relmse(x, ref):.6f}", f"{low_frequency_power(x, ref):.3f}"]
            print(" | ".join(map(str, row)), flush=True)
            rows.append(row)
        print(f"{name}: HDR-FLIP exposures {params['startExposure']:.2f} to "
              f"{params['stopExposure']:.2f} in {params['numExposures']} steps, "
              f"{params['ppd']:.1f} ppd, {params['tonemapper']}", flush=True)
    print(f"load after {machine.loadavg()}\n")
    header = ["scene", "image", "spp", "time (s)", "relMSE, worst 1 % dropped", "relMSE",
              "HDR-FLIP"]
    if spectral:
        header += ["binned relMSE (4×4)", "LF power"]
    print(report.table(header, rows, "ll" + "r" * (len(header) - 2)))


if __name__ == "__main__":
    main()
