"""Image I/O and the error measures the comparisons use.

Images are float64 numpy arrays of shape (height, width, 3), linear Rec.709 radiance.
EXR is read and written through Mitsuba's own `mi.Bitmap` (so no OpenEXR binding is
needed); any Mitsuba variant must be set before `load_exr`.
"""

import math

import numpy as np

# Two-sided significance of the mean-radiance z-tests: |z| above this at α = 0.001 says
# the means differ. α is small because each comparison runs 3 channels × several images,
# and a false alarm would send someone hunting for a bug that is not there.
Z_CRIT = 3.29  # Φ⁻¹(1 − 0.001/2)

# relMSE's ε: keeps black pixels from dominating (the usual 1e-2 of the literature, e.g.
# Rousselle et al. 2011).
RELMSE_EPS = 1e-2


def load_exr(path: str) -> np.ndarray:
    import mitsuba as mi
    bmp = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32,
                                  srgb_gamma=False)
    return np.array(bmp, dtype=np.float64)


def read_pfm(path: str) -> np.ndarray:
    """An RGB PFM, as candela writes it, top row first."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"PF":
            raise ValueError(f"{path}: not an RGB PFM")
        w, h = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    # PFM stores the bottom row first.
    return data.reshape(h, w, 3)[::-1].astype(np.float64)


# Side of the pixel tiles that bootstrap standard errors resample (a tile's pixels share
# their neighbourhood's noise, so tiles, not pixels, are close to independent).
TILE = 16


def tile_sums(x: np.ndarray) -> np.ndarray:
    """Per-tile sums of a (h, w) map, tiles of TILE² pixels (partial tiles dropped)."""
    h, w = (x.shape[0] // TILE) * TILE, (x.shape[1] // TILE) * TILE
    return x[:h, :w].reshape(h // TILE, TILE, w // TILE, TILE).sum(axis=(1, 3)).ravel()


def relative_variances(groups: dict) -> dict:
    """For each group of renders of one scene (a list of images differing only in their
    seeds), the variance of one render per pixel and channel across the group, relative
    to (m² + ε) with m the pixel's mean over every render of every group (relMSE's ε),
    averaged over the channels: an (h, w) map per group. For unbiased renders this is
    their whole error, measured without a reference image."""
    mean = np.mean([img for imgs in groups.values() for img in imgs], axis=0)
    den = mean ** 2 + RELMSE_EPS
    return {key: (np.array(imgs).var(axis=0, ddof=1) / den).mean(axis=-1)
            for key, imgs in groups.items()}


def tile_ratio(num: np.ndarray, den: np.ndarray, rng, draws: int = 200) -> tuple:
    """The ratio of two maps' sums of tile sums (`tile_sums`) and its standard error from
    a bootstrap over the tiles (the same tiles drawn for both)."""
    picks = rng.integers(0, len(num), size=(draws, len(num)))
    boot = num[picks].sum(axis=1) / den[picks].sum(axis=1)
    return num.sum() / den.sum(), boot.std(ddof=1)


def relmse(x: np.ndarray, ref: np.ndarray) -> float:
    """Mean over pixels and channels of (x − ref)² / (ref² + ε)."""
    return float(np.mean((x - ref) ** 2 / (ref ** 2 + RELMSE_EPS)))


def mean_rgb(x: np.ndarray) -> np.ndarray:
    return x.reshape(-1, 3).mean(axis=0)


def mean_difference_z(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Per channel, z = mean(x − y) / (std(x − y) / √N) over the N pixels.

    Both images are Monte Carlo estimates of the same picture with independent samples in
    every pixel, so under "same expected image" each pixel difference has mean 0 and the
    pixels are independent: by the CLT z is standard normal (N = 262144 at 512²). A bias
    in either renderer (geometry, camera, emitter side, depth convention) shows as |z|
    far above Z_CRIT."""
    d = (x - y).reshape(-1, 3)
    se = d.std(axis=0, ddof=1) / math.sqrt(d.shape[0])
    return d.mean(axis=0) / np.where(se > 0, se, np.inf)


def red_wall_side(x: np.ndarray) -> str:
    """"left" when the image's left third is redder (R/G) than its right third: the
    Cornell box's red wall, seen from the standard camera, must be on the left."""
    third = x.shape[1] // 3
    def redness(part):
        m = mean_rgb(part)
        return m[0] / max(m[1], 1e-12)
    return "left" if redness(x[:, :third]) > redness(x[:, -third:]) else "right"
