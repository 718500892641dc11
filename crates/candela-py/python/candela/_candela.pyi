"""Type hints of the native module (see ``candela/__init__.py`` for the documented API)."""

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

class SceneError(Exception):
    """A scene that cannot be loaded or built: ``file:line:col: what is wrong``."""

class MergeError(Exception):
    """Films of other scenes, resolutions, seeds or spp, or overlapping ranges."""

class DenoiseError(RuntimeError):
    """Open Image Denoise is absent (the message says ``pip install pyoidn``) or failed."""

class Scene:
    """A loaded scene description."""

    @property
    def path(self) -> str: ...
    @property
    def resolution(self) -> Tuple[int, int]: ...
    @property
    def spp(self) -> int: ...
    @property
    def seed(self) -> int: ...
    @property
    def warnings(self) -> List[str]: ...

class Film:
    """The film of a range of sample indices: exact sums that merge bit for bit."""

    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def samples(self) -> List[Tuple[int, int]]:
        """The (start, end) sample-index ranges held."""
    @property
    def spp(self) -> int:
        """Samples per pixel of the whole render this film is part of."""
    @property
    def seed(self) -> int: ...
    @property
    def fingerprint(self) -> str: ...
    @property
    def complete(self) -> bool:
        """Whether the film holds every sample of range(spp)."""
    @property
    def rejected(self) -> int: ...
    def image(self) -> np.ndarray:
        """float32 (height, width, 3) linear radiance."""
    def save(self, path: str) -> None:
        """Writes an OpenEXR part file that ``candela merge`` reads."""

def load(
    path: str, defines: Sequence[Tuple[str, str]], lenient: bool = False, gltf_scene: Optional[int] = None
) -> Scene: ...
def render_film(
    scene: Scene,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    samples: Optional[Tuple[int, int]] = None,
    threads: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
    filter_sampling: Optional[str] = None,
) -> Film: ...
def merge(films: Sequence[Film]) -> Film: ...
def read_film(path: str) -> Film: ...
def _film_from_bytes(data: bytes) -> Film: ...
def write_pixels(
    path: str,
    pixels: bytes,
    width: int,
    height: int,
    exposure: float = 0.0,
    tonemap: str = "none",
    gamma: Optional[float] = None,
) -> None: ...
def info(scene: Scene) -> Dict[str, Any]: ...
def denoise(
    color: bytes,
    width: int,
    height: int,
    albedo: Optional[bytes] = None,
    normal: Optional[bytes] = None,
    prefilter: bool = True,
    hdr: bool = True,
    threads: Optional[int] = None,
    pyoidn: Optional[str] = None,
) -> bytes:
    """Float32 RGB bytes (row-major) denoised by OIDN's RT filter; see ``candela.denoise``."""
def render_aovs(
    scene: Scene, spp: Optional[int] = None, seed: Optional[int] = None, threads: Optional[int] = None
) -> Dict[str, bytes]:
    """Float32 bytes (row-major) of the "albedo", "normal" (3 a pixel) and "depth" passes."""
