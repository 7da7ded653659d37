"""The gain that brings a frame to the light the compass learned in (beyond the paper).

Colour classes are fixed regions of colour space, so a change of light moves pixels
across class boundaries. ``CompassConfig.exposure`` picks how a frame's linear light
is scaled before it is classified:

- ``"mean"``: every frame to the reference level, the mean linear level of the
  colour-fitting images (:func:`scaled_to_reference`);
- ``"session"``: one gain for a whole session, read from its frames' gains
  (:func:`frame_gain_of`, a :class:`~vc_gym.exposure.SessionLight` over them); a lone
  frame is its own session;
- ``"map"``: a gain per candidate heading, from the light the map learned in the
  directions that heading puts in view (:class:`~vc_gym.compass.light_map.LightMap`);
  each heading is scored with its own gain, a profile likelihood over the unknown
  gain (:func:`profile_log_likelihood`).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence

import numpy as np

from vc_gym.compass.light_map import LightMap
from vc_gym.compass.scan_geometry import ScanGeometry
from vc_gym.deprecation import moved_names
from vc_gym.exposure import (
    GAIN_STEP_STOPS,
    column_levels,
    gain_table,
    mean_linear_level,
    quantized_stops,
)

__all__ = [
    "REFERENCE_EXPOSURES",
    "color_fitting_levels",
    "exposure_corrected",
    "frame_gain_of",
    "heading_gain_steps",
    "profile_log_likelihood",
    "scaled_to_reference",
    "step_gain",
    "upper_half",
]

#: Exposure modes that keep the colour-fitting images' mean light as a reference level.
REFERENCE_EXPOSURES = ("mean", "session")

#: A frame's sector features ``(counts, total)``
#: (:func:`vc_gym.compass.likelihood.sector_features`).
Features = tuple[np.ndarray, np.ndarray]


def upper_half(image: np.ndarray) -> np.ndarray:
    """The upper half of an image (at least one row): what the compass scans at pitch 0."""
    return image[: max(image.shape[0] // 2, 1)]


def color_fitting_levels(images: Sequence[np.ndarray]) -> list[float]:
    """Mean linear light level of the :func:`upper_half` of each colour-fitting image;
    their mean is the reference level of ``exposure="mean"`` and ``"session"``."""
    return [mean_linear_level(upper_half(im)) for im in images]


# deprecated: colour_fitting_levels, the British spelling of color_fitting_levels, served
# for one release
__getattr__ = moved_names(
    __name__, {"colour_fitting_levels": (sys.modules[__name__], "color_fitting_levels")}
)


def scaled_to_reference(pixels: np.ndarray, level: float, reference: float) -> np.ndarray:
    """Scale linear light so that pixels at mean ``level`` come out at ``reference``
    (unchanged if ``level <= 0``: a black frame has no level to scale)."""
    if level <= 0:
        return pixels
    return np.take(gain_table(reference / level), pixels)


def exposure_corrected(
    pixels: np.ndarray, exposure: str, reference: float, gain: float = 1.0
) -> np.ndarray:
    """The scanned ``pixels`` as the colour classes should see them.

    ``exposure="mean"`` scales them to the ``reference`` level; any other mode
    multiplies their linear light by ``gain`` (1 leaves them as they are).
    """
    if exposure == "mean":
        return scaled_to_reference(pixels, mean_linear_level(pixels), reference)
    if gain != 1.0:
        return np.take(gain_table(gain), pixels)
    return pixels


def frame_gain_of(pixels: np.ndarray, reference: float) -> float:
    """The reference level over the mean linear level of ``pixels``; ``inf`` if black."""
    level = mean_linear_level(pixels)
    return reference / level if level > 0 else math.inf


def step_gain(step: int) -> float:
    """The gain of ``step`` steps of :data:`~vc_gym.exposure.GAIN_STEP_STOPS`."""
    return 2.0 ** (step * GAIN_STEP_STOPS)


def heading_gain_steps(light: LightMap, pixels: np.ndarray, geom: ScanGeometry) -> np.ndarray:
    """``exposure="map"``: the gain of every candidate heading, in steps of
    :data:`~vc_gym.exposure.GAIN_STEP_STOPS` (:func:`~vc_gym.exposure.quantized_stops`).

    Parameters
    ----------
    light : LightMap
        The light the map learned per sector.
    pixels : numpy.ndarray
        The frame's scanned pixels (``image[geom.row_slice, geom.col_slice]``).
    geom : ScanGeometry
        The frame's scan geometry.

    Returns
    -------
    numpy.ndarray
        ``(n_headings,)`` integer steps.
    """
    gains = light.heading_gains(
        column_levels(pixels),
        geom.first_col,
        geom.stop_col,
        geom.n_rel,
        geom.heading_phase,
        geom.roll_index[:, geom.heading_sector],
    )
    return quantized_stops(gains)


def profile_log_likelihood(
    steps: np.ndarray,
    features_at: Callable[[float], Features],
    log_likelihood_of: Callable[[Features], np.ndarray],
) -> tuple[np.ndarray, Features, int]:
    """Log-likelihood over headings with each heading scored at its own gain.

    Parameters
    ----------
    steps : numpy.ndarray
        ``(n_headings,)`` gain of each heading in steps (:func:`heading_gain_steps`).
    features_at : callable
        The frame's sector features classified at a gain.
    log_likelihood_of : callable
        Log-likelihood over all headings of sector features.

    Returns
    -------
    ll : numpy.ndarray
        ``(n_headings,)``: heading ``h`` takes its value from the features at
        ``step_gain(steps[h])``.
    features : tuple of numpy.ndarray
        The features of the best heading.
    step : int
        The gain step of the best heading.
    """
    ll = np.empty(steps.size)
    # only the features of the best heading so far are kept (a frame has 5-15
    # gains, each a (phases x sectors in view x pairs) array); the best is the
    # first heading of the largest log-likelihood, as numpy.argmax finds it
    best, best_at, best_features = 0, steps.size, None
    for k in np.unique(steps).tolist():
        features = features_at(step_gain(k))
        at = np.flatnonzero(steps == k)
        ll[at] = log_likelihood_of(features)[at]
        first = int(at[np.argmax(ll[at])])
        if best_features is None or (ll[first], -first) > (ll[best_at], -best_at):
            best, best_at, best_features = k, first, features
    assert best_features is not None
    return ll, best_features, best
