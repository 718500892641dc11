"""Candela, a physically based path tracer, from Python.

>>> import candela
>>> scene = candela.load("scenes/cornell.toml")
>>> img = candela.render(scene, spp=16)          # float32 NumPy array (H, W, 3)
>>> candela.write("cornell.png", img, exposure=0.5, tonemap="aces")

Sample ranges merge exactly: ``candela.merge([candela.render(scene, samples=range(0, 8)),
candela.render(scene, samples=range(8, 16))]).image()`` equals ``candela.render(scene)``
bit for bit. ``python -m candela.distributed`` runs such ranges as Ray tasks.

``candela.denoise(img, p["albedo"], p["normal"])``, with ``p = candela.render_aovs(scene,
spp=16)``, runs Intel Open Image Denoise (``pip install pyoidn``) on an image, guided by
its albedo and normal passes.
"""

from __future__ import annotations

import importlib.util
import os
import sys
import time
from typing import Any, Dict, Iterable, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _candela
from ._candela import DenoiseError, Film, MergeError, Scene, SceneError

__all__ = [
    "DenoiseError",
    "Film",
    "MergeError",
    "Scene",
    "SceneError",
    "denoise",
    "film_image",
    "info",
    "load",
    "merge",
    "read_film",
    "render",
    "render_aovs",
    "write",
]

PathLike = Union[str, "os.PathLike[str]"]


def load(
    path: PathLike,
    *,
    lenient: bool = False,
    gltf_scene: Optional[int] = None,
    **params: Any,
) -> Scene:
    """Loads a scene: Candela TOML, Mitsuba 3 XML or glTF 2.0 (.gltf/.glb).

    ``params`` set scene parameters as ``-D NAME=VALUE`` does on the command line (a
    Mitsuba ``$name``); values are converted with ``str``. ``lenient`` skips what Candela
    does not support with a warning (see ``scene.warnings``) instead of failing.

    Raises ``candela.SceneError`` whose message is ``file:line:col: what is wrong``.
    """
    defines = [(str(k), str(v)) for k, v in params.items()]
    return _candela.load(os.fspath(path), defines, lenient, gltf_scene)


def film_image(film: Film) -> np.ndarray:
    """The film's resolved image: float32 linear radiance, shape (height, width, 3);
    the same as ``film.image()``."""
    return film.image()


class _Bar:
    """A text progress bar on stderr (tqdm's when it is installed)."""

    def __init__(self) -> None:
        self._tqdm = None
        self._start = time.monotonic()
        self._last = -1
        try:
            from tqdm.auto import tqdm  # type: ignore

            self._tqdm = tqdm(total=100, unit="%", desc="candela")
        except ImportError:
            pass

    def __call__(self, done: int, total: int) -> None:
        pct = int(100 * done / total) if total else 100
        if pct == self._last:
            return
        if self._tqdm is not None:
            self._tqdm.update(pct - max(self._last, 0))
        else:
            width = 40
            fill = width * pct // 100
            elapsed = time.monotonic() - self._start
            sys.stderr.write(
                f"\r[{'#' * fill}{'.' * (width - fill)}] {pct:3d}% {elapsed:6.1f} s"
            )
            if pct == 100:
                sys.stderr.write("\n")
            sys.stderr.flush()
        self._last = pct
        if pct == 100 and self._tqdm is not None:
            self._tqdm.close()


