"""Textures for the simulated scenes: real photos, procedural pictures and painted surfaces.

The robot's camera has 208 x 160 pixels over 56.9°, so one pixel covers about 1.7 cm
on a wall 3.5 m away. Everything painted here is therefore *coarse*: uniform regions,
bars and lines at least 4-5 cm wide, smooth noise only (fine stripes would alias).

* Real photos come from matplotlib's sample data, which vc_gym already depends on
  (:func:`sample_photo`, :func:`map_image`).
* :func:`procedural_poster` paints posters of several styles from a numpy ``Generator``.
* :class:`Canvas` paints a flat surface measured in metres (a wall, a floor, a sky band)
  with doors, windows, framed pictures, boards...; the scene builder bakes whole walls
  into one texture, which renders much faster than one body per picture.
* :class:`TextureStore` writes images as PNG files into a private temporary folder, loads
  each once into a PyBullet client (``loadTexture`` memory is freed only by
  ``resetSimulation``/``disconnect``), deletes each file right after loading and the
  folder when it is closed.

All images are ``(H, W, 3)`` ``uint8`` RGB arrays; row 0 is the top of the picture. All
randomness comes from the ``numpy.random.Generator`` passed in.
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import math
import os
import shutil
import tempfile
from collections.abc import Callable, Sequence

import cv2
import numpy as np

# the colour and noise helpers are shared with vc_gym.worlds; re-exported here
from vc_gym.worlds.paint import hsv, random_colour, smooth_noise

__all__ = [
    "Canvas",
    "MAP_IMAGES",
    "POSTER_STYLES",
    "SAMPLE_PHOTOS",
    "TextureStore",
    "ad_board",
    "desktop_screen",
    "facade",
    "hsv",
    "map_image",
    "outdoor_view",
    "photo_posters",
    "poster_image",
    "procedural_poster",
    "random_colour",
    "sample_photo",
    "sky_band",
    "sky_cap",
    "smooth_noise",
    "TEXTURE_DIR_PREFIX",
]

#: Real photos in matplotlib's sample data used as posters (those that exist are used).
SAMPLE_PHOTOS = ("grace_hopper.jpg", "Minduka_Present_Blue_Pack.png", "logo2.png")
#: Elevation models in matplotlib's sample data, drawn as colour maps ("map" posters).
MAP_IMAGES = ("topobathy.npz", "jacksboro_fault_dem.npz")
#: Styles understood by :func:`procedural_poster`.
POSTER_STYLES = ("blocks", "discs", "bands", "landscape", "chart", "text")

_WORDS = ("ROBOCUP", "AIBO", "ISLA", "UvA", "2006", "GOAL", "KICK", "TEAM", "LAB", "VISION")
_FONT = cv2.FONT_HERSHEY_DUPLEX


# ----------------------------------------------------------------------------- colours


def _u8(img: np.ndarray) -> np.ndarray:
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


# ------------------------------------------------------------------------ real images


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
    return _u8(rgba[:, :, :3] * alpha + bg * (1.0 - alpha))


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
    return cv2.resize(_u8(rgb), (width, height), interpolation=cv2.INTER_AREA)


# ------------------------------------------------------------------- procedural images


def _text(
    img: np.ndarray,
    text: str,
    rgb: Sequence[float],
    box: tuple[int, int, int, int],
    bold: float = 0.16,
) -> None:
    """Write ``text`` as big as fits into ``box = (x0, y0, x1, y1)`` (pixels), centred."""
    x0, y0, x1, y1 = box
    bw, bh = max(x1 - x0, 4), max(y1 - y0, 4)
    (tw, th), _ = cv2.getTextSize(text, _FONT, 1.0, 1)
    scale = 0.9 * min(bw / tw, bh / th)
    thick = max(1, int(round(bold * th * scale)))
    (tw, th), _ = cv2.getTextSize(text, _FONT, scale, thick)
    org = (int(x0 + (bw - tw) / 2), int(y0 + (bh + th) / 2))
    mask = np.zeros(img.shape[:2], np.uint8)  # putText draws only on 8-bit images
    cv2.putText(mask, text, org, _FONT, scale, 255, thick, cv2.LINE_AA)
    a = (mask.astype(np.float32) / 255.0)[..., None]
    img *= 1.0 - a
    img += a * np.asarray(rgb, np.float32)


def procedural_poster(
    rng: np.random.Generator, size: int | tuple[int, int] = 128, style: str | None = None
) -> np.ndarray:
    """A coarse, colourful poster painted from ``rng``.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of every random choice.
    size : int or (int, int)
        Side of a square poster, or ``(height, width)`` in pixels (each ``>= 16``).
    style : str, optional
        One of :data:`POSTER_STYLES` (drawn from ``rng`` if ``None``): ``"blocks"``
        (Mondrian-like panels with thick black bars), ``"discs"`` (big discs and
        rings), ``"bands"`` (broad straight or diagonal bands), ``"landscape"`` (sky,
        sun, hills), ``"chart"`` (a scientific poster: title bar, bar chart, text
        blocks) or ``"text"`` (a big word on a coloured ground).

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB image.
    """
    h, w = (size, size) if isinstance(size, int | np.integer) else (int(size[0]), int(size[1]))
    if h < 16 or w < 16:
        raise ValueError(f"poster size must be at least 16 x 16 pixels, got {h} x {w}")
    if style is None:
        style = str(rng.choice(POSTER_STYLES))
    if style not in POSTER_STYLES:
        raise ValueError(f"style must be one of {POSTER_STYLES}, got {style!r}")
    img = np.empty((h, w, 3), np.float32)
    img[:] = random_colour(rng, s=(0.2, 0.9), v=(0.55, 1.0))
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    xx /= w
    yy /= h
    m = min(h, w)
    if style == "blocks":
        img[:] = (240, 238, 228)
        bar = max(2, int(0.035 * m))
        panels = [(0, 0, w, h)]
        for _ in range(int(rng.integers(3, 6))):
            i = int(np.argmax([(p[2] - p[0]) * (p[3] - p[1]) for p in panels]))
            x0, y0, x1, y1 = panels.pop(i)
            if (x1 - x0) >= (y1 - y0):
                c = int(x0 + rng.uniform(0.3, 0.7) * (x1 - x0))
                panels += [(x0, y0, c, y1), (c, y0, x1, y1)]
            else:
                c = int(y0 + rng.uniform(0.3, 0.7) * (y1 - y0))
                panels += [(x0, y0, x1, c), (x0, c, x1, y1)]
        primaries = [(220, 30, 35), (30, 60, 170), (250, 205, 30), (20, 20, 20), (240, 238, 228)]
        for x0, y0, x1, y1 in panels:
            if rng.uniform() < 0.6:
                img[y0:y1, x0:x1] = primaries[int(rng.integers(len(primaries)))]
            img[y0 : y0 + bar, x0:x1] = 15
            img[y1 - bar : y1, x0:x1] = 15
            img[y0:y1, x0 : x0 + bar] = 15
            img[y0:y1, x1 - bar : x1] = 15
    elif style == "discs":
        for _ in range(int(rng.integers(2, 6))):
            cx, cy, r = rng.uniform(0.15, 0.85), rng.uniform(0.15, 0.85), rng.uniform(0.12, 0.35)
            d = np.hypot((xx - cx) * w / m, (yy - cy) * h / m)
            colour = random_colour(rng)
            if rng.uniform() < 0.35:
                img[(d < r) & (d > r * rng.uniform(0.45, 0.7))] = colour
            else:
                img[d < r] = colour
    elif style == "bands":
        angle = rng.choice([0.0, 0.0, 90.0, 45.0, -45.0])
        a = math.radians(float(angle))
        t = xx * math.sin(a) * w / m + yy * math.cos(a) * h / m
        edges = np.sort(rng.uniform(t.min(), t.max(), int(rng.integers(2, 5))))
        for lo, hi in itertools.pairwise([t.min() - 1, *edges, t.max() + 1]):
            if hi - lo > 0.06:
                img[(t >= lo) & (t < hi)] = random_colour(rng, s=(0.4, 1.0))
    elif style == "landscape":
        hue = rng.uniform(0.0, 1.0)
        top = hsv(hue, rng.uniform(0.4, 0.8), rng.uniform(0.5, 0.9))
        bottom = hsv(hue + rng.uniform(-0.15, 0.15), rng.uniform(0.2, 0.6), 0.95)
        img[:] = top * (1.0 - yy[..., None]) + bottom * yy[..., None]
        cx, cy, r = rng.uniform(0.2, 0.8), rng.uniform(0.15, 0.45), rng.uniform(0.06, 0.14)
        img[np.hypot((xx - cx) * w / m, (yy - cy) * h / m) < r] = hsv(
            rng.uniform(0.0, 0.15), 0.8, 1.0
        )
        base = rng.uniform(0.45, 0.6)
        for k in range(int(rng.integers(2, 4))):
            phase, freq = rng.uniform(0, 2 * math.pi, 2), rng.uniform(1.5, 4.0, 2)
            ridge = (
                base
                + 0.12 * k
                + 0.06
                * (
                    np.sin(freq[0] * math.pi * xx[0] + phase[0])
                    + 0.5 * np.sin(freq[1] * math.pi * xx[0] + phase[1])
                )
            )
            colour = hsv(rng.uniform(0.2, 0.45), rng.uniform(0.4, 0.8), 0.75 - 0.18 * k)
            img[yy > ridge[None, :]] = colour
    elif style == "chart":
        img[:] = (245, 245, 240)
        accent = random_colour(rng, s=(0.6, 1.0), v=(0.4, 0.8))
        head = int(0.2 * h)
        img[:head] = accent
        _text(
            img, str(rng.choice(_WORDS)), (255, 255, 255), (int(0.05 * w), 0, int(0.95 * w), head)
        )
        # a bar chart in the left half, grey text blocks on the right
        n = int(rng.integers(3, 6))
        x0, x1, y0, y1 = int(0.08 * w), int(0.55 * w), int(0.3 * h), int(0.9 * h)
        bw = (x1 - x0) / n
        for i in range(n):
            top = int(y1 - rng.uniform(0.2, 1.0) * (y1 - y0))
            img[top:y1, int(x0 + i * bw + 0.15 * bw) : int(x0 + (i + 0.85) * bw)] = random_colour(
                rng
            )
        img[y1 : y1 + max(2, h // 60), x0:x1] = 40
        row = max(3, int(0.05 * h))
        for y in range(int(0.3 * h), int(0.9 * h) - row, 2 * row):
            img[y : y + row, int(0.62 * w) : int(rng.uniform(0.75, 0.93) * w)] = 150
    else:  # text
        img[:] = random_colour(rng, s=(0.5, 1.0), v=(0.3, 0.9))
        fg = (255, 255, 255) if rng.uniform() < 0.6 else (250, 220, 40)
        word = str(rng.choice(_WORDS))
        if h > 1.3 * w and len(word) > 2:  # portrait: a big word and a second one
            _text(img, word, fg, (int(0.05 * w), int(0.1 * h), int(0.95 * w), int(0.45 * h)))
            _text(img, str(rng.choice(_WORDS)), fg, (0, int(0.55 * h), w, int(0.9 * h)))
        else:
            _text(img, word, fg, (int(0.05 * w), int(0.1 * h), int(0.95 * w), int(0.9 * h)))
        img[int(0.92 * h) :] = random_colour(rng)
    return _u8(img)


def poster_image(rng: np.random.Generator, aspect: float, px: int = 160) -> np.ndarray:
    """A poster: a real photo, a map or a procedural poster.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of every choice.
    aspect : float
        Wanted width / height of a procedural poster (> 0). A quarter of the posters
        are real photos from matplotlib's sample data and a tenth are maps; those keep
        their own aspect.
    px : int
        Pixel size of the longer side of procedural posters.

    Returns
    -------
    numpy.ndarray
        ``(H, W, 3)`` ``uint8`` RGB; photos are shared, read-only arrays.
    """
    kind = rng.uniform()
    if kind < 0.25:
        photos = photo_posters()
        if photos:
            return photos[int(rng.integers(len(photos)))]
    elif kind < 0.35:
        cmap = str(rng.choice(["terrain", "gist_earth", "viridis", "plasma", "cividis"]))
        img = map_image(MAP_IMAGES[int(rng.integers(len(MAP_IMAGES)))], cmap)
        if img is not None:
            return img
    if aspect >= 1.0:
        size = (max(16, int(px / aspect)), px)
    else:
        size = (px, max(16, int(px * aspect)))
    return procedural_poster(rng, size)


def outdoor_view(rng: np.random.Generator, height: int = 96, width: int = 128) -> np.ndarray:
    """What a window shows: sky with soft clouds, far trees, maybe a building, a lawn.

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB.
    """
    img = np.empty((height, width, 3), np.float32)
    y = np.linspace(0.0, 1.0, height, dtype=np.float32)[:, None, None]
    hue = rng.uniform(0.55, 0.62)
    img[:] = hsv(hue, rng.uniform(0.4, 0.6), 0.85) * (1 - y) + hsv(hue, 0.15, 0.97) * y
    cloud = np.clip(smooth_noise(rng, height, width, 4) - 0.3, 0.0, 1.0)[..., None]
    img = img * (1 - 0.8 * cloud) + 250 * 0.8 * cloud
    horizon = int(rng.uniform(0.55, 0.75) * height)
    tops = horizon - (0.12 + 0.2 * np.abs(smooth_noise(rng, 1, width, 5)[0])) * height
    trees = hsv(rng.uniform(0.22, 0.36), 0.6, rng.uniform(0.3, 0.5))
    img[(np.arange(height)[:, None] > tops[None, :]) & (np.arange(height)[:, None] < horizon)] = (
        trees
    )
    if rng.uniform() < 0.5:  # a building
        bx0 = int(rng.uniform(0.1, 0.6) * width)
        bx1 = bx0 + int(rng.uniform(0.2, 0.4) * width)
        by = int(horizon - rng.uniform(0.3, 0.5) * height)
        img[by:horizon, bx0:bx1] = random_colour(rng, s=(0.1, 0.4), v=(0.5, 0.9))
    img[horizon:] = hsv(rng.uniform(0.22, 0.3), 0.55, 0.6)
    return _u8(img)


def desktop_screen(rng: np.random.Generator, height: int = 60, width: int = 96) -> np.ndarray:
    """A computer screen: a desktop colour with one to three big application windows.

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB.
    """
    img = np.empty((height, width, 3), np.float32)
    img[:] = random_colour(rng, s=(0.4, 0.9), v=(0.35, 0.8))
    for _ in range(int(rng.integers(1, 4))):
        x0, y0 = int(rng.uniform(0.0, 0.5) * width), int(rng.uniform(0.0, 0.4) * height)
        x1 = x0 + int(rng.uniform(0.35, 0.6) * width)
        y1 = y0 + int(rng.uniform(0.4, 0.6) * height)
        img[y0:y1, x0:x1] = random_colour(rng, s=(0.0, 0.3), v=(0.8, 1.0))
        img[y0 : y0 + max(3, height // 10), x0:x1] = random_colour(rng, s=(0.5, 1.0), v=(0.4, 0.8))
    return _u8(img)


def ad_board(rng: np.random.Generator, height: int = 32, width: int = 128) -> np.ndarray:
    """A pitch-side advertising board: a bright colour with a big word.

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB.
    """
    img = np.empty((height, width, 3), np.float32)
    img[:] = random_colour(rng, s=(0.6, 1.0), v=(0.5, 1.0))
    fg = (255, 255, 255) if rng.uniform() < 0.5 else random_colour(rng, v=(0.9, 1.0))
    word = str(rng.choice(("VC GYM", "ROBO", "KICK", "SPORT", "CLUB", "CAFE", "GOAL", "PLAY")))
    _text(img, word, fg, (int(0.06 * width), 2, int(0.94 * width), height - 2))
    return _u8(img)


def facade(
    rng: np.random.Generator, width_m: float, height_m: float, px_per_m: float = 8.0
) -> np.ndarray:
    """The front of a building: wall colour, a grid of big windows, a door, a cornice.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of colours and window layout.
    width_m, height_m : float
        Size of the facade (m).
    px_per_m : float
        Resolution.

    Returns
    -------
    numpy.ndarray
        ``uint8`` RGB image of the facade (row 0 is its top).
    """
    c = Canvas(width_m, height_m, px_per_m, random_colour(rng, s=(0.05, 0.5), v=(0.45, 0.9)))
    glass = hsv(rng.uniform(0.52, 0.65), rng.uniform(0.2, 0.5), rng.uniform(0.2, 0.45))
    floor_h = rng.uniform(2.8, 3.4)
    win_w, pitch = rng.uniform(1.0, 1.8), rng.uniform(2.4, 3.4)
    n = int((width_m - 1.0) // pitch)
    x_start = (width_m - (n - 1) * pitch) / 2.0
    z = 1.0
    while z + floor_h * 0.6 < height_m - 0.3:
        for i in range(n):
            x = x_start + i * pitch
            c.rect(x - win_w / 2, x + win_w / 2, z, z + floor_h * 0.55, glass)
        z += floor_h
    c.rect(width_m / 2 - 0.7, width_m / 2 + 0.7, 0.0, 2.3, hsv(0.08, 0.5, 0.3))
    c.rect(0.0, width_m, height_m - 0.5, height_m, random_colour(rng, s=(0.2, 0.6), v=(0.3, 0.6)))
    return c.image()


def sky_band(
    rng: np.random.Generator,
    width: int = 1536,
    height: int = 384,
    horizon: float = 0.14,
) -> np.ndarray:
    """A seamless 360° band of sky for the inside of a sky cylinder (row 0 = top).

    The lowest ``horizon`` fraction holds the far surroundings (a blue-green ridge of
    hills and woods with some far buildings); above it the sky goes from a pale horizon
    to a deeper blue with soft, coarse clouds. Column 0 and ``width - 1`` join.

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB.
    """
    img = np.empty((height, width, 3), np.float32)
    t = np.linspace(1.0, 0.0, height, dtype=np.float32)[:, None, None]  # 0 bottom, 1 top
    hue = rng.uniform(0.56, 0.62)
    low = hsv(hue, rng.uniform(0.1, 0.25), rng.uniform(0.88, 0.97))
    high = hsv(hue, rng.uniform(0.5, 0.7), rng.uniform(0.7, 0.85))
    img[:] = low * (1 - t**0.7) + high * t**0.7
    # periodic clouds: noise on a band three times wider, folded back to one period
    n = smooth_noise(rng, height, width + 64, 14)
    ramp = np.linspace(0.0, 1.0, 64, dtype=np.float32)[None, :]
    n[:, :64] = n[:, :64] * ramp + n[:, -64:] * (1.0 - ramp)
    n = n[:, :width]
    cover = np.clip((n - rng.uniform(0.2, 0.7)) / 0.6, 0.0, 1.0)
    cover *= np.clip((t[:, :, 0] - horizon - 0.03) / 0.1, 0.0, 1.0)  # none on the hills
    img = img * (1 - 0.85 * cover[..., None]) + 248.0 * 0.85 * cover[..., None]
    # far ridge of hills and woods along the bottom (periodic sums of sines)
    x = np.linspace(0.0, 2 * math.pi, width, endpoint=False)
    ridge = np.full(width, horizon * 0.55)
    for k in range(1, 7):
        ridge += rng.uniform(0.0, 0.03) / k * np.sin(k * x + rng.uniform(0, 2 * math.pi))
    rows = np.arange(height)[:, None]
    ridge_row = (1.0 - ridge[None, :]) * height
    woods = hsv(rng.uniform(0.25, 0.4), rng.uniform(0.3, 0.6), rng.uniform(0.35, 0.5))
    hills = 0.6 * woods + 0.4 * low
    img[rows >= ridge_row] = hills
    near = ridge_row + 0.25 * horizon * height * (0.6 + 0.4 * np.sin(3 * x + rng.uniform(0, 6)))
    img[rows >= near] = woods
    for _ in range(int(rng.integers(2, 6))):  # far buildings on the ridge
        bw = int(rng.uniform(0.01, 0.03) * width)
        bx = int(rng.integers(0, width - bw))
        top = int((1.0 - horizon * rng.uniform(0.8, 1.6)) * height)
        img[top:, bx : bx + bw] = random_colour(rng, s=(0.0, 0.3), v=(0.55, 0.85))
    return _u8(img)


def sky_cap(rng: np.random.Generator, colour: Sequence[float], size: int = 128) -> np.ndarray:
    """The lid of a sky cylinder: ``colour`` (RGB 0..255) with soft clouds.

    Returns
    -------
    numpy.ndarray
        ``(size, size, 3)`` ``uint8`` RGB.
    """
    img = np.empty((size, size, 3), np.float32)
    img[:] = np.asarray(colour, np.float32)
    cover = np.clip(smooth_noise(rng, size, size, 5) - 0.6, 0.0, 1.0)[..., None]
    return _u8(img * (1 - 0.7 * cover) + 248.0 * 0.7 * cover)


# ----------------------------------------------------------------------------- Canvas


class Canvas:
    """A flat surface measured in metres, painted as an RGB image.

    ``x`` runs to the right (0 .. ``width_m``), ``y`` up (0 .. ``height_m``); the image's
    row 0 is the top edge ``y = height_m``, so its bottom row is texture ``v = 0``.

    Parameters
    ----------
    width_m, height_m : float
        Size of the surface (> 0).
    px_per_m : float
        Resolution (the image is at least 2 x 2 pixels).
    rgb : sequence of float
        Background colour (0..255).
    """

    def __init__(
        self, width_m: float, height_m: float, px_per_m: float, rgb: Sequence[float]
    ) -> None:
        if not (width_m > 0 and height_m > 0 and px_per_m > 0):
            raise ValueError(
                f"canvas size and resolution must be > 0, got {width_m}, {height_m}, {px_per_m}"
            )
        self.width_m, self.height_m = float(width_m), float(height_m)
        w = max(2, int(round(width_m * px_per_m)))
        h = max(2, int(round(height_m * px_per_m)))
        self.sx, self.sy = w / self.width_m, h / self.height_m
        self.img = np.empty((h, w, 3), np.float32)
        self.img[:] = np.asarray(rgb, np.float32)

    def _box(self, x0: float, x1: float, y0: float, y1: float) -> tuple[slice, slice]:
        h, w = self.img.shape[:2]
        c0 = min(max(int(round(x0 * self.sx)), 0), w)
        c1 = min(max(int(round(x1 * self.sx)), 0), w)
        r0 = min(max(int(round((self.height_m - y1) * self.sy)), 0), h)
        r1 = min(max(int(round((self.height_m - y0) * self.sy)), 0), h)
        return slice(r0, r1), slice(c0, c1)

    def rect(self, x0: float, x1: float, y0: float, y1: float, rgb: Sequence[float]) -> None:
        """Fill the rectangle ``[x0, x1] x [y0, y1]``."""
        rows, cols = self._box(x0, x1, y0, y1)
        self.img[rows, cols] = np.asarray(rgb, np.float32)

    def shade(self, x0: float, x1: float, y0: float, y1: float, factor: float) -> None:
        """Multiply the rectangle's colours by ``factor``."""
        rows, cols = self._box(x0, x1, y0, y1)
        self.img[rows, cols] *= np.float32(factor)

    def outline(
        self, x0: float, x1: float, y0: float, y1: float, width: float, rgb: Sequence[float]
    ) -> None:
        """A frame of bars ``width`` wide just inside the rectangle."""
        self.rect(x0, x1, y0, y0 + width, rgb)
        self.rect(x0, x1, y1 - width, y1, rgb)
        self.rect(x0, x0 + width, y0, y1, rgb)
        self.rect(x1 - width, x1, y0, y1, rgb)

    def paste(self, x0: float, x1: float, y0: float, y1: float, image: np.ndarray) -> None:
        """Resample ``image`` (RGB) onto the rectangle (area interpolation)."""
        rows, cols = self._box(x0, x1, y0, y1)
        h, w = rows.stop - rows.start, cols.stop - cols.start
        if h <= 0 or w <= 0:
            return
        inter = cv2.INTER_AREA if image.shape[0] >= h else cv2.INTER_LINEAR
        self.img[rows, cols] = cv2.resize(image, (w, h), interpolation=inter).astype(np.float32)

    def disc(
        self, cx: float, cy: float, r: float, rgb: Sequence[float], inner: float = 0.0
    ) -> None:
        """A filled disc of radius ``r`` (a ring if ``inner > 0``)."""
        rows, cols = self._box(cx - r, cx + r, cy - r, cy + r)
        if rows.stop <= rows.start or cols.stop <= cols.start:
            return
        ys = self.height_m - (np.arange(rows.start, rows.stop) + 0.5) / self.sy
        xs = (np.arange(cols.start, cols.stop) + 0.5) / self.sx
        d = np.hypot(xs[None, :] - cx, ys[:, None] - cy)
        block = self.img[rows, cols]
        block[(d <= r) & (d >= inner)] = np.asarray(rgb, np.float32)

    def mottle(self, rng: np.random.Generator, amount: float, blob_m: float = 0.5) -> None:
        """Multiply by ``1 + amount * noise`` with blobs about ``blob_m`` across."""
        h, w = self.img.shape[:2]
        cells = max(1.0, self.width_m / blob_m)
        self.img *= (1.0 + np.float32(amount) * smooth_noise(rng, h, w, cells))[..., None]

    def image(self) -> np.ndarray:
        """The painted image as ``uint8`` RGB."""
        return _u8(self.img)

    # ------------------------------------------------------------- things on walls
    def framed(
        self,
        x0: float,
        x1: float,
        y0: float,
        y1: float,
        image: np.ndarray,
        frame_rgb: Sequence[float] = (30, 30, 30),
        frame_m: float = 0.04,
    ) -> None:
        """A picture with a frame ``frame_m`` wide around it (outer size given)."""
        self.rect(x0, x1, y0, y1, frame_rgb)
        self.paste(x0 + frame_m, x1 - frame_m, y0 + frame_m, y1 - frame_m, image)

    def door(
        self, x0: float, x1: float, top: float, leaf: Sequence[float], casing: Sequence[float]
    ) -> None:
        """A door from the floor to ``top``: casing, leaf, a handle and a kick plate."""
        self.rect(x0 - 0.07, x1 + 0.07, 0.0, top + 0.07, casing)
        self.rect(x0, x1, 0.0, top, leaf)
        self.shade(x0 + 0.1, x1 - 0.1, top * 0.55, top - 0.12, 0.9)  # upper panel
        self.shade(x0 + 0.1, x1 - 0.1, 0.15, top * 0.45, 0.9)  # lower panel
        self.rect(x1 - 0.16, x1 - 0.06, 0.98, 1.04, (200, 200, 205))  # handle

    def window(
        self,
        x0: float,
        x1: float,
        y0: float,
        y1: float,
        view: np.ndarray,
        frame: Sequence[float] = (240, 240, 240),
        mullions: int = 1,
    ) -> None:
        """A window: frame, sill, glass showing ``view`` and ``mullions`` vertical bars."""
        self.rect(x0 - 0.05, x1 + 0.05, y0 - 0.06, y0, (225, 225, 220))  # sill
        self.rect(x0, x1, y0, y1, frame)
        f = 0.06
        self.paste(x0 + f, x1 - f, y0 + f, y1 - f, view)
        for i in range(1, mullions + 1):
            x = x0 + (x1 - x0) * i / (mullions + 1)
            self.rect(x - 0.03, x + 0.03, y0, y1, frame)
        self.rect(x0, x1, y0 + 0.62 * (y1 - y0) - 0.03, y0 + 0.62 * (y1 - y0) + 0.03, frame)

    def blinds(self, x0: float, x1: float, y0: float, y1: float, rgb: Sequence[float]) -> None:
        """Venetian blinds half down: coarse slats 10 cm apart over the top part."""
        bottom = y0 + 0.45 * (y1 - y0)
        y = y1
        dark = np.asarray(rgb, np.float32) * np.float32(0.8)
        while y - 0.1 >= bottom:
            self.rect(x0, x1, y - 0.07, y, rgb)
            self.rect(x0, x1, y - 0.1, y - 0.07, dark)
            y -= 0.1
        self.rect(x0, x1, bottom - 0.04, bottom, dark)

    def curtains(
        self, x0: float, x1: float, y0: float, y1: float, rgb: Sequence[float], width: float
    ) -> None:
        """Two curtains ``width`` wide on either side of ``[x0, x1]`` with broad folds."""
        base = np.asarray(rgb, np.float32)
        self.rect(x0 - width - 0.1, x1 + width + 0.1, y1 - 0.05, y1, (90, 70, 50))  # rod
        for cx0 in (x0 - width, x1 - 0.15):
            n = 3
            fw = (width + 0.15) / n
            for i in range(n):
                f = 1.0 if i % 2 == 0 else 0.82
                self.rect(cx0 + i * fw, cx0 + (i + 1) * fw, y0, y1 - 0.05, base * np.float32(f))

    def radiator(self, x0: float, x1: float, y0: float, y1: float) -> None:
        """A white radiator with three coarse horizontal ribs."""
        self.rect(x0, x1, y0, y1, (232, 232, 228))
        for k in range(3):
            y = y0 + (k + 0.5) * (y1 - y0) / 3
            self.rect(x0, x1, y - 0.025, y + 0.025, (190, 190, 188))

    def clock(self, cx: float, cy: float, r: float, rim: Sequence[float]) -> None:
        """A wall clock: rim, white face, two thick hands."""
        self.disc(cx, cy, r, rim)
        self.disc(cx, cy, r - 0.035, (245, 245, 240))
        self.rect(cx - 0.015, cx + 0.015, cy, cy + 0.7 * r, (20, 20, 20))
        self.rect(cx, cx + 0.55 * r, cy - 0.015, cy + 0.015, (20, 20, 20))

    def board(
        self,
        rng: np.random.Generator,
        x0: float,
        x1: float,
        y0: float,
        y1: float,
        kind: str = "white",
    ) -> None:
        """A whiteboard with coarse coloured drawings, or a cork board with notes."""
        if kind == "white":
            self.rect(x0, x1, y0, y1, (170, 172, 178))
            self.rect(x0 + 0.04, x1 - 0.04, y0 + 0.04, y1 - 0.04, (246, 246, 246))
            self.rect(x0 + 0.1, x1 - 0.1, y0 - 0.05, y0, (150, 150, 155))  # pen tray
            for _ in range(int(rng.integers(3, 6))):
                colour = rng.choice([(200, 30, 30), (30, 60, 180), (20, 120, 40), (30, 30, 30)])
                bx = rng.uniform(x0 + 0.15, x1 - 0.5)
                by = rng.uniform(y0 + 0.15, y1 - 0.35)
                bw, bh = rng.uniform(0.25, 0.6), rng.uniform(0.15, 0.3)
                if rng.uniform() < 0.5:
                    self.outline(bx, bx + bw, by, by + bh, 0.03, colour)
                else:
                    for k in range(int(rng.integers(1, 4))):  # "text" lines
                        yy = by + bh - k * 0.09
                        self.rect(bx, bx + bw * rng.uniform(0.5, 1.0), yy - 0.03, yy, colour)
        else:
            self.rect(x0, x1, y0, y1, (120, 85, 50))
            self.rect(x0 + 0.04, x1 - 0.04, y0 + 0.04, y1 - 0.04, (190, 145, 95))
            for _ in range(int(rng.integers(4, 9))):
                w, h = rng.uniform(0.12, 0.3), rng.uniform(0.1, 0.3)
                bx, by = (
                    rng.uniform(x0 + 0.06, x1 - 0.06 - w),
                    rng.uniform(y0 + 0.06, y1 - 0.06 - h),
                )
                colour = random_colour(rng, s=(0.0, 0.6), v=(0.8, 1.0))
                self.rect(bx, bx + w, by, by + h, colour)


