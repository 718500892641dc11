#!/usr/bin/env python3
"""Writes smoke.vol, the density grid of scenes/media.toml: a 24^3 Mitsuba VOL (version 3,
float32, one channel) of a few soft blobs rising in a column, from a fixed formula (no
random numbers), so the file is reproducible. Standard library only.

    python3 scenes/media/make_smoke.py   # rewrites scenes/media/smoke.vol
"""
import math
import os
import struct

N = 24


def density(x, y, z):
    """Density at a point of the unit cube: blobs along a slightly twisting column."""
    d = 0.0
    for i in range(5):
        t = i / 4
        cx = 0.5 + 0.18 * math.sin(3.0 * t)
        cz = 0.5 + 0.18 * math.cos(2.0 * t + 0.5)
        cy = 0.15 + 0.7 * t
        r = 0.22 - 0.06 * t
        q = ((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / (r * r)
        d += math.exp(-2.5 * q)
    # A fine ripple so that the grid is visibly heterogeneous.
    d *= 0.75 + 0.25 * math.sin(17 * x + 5 * y) * math.cos(13 * z - 7 * y)
    return max(d, 0.0)


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "smoke.vol")
    data = bytearray(b"VOL\x03")
    data += struct.pack("<i", 1)  # float32
    data += struct.pack("<3i", N, N, N)
    data += struct.pack("<i", 1)  # channels
    data += struct.pack("<6f", 0, 0, 0, 1, 1, 1)
    for k in range(N):
        for j in range(N):
            for i in range(N):
                p = [(c + 0.5) / N for c in (i, j, k)]
                data += struct.pack("<f", density(*p))
    tmp = out + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, out)


if __name__ == "__main__":
    main()