def render(
    scene: Scene,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
    progress: bool = False,
    samples: Optional[range] = None,
    filter_sampling: Optional[str] = None,
) -> Union[np.ndarray, Film]:
    """Renders a scene.

    ``spp`` and ``seed`` override the scene's own; the same seed gives the same image,
    bit for bit the CLI's ``candela render --spp N --seed S``. ``threads``: worker
    threads (default: all cores). ``progress=True`` draws a bar on stderr.
    ``filter_sampling``: ``"splat"`` or ``"importance"`` over the scene's own (as
    ``--filter-sampling``), for a pixel filter wider than a pixel (a Mitsuba scene's
    tent or Gaussian); an image for :func:`denoise` needs ``"importance"``.

    Without ``samples`` it returns the image, a float32 array (height, width, 3) of
    linear radiance. With ``samples=range(a, b)`` (within ``range(spp)``, step 1) it
    renders only those sample indices of every pixel and returns a :class:`Film`, which
    :func:`merge` adds exactly to the films of other ranges of the same render.

    The GIL is released while rendering; Ctrl-C (KeyboardInterrupt) stops the render
    within a fraction of a second and raises.
    """
    bounds = None
    if samples is not None:
        if not isinstance(samples, range) or samples.step != 1:
            raise ValueError("samples must be a range(a, b) with step 1")
        bounds = (samples.start, samples.stop)
    bar = _Bar() if progress else None
    film = _candela.render_film(scene, spp, seed, bounds, threads, bar, filter_sampling)
    return film if samples is not None else film_image(film)


def render_aovs(
    scene: Scene,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
) -> Dict[str, np.ndarray]:
    """The albedo, normal and depth passes of the render of the same ``spp`` and
    ``seed``, as ``candela render --aov albedo,normal,depth`` writes them: averaged over
    that render's own sample positions, each through perfect mirrors and glass to the
    first other surface (Open Image Denoise's definition).

    Returns ``{"albedo": (H, W, 3), "normal": (H, W, 3), "depth": (H, W)}``, float32:
    albedo in [0, 1], world-space shading normals (averaged, not renormalized; zero
    where nothing is hit), depth along the camera's axis (+inf where nothing is hit).
    ``candela.denoise(img, passes["albedo"], passes["normal"])`` denoises ``img =
    candela.render(scene, spp=..., seed=...)`` with them. Each pass's camera rays are
    filter-importance-sampled: they match ``render(..., filter_sampling="importance")``
    (any filter; the box filter renders the same either way). The GIL is released while
    rendering.
    """
    raw = _candela.render_aovs(scene, spp, seed, threads)
    w, h = scene.resolution
    out = {
        name: np.frombuffer(raw[name], dtype="<f4").reshape(h, w, 3).astype(np.float32)
        for name in ("albedo", "normal")
    }
    out["depth"] = np.frombuffer(raw["depth"], dtype="<f4").reshape(h, w).astype(np.float32)
    return out


def merge(films: Iterable[Film]) -> Film:
    """Adds films of disjoint sample ranges of one render into the film of their union.

    Any split of ``range(spp)`` merges to the single render bit for bit, in any order.
    Raises ``candela.MergeError`` for films of another scene, resolution, seed or spp,
    or overlapping ranges.
    """
    return _candela.merge(list(films))


def read_film(path: PathLike) -> Film:
    """Reads a film part (.exr) written by ``candela render --samples``, ``candela merge``
    or :meth:`Film.save`."""
    return _candela.read_film(os.fspath(path))


def write(
    path: PathLike,
    image: Union[np.ndarray, Film],
    exposure: float = 0.0,
    tonemap: str = "none",
    gamma: Optional[float] = None,
) -> None:
    """Writes an image as .exr or .pfm (linear) or .png (8-bit sRGB after ``exposure``
    stops, the ``tonemap`` curve and the sRGB curve, or a pure ``gamma`` power law), as
    ``candela render`` does. ``image``: an array (height, width, 3) of linear radiance,
    or a :class:`Film` (written with its exact sums when the path ends in .exr, so it
    can be merged later). The file is written to a temporary name and renamed."""
    path = os.fspath(path)
    if isinstance(image, Film):
        if path.lower().endswith(".exr"):
            image.save(path)
            return
        image = film_image(image)
    arr = np.ascontiguousarray(np.asarray(image, dtype="<f4"))
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise ValueError(f"expected an image of shape (height, width, 3), got {arr.shape}")
    h, w, _ = arr.shape
    _candela.write_pixels(path, arr.tobytes(), w, h, exposure, tonemap, gamma)


def info(scene: Scene) -> Dict[str, Any]:
    """What the scene contains, as ``candela info`` prints it: resolution, spp, seed,
    shapes, triangles, instances, lights and their power, materials, bounds and the
    fingerprint that film parts carry."""
    return _candela.info(scene)


