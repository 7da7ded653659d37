"""Colour and noise helpers shared by every painter of vc_gym's worlds and textures.

The procedural panoramas (:mod:`vc_gym.worlds.panorama_painters`), the ray-cast room
(:mod:`vc_gym.worlds.room`), the :class:`~vc_gym.worlds.canvas.Canvas` and the PyBullet
scene textures (:mod:`vc_gym.sim.textures`) all paint with these:

* :func:`hsv` and :func:`random_color`: colours as ``(3,)`` ``float32`` RGB in 0..255;
* :func:`to_uint8`: a painted float image as the ``uint8`` image everything else takes;
* :func:`value_noise`: smooth value noise in ``[-1, 1]``, periodic along x (seamless
  around a panorama or a room's perimeter);
* :func:`smooth_noise`: smooth Gaussian noise of about unit standard deviation, not
  periodic (blotches on a flat texture);
* :func:`smoothstep`: the cubic ease curve :func:`value_noise` interpolates with.

The two noises are different random fields (uniform knots eased with :func:`smoothstep`
and wrapped in x, versus normal draws upsampled bicubically by OpenCV); they draw
different numbers from the generator, so each painter keeps the one it was seeded with.

All randomness comes from the ``numpy.random.Generator`` passed in.
"""

from __future__ import annotations

import colorsys
import sys

import cv2
import numpy as np

from vc_gym.deprecation import moved_names

__all__ = ["hsv", "random_color", "smooth_noise", "smoothstep", "to_uint8", "value_noise"]


def hsv(h: float, s: float, v: float) -> np.ndarray:
    """RGB colour of a hue, saturation and value.

    Parameters
    ----------
    h : float
        Hue in turns; wraps around (0 and 1 are red).
    s, v : float
        Saturation and value, clipped to 0..1.

    Returns
    -------
    numpy.ndarray
        ``(3,)`` ``float32`` RGB in 0..255.
    """
    r, g, b = colorsys.hsv_to_rgb(h % 1.0, min(max(s, 0.0), 1.0), min(max(v, 0.0), 1.0))
    return np.array([r, g, b], dtype=np.float32) * np.float32(255.0)


def random_color(
    rng: np.random.Generator,
    s: tuple[float, float] = (0.5, 1.0),
    v: tuple[float, float] = (0.5, 1.0),
    h: tuple[float, float] = (0.0, 1.0),
) -> np.ndarray:
    """A random colour with hue, saturation and value drawn uniformly from the ranges.

    Three draws from ``rng``, in the order hue, saturation, value.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the draws.
    s, v, h : tuple of float
        ``(low, high)`` ranges of saturation, value and hue (turns).

    Returns
    -------
    numpy.ndarray
        ``(3,)`` ``float32`` RGB in 0..255.
    """
    return hsv(rng.uniform(*h), rng.uniform(*s), rng.uniform(*v))


# deprecated: random_colour, the British spelling of random_color, served for one release
__getattr__ = moved_names(__name__, {"random_colour": (sys.modules[__name__], "random_color")})


def to_uint8(img: np.ndarray) -> np.ndarray:
    """A float image in 0..255 rounded to the nearest integer and clipped, as ``uint8``.

    Parameters
    ----------
    img : numpy.ndarray
        Float image (any shape), values nominally 0..255.

    Returns
    -------
    numpy.ndarray
        A new ``uint8`` array of the same shape; ``img`` is not changed.
    """
    out = np.rint(img)
    np.clip(out, 0, 255, out=out)
    return out.astype(np.uint8)


def smoothstep(t: np.ndarray) -> np.ndarray:
    """The cubic ease curve ``3 t^2 - 2 t^3``: 0 at 0, 1 at 1, flat at both ends.

    Parameters
    ----------
    t : numpy.ndarray
        Values in ``[0, 1]`` (not clipped).

    Returns
    -------
    numpy.ndarray
        ``t * t * (3 - 2 t)``, same shape and dtype as ``t``.
    """
    return t * t * (3.0 - 2.0 * t)


def value_noise(
    rng: np.random.Generator, height: int, width: int, cells_x: int, cells_y: int
) -> np.ndarray:
    """Smooth value noise in ``[-1, 1]``, periodic in x.

    Uniform knots on a ``(cells_y + 1) x cells_x`` grid are blended with
    :func:`smoothstep` weights between pixel centres; the last knot column wraps to the
    first, so the noise is seamless around a 360° panorama.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the knots (one ``uniform(-1, 1, (cells_y + 1, cells_x))`` draw).
    height, width : int
        Size of the result in pixels.
    cells_x, cells_y : int
        Number of noise cells across the width (period) and down the height.

    Returns
    -------
    numpy.ndarray
        ``(height, width)`` ``float32`` in ``[-1, 1]``.
    """
    knots = rng.uniform(-1.0, 1.0, (cells_y + 1, cells_x)).astype(np.float32)
    tx = (np.arange(width) + 0.5) * (cells_x / width)
    i0 = np.floor(tx).astype(np.intp)
    wx = smoothstep(tx - i0).astype(np.float32)
    rows = knots[:, i0 % cells_x] * (1.0 - wx) + knots[:, (i0 + 1) % cells_x] * wx
    ty = (np.arange(height) + 0.5) * (cells_y / height)
    j0 = np.floor(ty).astype(np.intp)
    wy = smoothstep(ty - j0).astype(np.float32)[:, None]
    return rows[j0] * (1.0 - wy) + rows[np.minimum(j0 + 1, cells_y)] * wy


def smooth_noise(rng: np.random.Generator, height: int, width: int, cells: float) -> np.ndarray:
    """Smooth noise of about unit standard deviation, ``cells`` blobs across the width.

    A coarse grid of normal draws upsampled bicubically: no detail finer than
    ``width / cells`` pixels, so it never aliases. Not periodic (use
    :func:`value_noise` for a seamless panorama).

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the draws.
    height, width : int
        Size of the result in pixels.
    cells : float
        Number of blobs across the width (the grid keeps square cells).

    Returns
    -------
    numpy.ndarray
        ``(height, width)`` ``float32``.
    """
    gw = max(2, int(round(cells)) + 1)
    gh = max(2, int(round(cells * height / max(width, 1))) + 1)
    grid = rng.standard_normal((gh, gw)).astype(np.float32)
    return cv2.resize(grid, (int(width), int(height)), interpolation=cv2.INTER_CUBIC)
