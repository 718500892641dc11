"""What Open Image Denoise is given (issue #38): cheap checks at 128² of the inputs behind
the denoising benchmark (bench/denoise.py), through the Python package.

1. Guides on the Cornell box (16 spp): the beauty alone, albedo alone, albedo + normal
   prefiltered (`--denoise`), the same unprefiltered (noisy guides, `cleanAux` off), and
   guides from 256 spp — is the denoised image limited by its guides?
2. Sampler: the same with independent, Sobol' and Sobol'+CMJ (the default) samples.
3. Resolution: the Cornell box at 128² and 256²: raw 256 spp against denoised 16 spp.
4. A wide pixel filter: Mitsuba's Cornell box with Mitsuba's default Gaussian, splatted
   (Candela's default) or importance-sampled (`--denoise`'s choice), raw and denoised.

Errors against a 1024-spp reference (seed 1; every other image seed 2): relMSE with the
worst 1 % of pixels dropped and HDR-FLIP (flip-evaluator, default exposures), as in
bench/denoise.py, plus the exposure range FLIP chose. Needs a Python with the candela
package, pyoidn and flip-evaluator:
`pip install "./crates/candela-py[denoise]" flip-evaluator`.
"""

import argparse
import os
import re
import sys
import tempfile

import numpy as np

import candela

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
from benchlib import machine  # noqa: E402
from denoise import flip_hdr, per_pixel_relmse, relmse_dropped  # noqa: E402

REPO = os.path.dirname(here)


class Scenes:
    """Copies of bundled scenes with other settings, beside links to their assets."""

    def __init__(self, folder):
        self.folder = folder
        for assets in ("cornell",):
            os.symlink(os.path.join(REPO, "scenes", assets), os.path.join(folder, assets))

    def toml(self, name, res, render=""):
        text = open(os.path.join(REPO, "scenes", name + ".toml")).read()
        text = re.sub(r"resolution = \[\d+, \d+\]", f"resolution = [{res[0]}, {res[1]}]", text)
        text = text.replace("[render]\n", "[render]\n" + render, 1)
        path = os.path.join(self.folder, f"{name}-{res[0]}-{len(os.listdir(self.folder))}.toml")
        open(path, "w").write(text)
        return candela.load(path)

    def mitsuba_gaussian(self, res):
        text = open(os.path.join(REPO, "scenes/mitsuba-cornell.xml")).read()
        assert '<rfilter type="box"/>' in text
        path = os.path.join(self.folder, "mitsuba-gaussian.xml")
        open(path, "w").write(text.replace('<rfilter type="box"/>', ""))
        return candela.load(path, res=res)


def report(label, x, ref):
    assert np.isfinite(x).all(), label
    flip_mean, _ = flip_hdr(x, ref)
    print(f"| {label} | {relmse_dropped(x, ref):.5f} | {float(per_pixel_relmse(x, ref).mean()):.5f}"
          f" | {flip_mean:.4f} |", flush=True)


def header(title, ref):
    _, p = flip_hdr(ref, ref)
    print(f"\n{title} (HDR-FLIP exposures {p['startExposure']:.2f} to {p['stopExposure']:.2f}, "
          f"{p['numExposures']} steps)\n\n| image | relMSE, worst 1 % dropped | relMSE | HDR-FLIP |\n"
          "| --- | ---: | ---: | ---: |", flush=True)


def guided(scene, img, spp, seed=2, **kw):
    p = candela.render_aovs(scene, spp=spp, seed=seed, threads=kw.pop("threads", None))
    return candela.denoise(img, p["albedo"], p["normal"], **kw)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--threads", type=int, default=None)
    a = ap.parse_args()
    t = a.threads
    info = machine.describe(REPO)
    print(f"{info['date']}, {info['git']}, {info['cpu']} ({info['nproc']} threads), "
          f"load {machine.loadavg()}", flush=True)
    with tempfile.TemporaryDirectory() as folder:
        s = Scenes(folder)
        # 1. Guides.
        cornell = s.toml("cornell", (128, 128))
        ref = candela.render(cornell, spp=a.ref_spp, seed=1, threads=t)
        raw16 = candela.render(cornell, spp=16, seed=2, threads=t)
        header("Cornell box 128², 16 spp: guides", ref)
        report("raw 16 spp", raw16, ref)
        report("raw 256 spp", candela.render(cornell, spp=256, seed=2, threads=t), ref)
        report("denoised, beauty alone", candela.denoise(raw16), ref)
        p16 = candela.render_aovs(cornell, spp=16, seed=2, threads=t)
        report("denoised, albedo prefiltered", candela.denoise(raw16, p16["albedo"]), ref)
        report("denoised, albedo + normal prefiltered (`--denoise`)",
               candela.denoise(raw16, p16["albedo"], p16["normal"]), ref)
        report("denoised, albedo + normal not prefiltered",
               candela.denoise(raw16, p16["albedo"], p16["normal"], prefilter=False), ref)
        report("denoised, albedo + normal of 256 spp, prefiltered",
               guided(cornell, raw16, 256, seed=3, threads=t), ref)
        # 2. Sampler.
        header("Cornell box 128², 16 spp: sampler", ref)
        for sampler in ("independent", "sobol", "sobol-cmj"):
            sc = s.toml("cornell", (128, 128), f'sampler = "{sampler}"\n')
            img = candela.render(sc, spp=16, seed=2, threads=t)
            report(f"{sampler}, raw", img, ref)
            report(f"{sampler}, denoised (albedo + normal)", guided(sc, img, 16, threads=t), ref)
        # 3. Resolution.
        big = s.toml("cornell", (256, 256))
        ref_big = candela.render(big, spp=a.ref_spp, seed=1, threads=t)
        header("Cornell box 256²", ref_big)
        img = candela.render(big, spp=16, seed=2, threads=t)
        report("raw 16 spp", img, ref_big)
        report("raw 256 spp", candela.render(big, spp=256, seed=2, threads=t), ref_big)
        report("denoised 16 spp, albedo + normal", guided(big, img, 16, threads=t), ref_big)
        report("denoised 16 spp, beauty alone", candela.denoise(img), ref_big)
        # 4. A wide filter.
        mg = s.mitsuba_gaussian(128)
        ref_g = candela.render(mg, spp=a.ref_spp, seed=1, threads=t, filter_sampling="importance")
        header("Mitsuba Cornell box, Gaussian filter, 128²", ref_g)
        report("raw 256 spp, splatted",
               candela.render(mg, spp=256, seed=2, threads=t, filter_sampling="splat"), ref_g)
        for how in ("splat", "importance"):
            img = candela.render(mg, spp=16, seed=2, threads=t, filter_sampling=how)
            report(f"raw 16 spp, {how}", img, ref_g)
            report(f"denoised 16 spp ({how}), albedo + normal", guided(mg, img, 16, threads=t), ref_g)
            report(f"denoised 16 spp ({how}), beauty alone", candela.denoise(img), ref_g)
    print(f"\nload after {machine.loadavg()}")


if __name__ == "__main__":
    main()
