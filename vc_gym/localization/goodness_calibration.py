"""Position from one view: a likelihood calibrated on goodness against distance.

The paper's position estimate (eq. 30) weights the training spots by their goodness
``L_i`` (eq. 28): it can only answer points inside the spots' hull, and ``L_i`` says how
well a frame fits spot ``i``, not how far the spot is. Calibrated on frames taken at
known positions, each spot's raw score ``s_i = log L_i`` is modelled as a saturating
fall with distance,

    s_i ≈ a_i − b_i · (1 − exp(−d_i / λ)),    residual spread σ_i,

and a frame's score vector then gives a likelihood over the whole field,

    p(s | x) ∝ Π_i N(s_i; a_i − b_i · (1 − exp(−d_i(x) / λ)), σ_i),

whose mean is the position estimate and whose spread its uncertainty.

* :func:`calibration_points` -- where to take the calibration frames: the spots, the
  midpoints between neighbouring spots and (with the field's bounds) its border;
* :func:`calibrate_goodness` -- fit ``a``, ``b``, ``σ`` per spot and a shared ``λ``;
* :func:`goodness_log_likelihood` -- ``log p(s | x)`` at given positions (e.g. a
  particle filter's);
* :func:`locate_by_goodness` -- the posterior mean and spread on a grid over the field.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from vc_gym.localization.spot_scores import finite_array
from vc_gym.validation import positive_float

__all__ = [
    "BORDER_MARGIN_M",
    "GRID_STEP_M",
    "LENGTH_SCALES_M",
    "GoodnessCalibration",
    "calibrate_goodness",
    "calibration_points",
    "goodness_log_likelihood",
    "locate_by_goodness",
]

#: Length scales ``λ`` tried for the saturating fall of goodness with distance (metres).
LENGTH_SCALES_M = (0.25, 0.35, 0.5, 0.7, 1.0, 1.4, 2.0, 3.0)
#: Resolution of the grid :func:`locate_by_goodness` evaluates the likelihood on (metres).
GRID_STEP_M = 0.05
#: Distance kept from the field's edges by border calibration points (metres).
BORDER_MARGIN_M = 0.25
#: Smallest residual spread a fit reports: a spot whose scores fit exactly still
#: leaves room for a frame's noise.
MIN_SIGMA = 1e-3


class GoodnessCalibration(NamedTuple):
    """How each spot's raw score falls with distance: ``s_i ≈ a_i − b_i·(1 − exp(−d/λ))``.

    A tuple ``(a, b, sigma, length_m)``, as :func:`calibrate_goodness` returns it.

    Attributes
    ----------
    a : numpy.ndarray
        ``(M,)`` score of each spot's map at the spot.
    b : numpy.ndarray
        ``(M,)`` how far it falls far away (>= 0).
    sigma : numpy.ndarray
        ``(M,)`` residual standard deviation of each spot's scores (> 0).
    length_m : float
        ``λ``: the distance over which the scores fall, shared by every spot.
    """

    a: np.ndarray
    b: np.ndarray
    sigma: np.ndarray
    length_m: float


def _falloff(d: np.ndarray, length_m: float) -> np.ndarray:
    return 1.0 - np.exp(-d / length_m)


def calibration_points(spots: np.ndarray, bounds: Sequence[float] | None = None) -> np.ndarray:
    """Where to take calibration frames: the spots and the midpoints between neighbours.

    That is where a robot that walks from spot to spot while learning passes, knowing
    by odometry where it is. With the field's ``bounds`` also border points: every
    outermost spot of a row or column moved out to :data:`BORDER_MARGIN_M` inside the
    field's edge, and the four corners, so that calibration also covers the strip
    beyond the outer spots.

    Parameters
    ----------
    spots : array_like
        ``(M, 2)`` training spots ``(x, y)``, metres.
    bounds : sequence of float, optional
        ``(xmin, xmax, ymin, ymax)`` of the field.

    Returns
    -------
    numpy.ndarray
        ``(P, 2)`` places: the spots first, then the midpoints of neighbouring spots
        (no diagonals), then the border points not already among them.

    Raises
    ------
    ValueError
        Spots not a finite, non-empty ``(M, 2)`` array; bounds not 4 finite numbers
        with ``min < max``.
    """
    pts = finite_array("spots", spots, (None, 2))
    border = _border_points(pts, bounds) if bounds is not None else np.zeros((0, 2))
    d = np.hypot(pts[:, None, 0] - pts[None, :, 0], pts[:, None, 1] - pts[None, :, 1])
    nearest = np.min(np.where(d > 0, d, np.inf), axis=1)
    mids = [
        (pts[i] + pts[j]) / 2
        for i in range(len(pts))
        for j in range(i + 1, len(pts))
        if d[i, j] <= 1.01 * max(nearest[i], nearest[j])
    ]
    out = list(np.vstack([pts, *mids]) if mids else pts)
    for p in border:  # each border point once, and none that is already a place
        if not np.any(np.all(np.abs(np.asarray(out) - p) < 1e-6, axis=1)):
            out.append(p)
    return np.array(out, np.float64)


def _field_bounds(bounds: object) -> np.ndarray:
    b = finite_array("bounds", bounds, (4,))
    if not (b[0] < b[1] and b[2] < b[3]):
        raise ValueError(f"bounds must be (xmin, xmax, ymin, ymax) with min < max, got {bounds}")
    return b


def _border_points(pts: np.ndarray, bounds: Sequence[float]) -> np.ndarray:
    x0, x1, y0, y1 = _field_bounds(bounds)
    m = BORDER_MARGIN_M
    lo_x, hi_x, lo_y, hi_y = x0 + m, x1 - m, y0 + m, y1 - m
    out = []
    for y in np.unique(pts[:, 1]):
        row = pts[pts[:, 1] == y, 0]
        out += [(lo_x, y)] if row.min() > lo_x + 1e-6 else []
        out += [(hi_x, y)] if row.max() < hi_x - 1e-6 else []
    for x in np.unique(pts[:, 0]):
        col = pts[pts[:, 0] == x, 1]
        out += [(x, lo_y)] if col.min() > lo_y + 1e-6 else []
        out += [(x, hi_y)] if col.max() < hi_y - 1e-6 else []
    out += [(lo_x, lo_y), (lo_x, hi_y), (hi_x, lo_y), (hi_x, hi_y)]
    return np.array(out, np.float64)


def calibrate_goodness(
    spots: np.ndarray,
    positions: np.ndarray,
    scores: np.ndarray,
    length_scales_m: Sequence[float] = LENGTH_SCALES_M,
) -> GoodnessCalibration:
    """Fit ``s_i ≈ a_i − b_i·(1 − exp(−d/λ))`` per spot on frames at known positions.

    Goodness falls steeply near a spot and then levels off, so a straight line in
    distance fits badly. ``λ`` is shared by all spots and chosen by least squares
    among ``length_scales_m``; for each ``λ`` every spot's ``a`` and ``b`` are a
    linear least-squares fit, ``b`` is kept >= 0 and ``sigma`` (the residual standard
    deviation) >= ``1e-3``.

    Parameters
    ----------
    spots : array_like
        ``(M, 2)`` training spots ``(x, y)``, metres.
    positions : array_like
        ``(N, 2)`` true positions of the calibration frames (or turns), e.g. at
        :func:`calibration_points`.
    scores : array_like
        ``(N, M)`` raw scores of each frame under each spot's map
        (:func:`~vc_gym.localization.mean_spot_scores`).
    length_scales_m : sequence of float
        The ``λ`` tried, metres, each > 0.

    Returns
    -------
    GoodnessCalibration
        ``(a, b, sigma, length_m)``.

    Raises
    ------
    ValueError
        Arrays of the wrong shape, empty or not finite; no length scale or one <= 0.
    """
    spots = finite_array("spots", spots, (None, 2))
    positions = finite_array("positions", positions, (None, 2))
    n = spots.shape[0]
    scores = finite_array("scores", scores, (positions.shape[0], n))
    lengths = [positive_float("length_scales_m", v) for v in length_scales_m]
    if not lengths:
        raise ValueError("length_scales_m must hold at least one length")
    best = None
    for length in lengths:
        a, b, sigma = np.zeros(n), np.zeros(n), np.zeros(n)
        for i in range(n):
            f = _falloff(np.hypot(*(positions - spots[i]).T), length)
            design = np.stack([np.ones_like(f), -f], axis=1)
            coef, *_ = np.linalg.lstsq(design, scores[:, i], rcond=None)
            a[i], b[i] = coef[0], max(coef[1], 0.0)
            sigma[i] = max(float((scores[:, i] - (a[i] - b[i] * f)).std()), MIN_SIGMA)
        cost = float((sigma**2).sum())
        if best is None or cost < best[0]:
            best = (cost, a, b, sigma, length)
    _, a, b, sigma, length = best
    return GoodnessCalibration(a, b, sigma, length)


def _checked(
    scores: object, spots: object, calibration: object
) -> tuple[np.ndarray, np.ndarray, GoodnessCalibration]:
    spots = finite_array("spots", spots, (None, 2))
    n = spots.shape[0]
    scores = finite_array("scores", scores, (n,))
    try:
        a, b, sigma, length = calibration  # type: ignore[misc]
    except (TypeError, ValueError):
        raise ValueError(
            f"calibration must be a GoodnessCalibration (a, b, sigma, length_m), "
            f"got {type(calibration).__name__}"
        ) from None
    a = finite_array("calibration.a", a, (n,))
    b = finite_array("calibration.b", b, (n,))
    sigma = finite_array("calibration.sigma", sigma, (n,))
    if np.any(sigma <= 0):
        raise ValueError("calibration.sigma must be > 0")
    length = positive_float("calibration.length_m", length)
    return scores, spots, GoodnessCalibration(a, b, sigma, length)


def _log_likelihood(
    scores: np.ndarray, spots: np.ndarray, cal: GoodnessCalibration, positions: np.ndarray
) -> np.ndarray:
    d = np.hypot(
        positions[:, None, 0] - spots[None, :, 0], positions[:, None, 1] - spots[None, :, 1]
    )
    expected = cal.a[None, :] - cal.b[None, :] * _falloff(d, cal.length_m)
    return -0.5 * (((scores[None, :] - expected) / cal.sigma[None, :]) ** 2).sum(axis=1)


def goodness_log_likelihood(
    scores: np.ndarray,
    spots: np.ndarray,
    calibration: GoodnessCalibration,
    positions: np.ndarray,
) -> np.ndarray:
    """``log p(s | x)`` of a score vector at each position, up to a constant.

    ``−½ Σ_i ((s_i − a_i + b_i·(1 − exp(−d_i(x)/λ))) / σ_i)²``: the calibrated
    one-view sensor model, e.g. to weight a particle filter's particles.

    Parameters
    ----------
    scores : array_like
        ``(M,)`` raw score of the frame (or mean over a view's frames) under each
        spot's map.
    spots : array_like
        ``(M, 2)`` training spots ``(x, y)``, metres.
    calibration : GoodnessCalibration
        From :func:`calibrate_goodness` on the same spots.
    positions : array_like
        ``(N, 2)`` positions ``(x, y)`` to evaluate, metres.

    Returns
    -------
    numpy.ndarray
        ``(N,)`` log-likelihoods (0 where every score is exactly as expected).

    Raises
    ------
    ValueError
        Arrays of the wrong shape, empty or not finite; a calibration for another
        number of spots, with ``sigma <= 0`` or ``length_m <= 0``.
    """
    scores, spots, cal = _checked(scores, spots, calibration)
    positions = finite_array("positions", positions, (None, 2))
    return _log_likelihood(scores, spots, cal, positions)


def locate_by_goodness(
    scores: np.ndarray,
    spots: np.ndarray,
    calibration: GoodnessCalibration,
    bounds: Sequence[float],
    grid_step_m: float = GRID_STEP_M,
) -> tuple[np.ndarray, np.ndarray]:
    """Posterior mean and per-axis spread of the position given a score vector.

    The likelihood of :func:`goodness_log_likelihood` with a flat prior, evaluated on
    a grid ``grid_step_m`` apart over the field (its corner at ``(xmin, ymin)``).

    Parameters
    ----------
    scores : array_like
        ``(M,)`` raw score of the frame (or mean over a view's or a turn's frames)
        under each spot's map.
    spots : array_like
        ``(M, 2)`` training spots ``(x, y)``, metres.
    calibration : GoodnessCalibration
        From :func:`calibrate_goodness` on the same spots (and on scores averaged the
        same way).
    bounds : sequence of float
        ``(xmin, xmax, ymin, ymax)`` of the field.
    grid_step_m : float
        Resolution of the grid, metres.

    Returns
    -------
    mean : numpy.ndarray
        ``(2,)`` posterior mean ``(x, y)``.
    std : numpy.ndarray
        ``(2,)`` posterior standard deviation per axis.

    Raises
    ------
    ValueError
        As :func:`goodness_log_likelihood`; bounds not 4 finite numbers with
        ``min < max``; a step that is not > 0.
    """
    scores, spots, cal = _checked(scores, spots, calibration)
    x0, x1, y0, y1 = (float(v) for v in _field_bounds(bounds))
    step = positive_float("grid_step_m", grid_step_m)
    gx = np.arange(x0, x1 + 1e-9, step)
    gy = np.arange(y0, y1 + 1e-9, step)
    xx, yy = np.meshgrid(gx, gy)
    cells = np.stack([xx.ravel(), yy.ravel()], axis=1)
    logl = _log_likelihood(scores, spots, cal, cells)
    w = np.exp(logl - logl.max())
    w /= w.sum()
    mean = w @ cells
    std = np.sqrt(np.maximum(w @ (cells - mean) ** 2, 0.0))
    return mean, std
