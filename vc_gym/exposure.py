"""Exposure: scaling the light of an image in linear (not sRGB) units.

Used to darken synthetic views physically (``illumination``) and, when
``CompassConfig.exposure == "mean"``, to undo a change of illumination or camera
exposure before colour classification: every frame's scanned pixels are scaled so
that their mean linear luminance equals the reference level of the colour-fitting
images. Both are one 256-entry table read per channel value.
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = [
    "MAX_GAIN_STOPS",
    "SRGB_TO_LINEAR",
    "column_levels",
    "gain_table",
    "mean_linear_level",
    "quantized_gain",
]

_v = np.arange(256, dtype=np.float64) / 255.0
#: Linear light (0..1) of every sRGB code value.
SRGB_TO_LINEAR = np.where(_v <= 0.04045, _v / 12.92, ((_v + 0.055) / 1.055) ** 2.4)
SRGB_TO_LINEAR.setflags(write=False)
_LINEAR32 = SRGB_TO_LINEAR.astype(np.float32)
#: Gains are quantised to 1/32 of a stop so that the tables can be cached.
_STEPS_PER_STOP = 32
#: Gains are kept within ±8 stops (a factor of 256).
MAX_GAIN_STOPS = 8


@functools.lru_cache(maxsize=512)
def _table(step: int) -> np.ndarray:
    gain = 2.0 ** (step / _STEPS_PER_STOP)
    linear = np.clip(SRGB_TO_LINEAR * gain, 0.0, 1.0)
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
    table = np.clip(np.rint(srgb * 255.0), 0, 255).astype(np.uint8)
    table.setflags(write=False)
    return table


def quantized_gain(gain: float) -> int:
    """Index of the cached table nearest to ``gain`` (1/32-stop steps, ±8 stops)."""
    if not math.isfinite(gain) or gain <= 0:
        raise ValueError(f"gain must be finite and > 0, got {gain}")
    stops = min(max(math.log2(gain), -MAX_GAIN_STOPS), MAX_GAIN_STOPS)
    return int(round(stops * _STEPS_PER_STOP))


def gain_table(gain: float) -> np.ndarray:
    """256-entry ``uint8`` table: sRGB value -> sRGB value with linear light × ``gain``.

    ``gain`` is quantised to 1/32 of a stop (at most 2 % off) and clipped to ±8 stops.
    """
    return _table(quantized_gain(gain))


def mean_linear_level(pixels: np.ndarray) -> float:
    """Mean linear light (0..1) over all channels of ``uint8`` sRGB pixels."""
    if pixels.size == 0:
        return 0.0
    return float(_LINEAR32[pixels].mean())


def column_levels(pixels: np.ndarray) -> np.ndarray:
    """Mean linear light (0..1) of every column of ``(R, U, 3)`` uint8 sRGB pixels."""
    if pixels.shape[0] == 0:
        return np.zeros(pixels.shape[1], dtype=np.float64)
    return _LINEAR32[pixels].mean(axis=(0, 2), dtype=np.float64)
