"""Procedural pictures for the scenes: posters, window views, screens, boards, facades, sky.

The robot's camera has 208 x 160 pixels over 56.9°, so one pixel covers about 1.7 cm
on a wall 3.5 m away. Everything painted here is therefore *coarse*: uniform regions,
bars and lines at least 4-5 cm wide, smooth noise only (fine stripes would alias).

Every painter returns an ``(H, W, 3)`` ``uint8`` RGB array (row 0 is the top of the
picture) and takes all its randomness from the ``numpy.random.Generator`` passed in.
:func:`poster_image` mixes in the real photos and maps of
:mod:`vc_gym.sim.textures.photos`; :func:`facade` paints on a
:class:`~vc_gym.worlds.canvas.Canvas`.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import cv2
import numpy as np

from vc_gym.sim.textures.photos import MAP_IMAGES, map_image, photo_posters
from vc_gym.worlds.canvas import Canvas
from vc_gym.worlds.paint import hsv, random_color, smooth_noise, to_uint8

__all__ = [
    "POSTER_STYLES",
    "ad_board",
    "desktop_screen",
    "facade",
    "outdoor_view",
    "poster_image",
    "procedural_poster",
    "sky_band",
    "sky_cap",
]

#: Styles understood by :func:`procedural_poster`.
POSTER_STYLES = ("blocks", "discs", "bands", "landscape", "chart", "text")

_WORDS = ("ROBOCUP", "AIBO", "ISLA", "UvA", "2006", "GOAL", "KICK", "TEAM", "LAB", "VISION")
_FONT = cv2.FONT_HERSHEY_DUPLEX


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
    img[:] = random_color(rng, s=(0.2, 0.9), v=(0.55, 1.0))
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
            color = random_color(rng)
            if rng.uniform() < 0.35:
                img[(d < r) & (d > r * rng.uniform(0.45, 0.7))] = color
            else:
                img[d < r] = color
    elif style == "bands":
        angle = rng.choice([0.0, 0.0, 90.0, 45.0, -45.0])
        a = math.radians(float(angle))
        t = xx * math.sin(a) * w / m + yy * math.cos(a) * h / m
        edges = np.sort(rng.uniform(t.min(), t.max(), int(rng.integers(2, 5))))
        for lo, hi in itertools.pairwise([t.min() - 1, *edges, t.max() + 1]):
            if hi - lo > 0.06:
                img[(t >= lo) & (t < hi)] = random_color(rng, s=(0.4, 1.0))
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
            color = hsv(rng.uniform(0.2, 0.45), rng.uniform(0.4, 0.8), 0.75 - 0.18 * k)
            img[yy > ridge[None, :]] = color
    elif style == "chart":
        img[:] = (245, 245, 240)
        accent = random_color(rng, s=(0.6, 1.0), v=(0.4, 0.8))
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
            img[top:y1, int(x0 + i * bw + 0.15 * bw) : int(x0 + (i + 0.85) * bw)] = random_color(
                rng
            )
        img[y1 : y1 + max(2, h // 60), x0:x1] = 40
        row = max(3, int(0.05 * h))
        for y in range(int(0.3 * h), int(0.9 * h) - row, 2 * row):
            img[y : y + row, int(0.62 * w) : int(rng.uniform(0.75, 0.93) * w)] = 150
    else:  # text
        img[:] = random_color(rng, s=(0.5, 1.0), v=(0.3, 0.9))
        fg = (255, 255, 255) if rng.uniform() < 0.6 else (250, 220, 40)
        word = str(rng.choice(_WORDS))
        if h > 1.3 * w and len(word) > 2:  # portrait: a big word and a second one
            _text(img, word, fg, (int(0.05 * w), int(0.1 * h), int(0.95 * w), int(0.45 * h)))
            _text(img, str(rng.choice(_WORDS)), fg, (0, int(0.55 * h), w, int(0.9 * h)))
        else:
            _text(img, word, fg, (int(0.05 * w), int(0.1 * h), int(0.95 * w), int(0.9 * h)))
        img[int(0.92 * h) :] = random_color(rng)
    return to_uint8(img)


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
        img[by:horizon, bx0:bx1] = random_color(rng, s=(0.1, 0.4), v=(0.5, 0.9))
    img[horizon:] = hsv(rng.uniform(0.22, 0.3), 0.55, 0.6)
    return to_uint8(img)


def desktop_screen(rng: np.random.Generator, height: int = 60, width: int = 96) -> np.ndarray:
    """A computer screen: a desktop colour with one to three big application windows.

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB.
    """
    img = np.empty((height, width, 3), np.float32)
    img[:] = random_color(rng, s=(0.4, 0.9), v=(0.35, 0.8))
    for _ in range(int(rng.integers(1, 4))):
        x0, y0 = int(rng.uniform(0.0, 0.5) * width), int(rng.uniform(0.0, 0.4) * height)
        x1 = x0 + int(rng.uniform(0.35, 0.6) * width)
        y1 = y0 + int(rng.uniform(0.4, 0.6) * height)
        img[y0:y1, x0:x1] = random_color(rng, s=(0.0, 0.3), v=(0.8, 1.0))
        img[y0 : y0 + max(3, height // 10), x0:x1] = random_color(rng, s=(0.5, 1.0), v=(0.4, 0.8))
    return to_uint8(img)


def ad_board(rng: np.random.Generator, height: int = 32, width: int = 128) -> np.ndarray:
    """A pitch-side advertising board: a bright colour with a big word.

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB.
    """
    img = np.empty((height, width, 3), np.float32)
    img[:] = random_color(rng, s=(0.6, 1.0), v=(0.5, 1.0))
    fg = (255, 255, 255) if rng.uniform() < 0.5 else random_color(rng, v=(0.9, 1.0))
    word = str(rng.choice(("VC GYM", "ROBO", "KICK", "SPORT", "CLUB", "CAFE", "GOAL", "PLAY")))
    _text(img, word, fg, (int(0.06 * width), 2, int(0.94 * width), height - 2))
    return to_uint8(img)


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
    c = Canvas(width_m, height_m, px_per_m, random_color(rng, s=(0.05, 0.5), v=(0.45, 0.9)))
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
    c.rect(0.0, width_m, height_m - 0.5, height_m, random_color(rng, s=(0.2, 0.6), v=(0.3, 0.6)))
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
        img[top:, bx : bx + bw] = random_color(rng, s=(0.0, 0.3), v=(0.55, 0.85))
    return to_uint8(img)


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
    return to_uint8(img * (1 - 0.7 * cover) + 248.0 * 0.7 * cover)
