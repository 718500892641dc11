"""Per-tile z-test of a `bench/compare_mitsuba` run: for each 16x16 tile and channel,
z = mean(x - ref) / (std(x - ref) / 16) between a renderer's image and the Mitsuba
reference that compare_mitsuba cached in bench/out/compare/. Under "same expected image"
each z is standard normal; |z| > 3.29 flags a tile at alpha = 0.001. Used for the media
scenes (bench/scenes/media-*.xml; see bench/RESULTS.md).

    bench/.venv/bin/python bench/media_tiles.py media-room   # after compare_mitsuba ran it
"""

import os
import sys

import numpy as np

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, BENCH_DIR)

import mitsuba as mi  # noqa: E402

from benchlib import images  # noqa: E402

TILE = images.TILE


def main() -> None:
    mi.set_variant("scalar_rgb")
    name = sys.argv[1]
    out = os.path.join(BENCH_DIR, "out", "compare")
    ref = images.load_exr(os.path.join(out, f"{name}_reference.exr"))
    for who in ["candela_0", "llvm_ad_rgb_0"]:
        path = os.path.join(out, f"{name}_{who}.exr")
        if not os.path.exists(path):
            continue
        x = images.load_exr(path)
        h, w = ref.shape[0] // TILE * TILE, ref.shape[1] // TILE * TILE
        d = (x - ref)[:h, :w].reshape(h // TILE, TILE, w // TILE, TILE, 3)
        se = d.std(axis=(1, 3), ddof=1) / TILE
        z = d.mean(axis=(1, 3)) / np.where(se > 0, se, np.inf)
        beyond = int((np.abs(z) > images.Z_CRIT).sum())
        print(f"{who}: max |z| per channel {np.round(np.abs(z).max(axis=(0, 1)), 2)}, "
              f"{beyond} of {z.size} tile-channels beyond {images.Z_CRIT}")
        for c in range(3):
            print(f"  channel {c}:\n{np.round(z[..., c], 1)}")


if __name__ == "__main__":
    main()
