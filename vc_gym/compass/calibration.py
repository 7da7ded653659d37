"""A heading spread a filter can trust: a temperature of the compass' log-likelihood.

The likelihood of eq. 16 is a product over every sector in view and every class pair,
as if those hundreds of terms were independent. They are not (neighbouring sectors
see the same wall, the class pairs of one sector share its pixels), so the posterior
``∝ exp(log-likelihood)`` is far narrower than the compass is right: its circular
standard deviation (eq. 27) is about 0.00° on real photos whose errors are 0.3-0.8°.

The calibrated spread of an estimate is

``σ = max(circular_std(softmax(log_likelihood / T)), floor)``

the eq. 27 spread of the posterior *tempered* by a temperature ``T`` (the
log-likelihood divided by ``T``, a uniform prior), floored at ``floor`` degrees.

- ``T`` is fitted to frames whose true heading is known by maximising the Gaussian
  log-likelihood of their errors ``e_k`` (estimate minus truth, wrapped) under their
  own spreads, ``Σ_k -log σ_k(T) - e_k² / (2 σ_k(T)²)``: the proper score of the
  reading ``heading ± σ`` that a Kalman filter takes as its measurement (eq. 25), so
  ``σ`` is neither too small (the squared term) nor too large (the log term). ``T`` is
  searched on :data:`TEMPERATURES` (log-spaced, 6 % apart); of equally good values
  the largest is kept (with every error below the floor, every ``T`` that keeps each
  spread at the floor scores alike, and the largest of them is the most cautious).
- The floor is half a heading-grid step by default (:data:`FLOOR_STEPS`). The
  posterior lives on the grid (1° by default): a tempered posterior narrower than a
  step puts all its weight on one grid point and its spread reads 0, while the best
  heading is only known to within the parabola through the peak (at most half a step
  from the grid point). Half a step makes ``±2σ`` reach the neighbouring grid points.
- At map time the learning frames themselves serve, each left out of the map in turn
  (:meth:`VisualCompass.calibrate(..., leave_one_out=True)
  <vc_gym.compass.VisualCompass.calibrate>`): a frame of a learning turn, scored
  against the map of every other frame of the turn, is a new view from the learning
  spot. A frame whose view no other learning frame saw (sparse learning photos, such as
  9 photos of 34° taken 40° apart) would be scored against sectors the map never saw, so
  such frames are skipped (:data:`MIN_COVERED_FRACTION`); when too few remain, calibrate with
  held-out frames of known heading instead.

Pure numpy; :class:`~vc_gym.compass.VisualCompass` stores ``T`` and the floor with its
map (:mod:`~vc_gym.compass.map_files`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vc_gym.angles import peak_headings, wrap180
from vc_gym.compass.config import MAX_TEMPERATURE, MIN_TEMPERATURE
from vc_gym.validation import finite_float

__all__ = [
    "FLOOR_STEPS",
    "MAX_FLOOR_DEG",
    "MIN_CALIBRATION_FRAMES",
    "MIN_COVERED_FRACTION",
    "TEMPERATURES",
    "UNCALIBRATED",
    "SpreadCalibration",
    "calibration_report",
    "check_spread_calibration",
    "fit_temperature",
    "heading_errors",
    "tempered_spreads",
]

#: The calibrated floor of the spread, in heading-grid steps (half a step: 0.5° on the
#: default 1° grid; see the module notes).
FLOOR_STEPS = 0.5
#: Largest floor accepted (degrees): a spread of 90° already says "somewhere in a half
#: circle".
MAX_FLOOR_DEG = 90.0
#: Fewest frames (with evidence) a temperature is fitted to: fewer say nothing about
#: the spread of the errors.
MIN_CALIBRATION_FRAMES = 5
#: Leave-one-out: a learning frame is used only if at least this share of the sectors
#: it saw were also seen by the other learning frames.
MIN_COVERED_FRACTION = 0.5
#: Temperatures searched by :func:`fit_temperature`: 201 values log-spaced over the
#: range :class:`~vc_gym.compass.CompassConfig` accepts (0.01-1000, 6 % apart).
TEMPERATURES = np.geomspace(MIN_TEMPERATURE, MAX_TEMPERATURE, 201)
#: ``(temperature, floor_deg)`` of a map never calibrated: the paper's posterior
#: (eq. 16, 27) as it is, with no floor.
UNCALIBRATED = (1.0, 0.0)


def check_spread_calibration(temperature: object, floor_deg: object) -> tuple[float, float]:
    """``(temperature, floor_deg)`` as floats, or a ``ValueError`` naming the one at fault.

    ``temperature`` must lie in ``[MIN_TEMPERATURE, MAX_TEMPERATURE]`` (those of
    :class:`~vc_gym.compass.CompassConfig`: beyond them every posterior is one grid
    point or flat), ``floor_deg`` in ``[0, MAX_FLOOR_DEG]``.
    """
    t = finite_float("spread temperature", temperature)
    if not MIN_TEMPERATURE <= t <= MAX_TEMPERATURE:
        raise ValueError(
            f"spread temperature must be in [{MIN_TEMPERATURE:g}, {MAX_TEMPERATURE:g}], "
            f"got {temperature!r}"
        )
    f = finite_float("spread floor_deg", floor_deg)
    if not 0.0 <= f <= MAX_FLOOR_DEG:
        raise ValueError(f"spread floor_deg must be in [0, {MAX_FLOOR_DEG:g}], got {floor_deg!r}")
    return t, f


def tempered_spreads(
    log_likelihoods: np.ndarray,
    headings_deg: np.ndarray,
    temperature: float | np.ndarray,
    floor_deg: float | np.ndarray,
) -> np.ndarray:
    """Calibrated spread of each row: eq. 27 of ``softmax(row / temperature)``, floored.

    Parameters
    ----------
    log_likelihoods : numpy.ndarray
        ``(M, N)`` log-likelihoods over ``headings_deg`` (finite).
    headings_deg : numpy.ndarray
        ``(N,)`` the heading grid.
    temperature, floor_deg : float or numpy.ndarray
        As checked by :func:`check_spread_calibration`: one for every row, or ``(M,)``
        arrays, one per row.

    Returns
    -------
    numpy.ndarray
        ``(M,)`` spreads in degrees, ``sqrt(-2 ln R)`` of the tempered posterior (``R``
        its mean resultant length), at least ``floor_deg``; infinite where ``R`` is 0.
        With ``temperature=1`` and ``floor_deg=0`` this is the paper's eq. 27 spread.
    """
    ll = np.asarray(log_likelihoods, dtype=np.float64)
    t = np.asarray(temperature, dtype=np.float64)
    if np.any(t != 1.0):
        ll = ll / (t[:, None] if t.ndim else t)
    w = np.exp(ll - ll.max(axis=1, keepdims=True))
    a = np.radians(np.asarray(headings_deg, dtype=np.float64))
    r = np.hypot((w * np.sin(a)).sum(axis=1), (w * np.cos(a)).sum(axis=1)) / w.sum(axis=1)
    return np.maximum(_std_of_resultants(r), floor_deg)


def _std_of_resultants(r: np.ndarray) -> np.ndarray:
    """``sqrt(-2 ln R)`` in degrees, as :func:`vc_gym.angles.circular_std` (``R`` capped
    at 1; infinite for ``R = 0``)."""
    r = np.minimum(r, 1.0)
    out = np.full(r.shape, np.inf)
    pos = r > 0.0
    out[pos] = np.degrees(np.sqrt(np.maximum(-2.0 * np.log(r[pos]), 0.0)))
    return out


def heading_errors(
    log_likelihoods: np.ndarray, true_headings_deg: np.ndarray, step_deg: float
) -> np.ndarray:
    """``|estimate - truth|`` (wrapped, degrees) of the refined arg-max heading of each row
    (the :attr:`~vc_gym.compass.CompassEstimate.heading_deg` of the row)."""
    heading, _ = peak_headings(log_likelihoods, step_deg)
    return np.abs(wrap180(heading - np.asarray(true_headings_deg, dtype=np.float64)))


def fit_temperature(
    log_likelihoods: np.ndarray,
    errors_deg: np.ndarray,
    headings_deg: np.ndarray,
    floor_deg: float,
) -> float:
    """The temperature whose spreads best describe the observed errors.

    Maximises ``Σ_k -log σ_k(T) - e_k² / (2 σ_k(T)²)`` over :data:`TEMPERATURES`, with
    ``σ_k(T)`` the :func:`tempered_spreads` of row ``k``; of equally good temperatures
    (within 1e-9) the largest.

    Parameters
    ----------
    log_likelihoods : numpy.ndarray
        ``(K, N)`` finite log-likelihoods of ``K >= MIN_CALIBRATION_FRAMES`` frames.
    errors_deg : numpy.ndarray
        ``(K,)`` their heading errors in degrees (:func:`heading_errors`).
    headings_deg : numpy.ndarray
        ``(N,)`` the heading grid.
    floor_deg : float
        The floor of the spreads. Without one, a temperature that leaves some frame's
        posterior on a single grid point (spread 0) with a non-zero error scores
        ``-inf``; if every temperature does, the largest is returned.

    Returns
    -------
    float
        The fitted temperature.

    Raises
    ------
    ValueError
        Too few frames, mismatched shapes, or values that are not finite.
    """
    ll = np.asarray(log_likelihoods, dtype=np.float64)
    e = np.asarray(errors_deg, dtype=np.float64)
    if ll.ndim != 2 or e.shape != (ll.shape[0],) or ll.shape[1] != np.size(headings_deg):
        raise ValueError(
            f"need (K, {np.size(headings_deg)}) log-likelihoods and (K,) errors, got "
            f"{ll.shape} and {e.shape}"
        )
    if ll.shape[0] < MIN_CALIBRATION_FRAMES:
        raise ValueError(
            f"a temperature needs at least {MIN_CALIBRATION_FRAMES} frames with evidence, "
            f"got {ll.shape[0]}"
        )
    if not (np.all(np.isfinite(ll)) and np.all(np.isfinite(e))):
        raise ValueError("log-likelihoods and errors must be finite")
    scores = np.empty(TEMPERATURES.size)
    for i, t in enumerate(TEMPERATURES):
        s = tempered_spreads(ll, headings_deg, float(t), floor_deg)
        with np.errstate(divide="ignore", invalid="ignore"):
            # an infinite spread (a flat posterior) costs its log; a zero one with a
            # zero error nothing, with any other error everything
            term = np.log(s) + 0.5 * np.where(e > 0, (e / s) ** 2, 0.0)
        scores[i] = -float(np.mean(term)) if np.all(np.isfinite(term)) else -math.inf
    best = scores.max()
    if not np.isfinite(best):
        # every candidate gives some frame a zero spread and an error: no floor
        return float(TEMPERATURES[-1])
    tie = scores >= best - 1e-9 * max(1.0, abs(best))
    return float(TEMPERATURES[np.flatnonzero(tie)[-1]])


@dataclass(frozen=True)
class SpreadCalibration:
    """A temperature fitted to frames of known heading, and how well it describes them.

    Attributes
    ----------
    temperature : float
        The fitted ``T`` (see the module notes).
    floor_deg : float
        The floor of the spread.
    frames : int
        Frames used (with evidence and, with leave-one-out, seen by the rest of the map).
    skipped : int
        Frames not used: no evidence, or (leave-one-out) a view the rest of the map did
        not cover.
    within_1sigma, within_2sigma : float
        Share of the used frames whose error is at most one and two calibrated spreads
        (a calibrated sensor: about 0.68 and 0.95).
    median_abs_error_deg, median_spread_deg : float
        Median error and median calibrated spread of the used frames.
    """

    temperature: float
    floor_deg: float
    frames: int
    skipped: int
    within_1sigma: float
    within_2sigma: float
    median_abs_error_deg: float
    median_spread_deg: float


def calibration_report(
    log_likelihoods: np.ndarray,
    errors_deg: np.ndarray,
    headings_deg: np.ndarray,
    temperature: float,
    floor_deg: float,
    skipped: int = 0,
) -> SpreadCalibration:
    """The :class:`SpreadCalibration` of ``temperature`` and ``floor_deg`` on frames whose
    log-likelihoods (``(K, N)``) and errors (``(K,)``) are given."""
    s = tempered_spreads(log_likelihoods, headings_deg, temperature, floor_deg)
    e = np.asarray(errors_deg, dtype=np.float64)
    return SpreadCalibration(
        temperature=float(temperature),
        floor_deg=float(floor_deg),
        frames=int(e.size),
        skipped=int(skipped),
        within_1sigma=float(np.mean(e <= s)),
        within_2sigma=float(np.mean(e <= 2.0 * s)),
        median_abs_error_deg=float(np.median(e)),
        median_spread_deg=float(np.median(s)),
    )
