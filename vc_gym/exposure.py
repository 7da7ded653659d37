"""Exposure: scaling the light of an image in linear (not sRGB) units.

Used to darken synthetic views physically (``illumination``) and to undo a change of
illumination or camera exposure before colour classification: with
``CompassConfig.exposure == "mean"`` every frame's scanned pixels are scaled so that
their mean linear luminance equals the reference level of the colour-fitting images;
with ``"session"`` every frame of a session is scaled by one gain, the
:class:`SessionLight` of the gains ``"mean"`` would apply. Both are one 256-entry
table read per channel value.
"""

from __future__ import annotations

import functools
import math
from collections import deque

import numpy as np

__all__ = [
    "GAIN_STEP_STOPS",
    "MAX_GAIN_STOPS",
    "SRGB_TO_LINEAR",
    "SessionLight",
    "column_levels",
    "gain_table",
    "mean_linear_level",
    "quantized_gain",
    "quantized_stops",
    "rounded_gain",
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
#: Gains the compass applies are whole multiples of a third of a stop (factor 1.26, a
#: camera's exposure step): with ``exposure="map"`` each is a classification, and finer
#: steps changed no result by more than the noise between steps; a session's light
#: rounded to it does not wander with what the frames show.
GAIN_STEP_STOPS = 1.0 / 3.0


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


def quantized_stops(gains: np.ndarray) -> np.ndarray:
    """``gains`` as whole multiples of :data:`GAIN_STEP_STOPS` (ints, clipped to ±8 stops,
    :data:`MAX_GAIN_STOPS`)."""
    stops = np.clip(np.log2(gains), -MAX_GAIN_STOPS, MAX_GAIN_STOPS)
    return np.rint(stops / GAIN_STEP_STOPS).astype(np.int64)


def rounded_gain(gain: float) -> float:
    """``gain`` rounded to a whole number of :data:`GAIN_STEP_STOPS` (within ±8 stops)."""
    return float(2.0 ** (int(quantized_stops(np.array(gain))) * GAIN_STEP_STOPS))


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


class SessionLight:
    """The light of a session, read from the gains of its frames (beyond the paper).

    The per-frame gain of ``exposure="mean"`` (reference level ÷ the frame's mean
    level) reads the light from what a frame shows: a view of the sky or of a white
    wall looks like more light, one of a dark shelf like less (one to two stops on the
    real photo sets, where the light never changed). The light of a session changes
    slowly, so the median of the last ``window`` frames' gains, in stops and rounded to
    :data:`GAIN_STEP_STOPS`, reads the light and not the content: a session at the
    colour-fitting light comes out at exactly 1 (the paper's classification), one at
    half the light at 2.

    Parameters
    ----------
    window : int or None
        Frames the median runs over (the newest); ``None``: every frame since
        :meth:`reset`.
    """

    def __init__(self, window: int | None = 100):
        if window is not None and (
            isinstance(window, bool) or not isinstance(window, (int, np.integer)) or window < 1
        ):
            raise ValueError(f"window must be an int >= 1 or None, got {window!r}")
        self.window = None if window is None else int(window)
        self.reset()

    @classmethod
    def of(cls, frame_gains) -> float:
        """The gain of one whole session given all its frames' gains at once."""
        light = cls(window=None)
        for g in frame_gains:
            light.update(g)
        return light.gain

    def reset(self) -> None:
        """Forget every frame (a new session)."""
        self._stops: deque[float] = deque(maxlen=self.window)

    def __len__(self) -> int:
        return len(self._stops)

    def update(self, frame_gain: float) -> float:
        """Add one frame's gain and return the session's (:attr:`gain`).

        A gain that is not a finite number > 0 (a black frame has no level to read) is
        skipped: it says nothing about the light.
        """
        g = float(frame_gain)
        if math.isfinite(g) and g > 0:
            self._stops.append(min(max(math.log2(g), -MAX_GAIN_STOPS), MAX_GAIN_STOPS))
        return self.gain

    @property
    def gain(self) -> float:
        """The session's gain: 1 before any usable frame."""
        if not self._stops:
            return 1.0
        return rounded_gain(2.0 ** float(np.median(np.fromiter(self._stops, float))))
