"""Textures for the simulated scenes: real photos and procedural, coarse images.

The head camera is 208×160, so every texture is coarse (no fine stripes: they alias).
Real photos come from matplotlib's sample data, which the package already depends on.
PyBullet loads textures from files: :class:`TextureStore` writes each image once per
scene build into a private temporary folder and loads it once (texture memory is freed
only by ``resetSimulation``).
"""

from __future__ import annotations

import atexit
import colorsys
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

__all__ = ["TextureStore", "photo_posters", "procedural_poster", "carpet", "sky_panorama"]

_PHOTOS = ("grace_hopper.jpg", "Minduka_Present_Blue_Pack.png", "logo2.png")


def _hsv(h: float, s: float, v: float) -> np.ndarray:
    r, g, b = colorsys.hsv_to_rgb(h % 1.0, min(max(s, 0.0), 1.0), min(max(v, 0.0), 1.0))
    return np.array([r, g, b]) * 255.0


def random_colour(rng: np.random.Generator, s: tuple = (0.5, 1.0), v: tuple = (0.5, 1.0)):
    """A saturated random RGB colour (0..255 floats)."""
    return _hsv(rng.uniform(), rng.uniform(*s), rng.uniform(*v))


def photo_posters() -> list[np.ndarray]:
    """The real photos shipped with matplotlib (RGB uint8), those that exist."""
    from matplotlib import cbook

    out = []
    for name in _PHOTOS:
        try:
            path = cbook.get_sample_data(name, asfileobj=False)
        except (OSError, ValueError):
            continue
        bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
        if bgr is not None:
            out.append(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB))
    return out


def procedural_poster(rng: np.random.Generator, size: int = 128) -> np.ndarray:
    """A coarse, colourful poster: blocks, discs or bands on a coloured background."""
    img = np.empty((size, size, 3), np.float64)
    img[:] = random_colour(rng, v=(0.6, 1.0))
    style = rng.integers(3)
    yy, xx = np.mgrid[0:size, 0:size] / size
    for _ in range(int(rng.integers(2, 5))):
        colour = random_colour(rng)
        if style == 0:  # blocks
            x0, y0 = rng.uniform(0, 0.6, 2)
            w, h = rng.uniform(0.2, 0.5, 2)
            mask = (xx >= x0) & (xx < x0 + w) & (yy >= y0) & (yy < y0 + h)
        elif style == 1:  # discs
            cx, cy = rng.uniform(0.2, 0.8, 2)
            mask = (xx - cx) ** 2 + (yy - cy) ** 2 < rng.uniform(0.1, 0.3) ** 2
        else:  # broad horizontal bands
            y0 = rng.uniform(0, 0.8)
            mask = (yy >= y0) & (yy < y0 + rng.uniform(0.12, 0.3))
        img[mask] = colour
    img[:4], img[-4:], img[:, :4], img[:, -4:] = 40, 40, 40, 40  # a dark frame
    return np.clip(img, 0, 255).astype(np.uint8)


