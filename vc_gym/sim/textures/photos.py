"""Real pictures from matplotlib's sample data: photos and elevation maps as RGB images.

vc_gym already depends on matplotlib, whose sample data holds a few photos
(:data:`SAMPLE_PHOTOS`, hung as posters) and elevation models (:data:`MAP_IMAGES`, drawn
as coloured maps). Each file is read once per process; a file that is not installed gives
``None``, and the scenes fall back to procedural posters.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import cv2
import numpy as np

from vc_gym.worlds.paint import to_uint8

__all__ = ["MAP_IMAGES", "SAMPLE_PHOTOS", "map_image", "photo_posters", "sample_photo"]

#: Real photos in matplotlib's sample data used as posters (those that exist are used).
SAMPLE_PHOTOS = ("grace_hopper.jpg", "Minduka_Present_Blue_Pack.png", "logo2.png")
#: Elevation models in matplotlib's sample data, drawn as colour maps ("map" posters).
MAP_IMAGES = ("topobathy.npz", "jacksboro_fault_dem.npz")


@functools.lru_cache(maxsize=8)
def _sample_rgba(name: str) -> np.ndarray | None:
    from matplotlib import cbook

    try:
        path = cbook.get_sample_data(name, asfileobj=False)
    except (OSError, ValueError):
        return None
    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None:
        return None
    if img.ndim == 2:
        img = cv2.cvtColor(img, cv2.COLOR_GRAY2BGRA)
    elif img.shape[2] == 3:
        img = cv2.cvtColor(img, cv2.COLOR_BGR2BGRA)
    img = cv2.cvtColor(img, cv2.COLOR_BGRA2RGBA)
    img.setflags(write=False)
    return img


def sample_photo(name: str, background: Sequence[float] = (255, 255, 255)) -> np.ndarray | None:
    """A photo from matplotlib's sample data as RGB.

    Parameters
    ----------
    name : str
        File name in matplotlib's ``sample_data`` folder (see :data:`SAMPLE_PHOTOS`).
    background : sequence of float
        RGB colour (0..255) shown through transparent pixels.

    Returns
    -------
    numpy.ndarray or None
        ``(H, W, 3)`` ``uint8`` RGB, or ``None`` if the file is not installed.
    """
    rgba = _sample_rgba(name)
    if rgba is None:
        return None
    alpha = rgba[:, :, 3:].astype(np.float32) / 255.0
    bg = np.asarray(background, dtype=np.float32)
    return to_uint8(rgba[:, :, :3] * alpha + bg * (1.0 - alpha))


@functools.lru_cache(maxsize=1)
def _photos() -> tuple[np.ndarray, ...]:
    out = []
    for name in SAMPLE_PHOTOS:
        img = sample_photo(name)
        if img is not None:
            img.setflags(write=False)
            out.append(img)
    return tuple(out)


def photo_posters() -> list[np.ndarray]:
    """Every installed photo of :data:`SAMPLE_PHOTOS` as RGB (on white), read-only."""
    return list(_photos())


@functools.lru_cache(maxsize=8)
def _dem(name: str) -> np.ndarray | None:
    from matplotlib import cbook

    try:
        with np.load(cbook.get_sample_data(name, asfileobj=False)) as data:
            key = "topo" if "topo" in data.files else "elevation"
            z = np.asarray(data[key], dtype=np.float32)
    except (OSError, ValueError, KeyError):
        return None
    z.setflags(write=False)
    return z


def map_image(name: str, cmap: str = "terrain", height: int = 240) -> np.ndarray | None:
    """An elevation model from matplotlib's sample data drawn as a coloured map.

    Parameters
    ----------
    name : str
        One of :data:`MAP_IMAGES`.
    cmap : str
        Name of a matplotlib colour map.
    height : int
        Height of the result in pixels (the aspect of the data is kept).

    Returns
    -------
    numpy.ndarray or None
        ``(height, W, 3)`` ``uint8`` RGB, or ``None`` if the file is not installed.
    """
    import matplotlib

    z = _dem(name)
    if z is None:
        return None
    t = (z - z.min()) / max(float(z.max() - z.min()), 1e-6)
    rgb = matplotlib.colormaps[cmap](t)[:, :, :3] * 255.0
    h, w = z.shape
    width = max(2, int(round(height * w / h)))
    return cv2.resize(to_uint8(rgb), (width, height), interpolation=cv2.INTER_AREA)
