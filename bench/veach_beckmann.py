"""How much the Beckmann → GGX substitution changes veach-bidir, measured in Mitsuba alone.

Candela's microfacets are GGX, so its import renders the lamp's Beckmann roughconductor of
veach-bidir as GGX of the same α. This renders the scene twice with Mitsuba 3 llvm_ad_rgb,
as written and with the lamp's distribution set to ggx, at the same seeds and spp, and
prints each image's mean against the cached reference of `bench/compare_mitsuba` (which
must have run on veach-bidir first: it writes bench/out/compare/veach-bidir_box.xml and
the reference), with z of the mean pixel difference.

    bench/.venv/bin/python bench/veach_beckmann.py [--passes 16]
"""

import argparse
import os
import sys

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, BENCH_DIR)

from benchlib import images, mitsuba_render  # noqa: E402

OUT = os.path.join(BENCH_DIR, "out", "compare")
# Far from the reference's and the benchmark runs' seeds, so the noise is independent.
SEED = 300_000


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--passes", type=int, default=16, help="passes of 64 spp each")
    a = ap.parse_args()
    scene = os.path.join(OUT, "veach-bidir_box.xml")
    reference = os.path.join(OUT, "veach-bidir_reference.exr")
    if not (os.path.exists(scene) and os.path.exists(reference)):
        sys.exit("run bench/compare_mitsuba on veach-bidir first (it writes the scene and reference)")
    with open(scene) as f:
        xml = f.read()
    if 'value="beckmann"' not in xml:
        sys.exit(f"{scene}: no beckmann distribution to replace")
    ggx_scene = os.path.join(OUT, "veach-bidir_box_ggx.xml")
    with open(ggx_scene, "w") as f:
        f.write(xml.replace('value="beckmann"', 'value="ggx"'))
    params = {"integrator": "path", "spp": 64, "resx": 256, "resy": 256}
    ref = images.load_exr(reference)
    for name, path in [("beckmann (as written)", scene), ("ggx", ggx_scene)]:
        out = os.path.join(OUT, f"veach-bidir_{name.split()[0]}_{64 * a.passes}spp.exr")
        mitsuba_render.run(path, out, variant="llvm_ad_rgb", threads=2, params=params,
                           seed=SEED, passes=a.passes)
        x = images.load_exr(out)
        ratio = images.mean_rgb(x) / images.mean_rgb(ref)
        z = images.mean_difference_z(x, ref)
        print(f"{name}, {64 * a.passes} spp: mean ÷ reference's = "
              f"{', '.join(f'{r:.4f}' for r in ratio)}; z = {', '.join(f'{v:.1f}' for v in z)}",
              flush=True)


if __name__ == "__main__":
    main()