def carpet(
    width_m: float,
    depth_m: float,
    field: tuple[float, float, float, float] | None,
    rgb: tuple[int, int, int],
    px_per_m: int = 64,
    rng: np.random.Generator | None = None,
) -> np.ndarray:
    """Floor texture: a carpet colour with mild mottling and, optionally, a soccer
    field's white lines (outline, centre line, centre circle; 6 cm wide).

    The image covers ``[-width/2, width/2] × [-depth/2, depth/2]``; row 0 is ``+y``.
    """
    w, h = int(width_m * px_per_m), int(depth_m * px_per_m)
    img = np.empty((h, w, 3), np.float64)
    img[:] = rgb
    if rng is not None:
        noise = cv2.resize(rng.normal(0, 6, (max(h // 16, 2), max(w // 16, 2))), (w, h))
        img += noise[..., None]
    if field is not None:
        x = (np.arange(w) + 0.5) / px_per_m - width_m / 2
        y = depth_m / 2 - (np.arange(h) + 0.5) / px_per_m
        xx, yy = np.meshgrid(x, y)
        fx0, fx1, fy0, fy1 = field
        half = 0.03
        inside = (xx >= fx0 - half) & (xx <= fx1 + half) & (yy >= fy0 - half) & (yy <= fy1 + half)
        edge = (
            (np.abs(xx - fx0) < half)
            | (np.abs(xx - fx1) < half)
            | (np.abs(yy - fy0) < half)
            | (np.abs(yy - fy1) < half)
        )
        centre_line = np.abs(xx - (fx0 + fx1) / 2) < half
        r = np.hypot(xx - (fx0 + fx1) / 2, yy - (fy0 + fy1) / 2)
        circle = np.abs(r - 0.5) < half
        img[inside & (edge | centre_line | circle)] = (235, 235, 235)
    return np.clip(img, 0, 255).astype(np.uint8)


def sky_panorama(rng: np.random.Generator, width: int = 1024, height: int = 256) -> np.ndarray:
    """A 360° band of distant surroundings for outdoor scenes: sky gradient with clouds
    above, tree and building silhouettes along the bottom third (row 0 is the top)."""
    y = np.linspace(0.0, 1.0, height)[:, None]
    top, bottom = np.array([70, 120, 200]), np.array([175, 205, 235])
    img = (top * (1 - y) + bottom * y)[:, None, :].repeat(width, axis=1).astype(np.float64)
    for _ in range(int(rng.integers(5, 9))):  # soft clouds
        cx, cy = rng.uniform(0, width), rng.uniform(0.1, 0.5) * height
        rx, ry = rng.uniform(40, 120), rng.uniform(10, 25)
        yy, xx = np.mgrid[0:height, 0:width]
        dx = np.minimum(np.abs(xx - cx), width - np.abs(xx - cx))
        m = np.clip(1.2 - ((dx / rx) ** 2 + ((yy - cy) / ry) ** 2), 0, 1)
        img = img * (1 - m[..., None] * 0.8) + 250 * m[..., None] * 0.8
    ground = int(height * 0.72)
    x = 0
    while x < width:  # silhouettes standing on the horizon line
        w = int(rng.integers(20, 80))
        kind = rng.integers(3)
        hgt = int(rng.uniform(0.15, 0.45) * height)
        cols = np.arange(x, x + w) % width
        if kind == 0:  # building
            img[ground - hgt : ground, cols] = random_colour(rng, s=(0.1, 0.5), v=(0.4, 0.9))
            for wy in range(ground - hgt + 8, ground - 8, 20):  # big windows
                img[wy : wy + 8, cols[4:-4:12]] = (60, 70, 90)
        elif kind == 1:  # tree: trunk and crown
            c = x + w // 2
            img[ground - hgt // 3 : ground, np.arange(c - 3, c + 3) % width] = (90, 60, 30)
            yy, xx = np.mgrid[0:height, 0:width]
            dx = np.minimum(np.abs(xx - c), width - np.abs(xx - c))
            crown = (dx / (w / 2)) ** 2 + ((yy - (ground - hgt * 0.6)) / (hgt * 0.45)) ** 2 < 1
            img[crown] = _hsv(rng.uniform(0.22, 0.38), 0.7, rng.uniform(0.3, 0.6))
        x += w + int(rng.integers(0, 60))
    img[ground:] = (70, 130, 60)
    return np.clip(img, 0, 255).astype(np.uint8)


class TextureStore:
    """Writes images to PNG files once and loads each into a PyBullet client once.

    Parameters
    ----------
    bc : BulletClient
        The client to load textures into.
    """

    _folder: Path | None = None

    def __init__(self, bc):
        self.bc = bc
        self._ids: dict[str, int] = {}
        if TextureStore._folder is None:
            folder = Path(tempfile.mkdtemp(prefix="vc_gym_textures_"))
            atexit.register(shutil.rmtree, folder, ignore_errors=True)
            TextureStore._folder = folder
        self._counter = 0

    def load(self, key: str, make: Callable[[], np.ndarray]) -> int:
        """Texture id for ``key``, creating the image with ``make()`` the first time."""
        if key in self._ids:
            return self._ids[key]
        rgb = make()
        assert TextureStore._folder is not None
        self._counter += 1
        path = TextureStore._folder / f"{id(self)}_{self._counter}.png"
        if not cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)):
            raise OSError(f"could not write texture {path}")
        tex = self.bc.loadTexture(str(path))
        path.unlink(missing_ok=True)
        if tex < 0:
            raise RuntimeError(f"PyBullet could not load texture {key!r}")
        self._ids[key] = tex
        return tex
