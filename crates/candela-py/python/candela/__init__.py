"""Candela, a physically based path tracer, from Python.

>>> import candela
>>> scene = candela.load("scenes/cornell.toml")
>>> img = candela.render(scene, spp=16)          # float32 NumPy array (H, W, 3)
>>> candela.write("cornell.png", img, exposure=0.5, tonemap="aces")

Sample ranges merge exactly: ``candela.merge([candela.render(scene, samples=range(0, 8)),
candela.render(scene, samples=range(8, 16))]).image()`` equals ``candela.render(scene)``
bit for bit. ``python -m candela.distributed`` runs such ranges as Ray tasks.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any, Dict, Iterable, Mapping, Optional, Sequence, Union

import numpy as np

from . import _candela
from ._candela import Film, MergeError, Scene, SceneError

__all__ = [
    "Film",
    "MergeError",
    "Scene",
    "SceneError",
    "film_image",
    "info",
    "load",
    "merge",
    "read_film",
    "render",
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
) -> Union[np.ndarray, Film]:
    """Renders a scene.

    ``spp`` and ``seed`` override the scene's own; the same seed gives the same image,
    bit for bit the CLI's ``candela render --spp N --seed S``. ``threads``: worker
    threads (default: all cores). ``progress=True`` draws a bar on stderr.

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
    film = _candela.render_film(scene, spp, seed, bounds, threads, bar)
    return film if samples is not None else film_image(film)


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