def _image_bytes(name: str, a: Any, shape: Optional[Tuple[int, ...]] = None) -> bytes:
    """The bytes of a float32 (height, width, 3) array of finite values, or a clear error
    naming the argument."""
    if not isinstance(a, np.ndarray):
        raise TypeError(f"{name} must be a NumPy array, got {type(a).__name__}")
    if a.dtype != np.float32:
        raise TypeError(
            f"{name} must be float32, got {a.dtype} (convert with {name}.astype(np.float32))"
        )
    if a.ndim != 3 or a.shape[2] != 3 or a.shape[0] == 0 or a.shape[1] == 0:
        raise ValueError(f"{name} must have shape (height, width, 3), got {a.shape}")
    if shape is not None and a.shape != shape:
        raise ValueError(f"{name} has shape {a.shape}, the image {shape}: they must match")
    if not np.isfinite(a).all():
        raise ValueError(f"{name} holds NaN or infinite values")
    return np.ascontiguousarray(a, dtype="<f4").tobytes()


def _pyoidn_folder() -> Optional[str]:
    """The folder of the ``pyoidn`` package this interpreter would import (found without
    importing it), where its wheel keeps ``oidn/lib/libOpenImageDenoise.so.2``."""
    try:
        spec = importlib.util.find_spec("pyoidn")
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.submodule_search_locations:
        return None
    return list(spec.submodule_search_locations)[0]


def denoise(
    img: np.ndarray,
    albedo: Optional[np.ndarray] = None,
    normal: Optional[np.ndarray] = None,
    *,
    prefilter: bool = True,
    hdr: bool = True,
    threads: Optional[int] = None,
) -> np.ndarray:
    """Denoises a rendered image with Intel Open Image Denoise 2.x (its ``RT`` filter on
    the CPU, high quality), as ``candela render --denoise`` does.

    ``img``: float32 array (height, width, 3) of linear radiance (``hdr=True``, any
    non-negative value) or a display image in [0, 1] (``hdr=False``). ``albedo`` and
    ``normal``: optional guide passes of the same shape, as ``candela render --aov
    albedo,normal`` writes them (albedo in [0, 1]; normals in [-1, 1], world or camera
    space); ``normal`` needs ``albedo``. With ``prefilter=True`` (the default) the guides
    are denoised first and the image's filter is told they are clean, OIDN's
    high-quality recipe for guides rendered with the image's noise; ``prefilter=False``
    passes them as they are. ``threads``: OIDN's threads (default: all cores).

    OIDN cannot denoise a splatted image: render a scene whose pixel filter is wider
    than a pixel (a Mitsuba scene's tent or Gaussian, Mitsuba's default) with
    ``candela.render(..., filter_sampling="importance")``, as ``candela render
    --denoise`` does; TOML scenes use the box filter, which needs nothing.

    Returns a new float32 array (height, width, 3). The GIL is released while filtering.
    Raises ``TypeError`` / ``ValueError`` for arrays of another dtype, shape or with
    non-finite values, and ``candela.DenoiseError`` when the library is absent (the
    message says ``pip install pyoidn``) or fails. The library is looked for in
    ``OIDN_DIR`` (a folder holding ``lib/libOpenImageDenoise.so.2``), then in the
    ``pyoidn`` package this interpreter imports, and loaded once per process.
    """
    color = _image_bytes("img", img)
    shape = img.shape
    a = None if albedo is None else _image_bytes("albedo", albedo, shape)
    n = None if normal is None else _image_bytes("normal", normal, shape)
    if n is not None and a is None:
        raise ValueError("normal needs albedo too (Open Image Denoise takes a normal pass "
                         "only beside an albedo pass)")
    h, w, _ = shape
    out = _candela.denoise(color, w, h, a, n, prefilter, hdr, threads, _pyoidn_folder())
    return np.frombuffer(out, dtype="<f4").reshape(h, w, 3).astype(np.float32)