# ----------------------------------------------------------------------- TextureStore

#: Prefix of the temporary folders texture files are written to.
TEXTURE_DIR_PREFIX = "vc_gym_textures_"


class TextureStore:
    """Loads images into one PyBullet client, each distinct image once.

    Create one store per scene build (after ``resetSimulation`` the ids are gone) and
    :meth:`close` it when the build is done (or use it as a context manager). Each image
    is written as a PNG into the store's own temporary folder, loaded with
    ``loadTexture`` and deleted at once; :meth:`close` removes the folder, so nothing is
    left behind however many scenes are built, even in worker processes that exit
    without running ``atexit`` handlers.

    Parameters
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client to load textures into.
    """

    def __init__(self, bc) -> None:
        self.bc = bc
        self._ids: dict[str, int] = {}
        self._dir: str | None = None
        self._count = 0

    def __enter__(self) -> TextureStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Remove the temporary folder (texture ids stay valid in the client)."""
        if self._dir is not None:
            shutil.rmtree(self._dir, ignore_errors=True)
            self._dir = None

    def __len__(self) -> int:
        return len(set(self._ids.values()))

    def load(self, key: str, make: Callable[[], np.ndarray]) -> int:
        """Texture id for ``key``, creating the image with ``make()`` the first time.

        Parameters
        ----------
        key : str
            Name of the texture within this store.
        make : callable
            Returns the ``(H, W, 3)`` ``uint8`` RGB image; called at most once per key.

        Returns
        -------
        int
            PyBullet texture id (for ``changeVisualShape(textureUniqueId=...)``).
        """
        if key not in self._ids:
            self._ids[key] = self.load_image(make())
        return self._ids[key]

    def load_image(self, image: np.ndarray) -> int:
        """Texture id of an image; the same pixels are loaded only once per store.

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W, 3)`` ``uint8`` RGB; row 0 is the top (texture ``v = 1``).

        Returns
        -------
        int
            PyBullet texture id.

        Raises
        ------
        ValueError
            If ``image`` is not an ``(H, W, 3)`` ``uint8`` array.
        RuntimeError
            If PyBullet cannot load the written file.
        """
        img = np.ascontiguousarray(image)
        if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] != 3:
            raise ValueError(
                f"texture must be an (H, W, 3) uint8 RGB image, got {img.shape} {img.dtype}"
            )
        digest = hashlib.sha1(img.tobytes(), usedforsecurity=False)
        digest.update(repr(img.shape).encode())
        key = "#" + digest.hexdigest()
        if key in self._ids:
            return self._ids[key]
        if self._dir is None:
            self._dir = tempfile.mkdtemp(prefix=TEXTURE_DIR_PREFIX)
        self._count += 1
        path = os.path.join(self._dir, f"{self._count}.png")
        try:
            bgr = cv2.cvtColor(img, cv2.COLOR_RGB2BGR)
            if not cv2.imwrite(path, bgr, [cv2.IMWRITE_PNG_COMPRESSION, 0]):
                raise OSError(f"could not write texture file {path}")
            tex = int(self.bc.loadTexture(path))
        finally:
            try:
                os.remove(path)
            except OSError:
                pass
        if tex < 0:
            raise RuntimeError(f"PyBullet could not load the texture written to {path}")
        self._ids[key] = tex
        return tex
