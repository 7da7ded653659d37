"""Angle helpers shared by every part of vc_gym.

All angles are in degrees, counter-clockwise positive seen from above. Differences
are wrapped with :func:`wrap180`; angles are never averaged arithmetically
(:func:`circular_mean` uses ``atan2(sum sin, sum cos)``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "MIN_HEADING_STEP_DEG",
    "steps_in_circle",
    "wrap180",
    "wrap360",
    "wrap_pi",
    "circular_mean",
    "circular_std",
    "circular_std_rows",
    "interp_circular",
    "peak_headings",
]


#: The finest heading grid any sensor takes (36,000 headings): a config, perhaps read
#: from a file, cannot make it allocate more.
MIN_HEADING_STEP_DEG = 0.01


def steps_in_circle(step_deg: float) -> int | None:
    """How many steps of ``step_deg`` make the full circle, or None if they do not
    (``step_deg`` must divide 360 to within 1e-6 of a step).

    Raises
    ------
    ValueError
        If ``step_deg`` is not a finite number > 0.
    """
    if isinstance(step_deg, bool) or not isinstance(step_deg, (int, float, np.number)):
        raise ValueError(f"step_deg must be a number, got {step_deg!r}")
    if not (math.isfinite(step_deg) and step_deg > 0):
        raise ValueError(f"step_deg must be finite and > 0, got {step_deg!r}")
    n = 360.0 / step_deg
    return int(round(n)) if abs(n - round(n)) <= 1e-6 else None


def wrap180(angle_deg: ArrayLike) -> np.ndarray | float:
    """Wrap angles to the half-open interval ``[-180, 180)`` degrees.

    Parameters
    ----------
    angle_deg : array_like
        Angle(s) in degrees.

    Returns
    -------
    float or numpy.ndarray
        The wrapped angle(s); a Python float for scalar input.
    """
    a = np.asarray(angle_deg, dtype=float)
    out = np.mod(a + 180.0, 360.0) - 180.0
    # mod of a tiny negative number can round up to exactly 360 -> 180; keep [-180, 180)
    out = np.where(out >= 180.0, out - 360.0, out)
    return float(out) if out.ndim == 0 else out


def wrap_pi(angle_rad: ArrayLike) -> np.ndarray | float:
    """Wrap angles in radians to ``[-pi, pi)`` (:func:`wrap180` for radians, for the
    hot paths that work in radians)."""
    a = np.asarray(angle_rad, dtype=float)
    out = np.mod(a + np.pi, 2.0 * np.pi) - np.pi
    out = np.where(out >= np.pi, out - 2.0 * np.pi, out)
    return float(out) if out.ndim == 0 else out


def wrap360(angle_deg: ArrayLike) -> np.ndarray | float:
    """Wrap angles to the half-open interval ``[0, 360)`` degrees."""
    a = np.asarray(angle_deg, dtype=float)
    out = np.mod(a, 360.0)
    out = np.where(out >= 360.0, out - 360.0, out)
    return float(out) if out.ndim == 0 else out


def _weights(angles: np.ndarray, weights: ArrayLike | None) -> np.ndarray:
    if weights is None:
        return np.ones_like(angles)
    w = np.asarray(weights, dtype=float)
    if w.shape != angles.shape:
        raise ValueError(f"weights shape {w.shape} does not match angles shape {angles.shape}")
    if not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ValueError("weights must be finite and non-negative")
    if w.sum() <= 0:
        raise ValueError("weights must not all be zero")
    return w


def circular_mean(angle_deg: ArrayLike, weights: ArrayLike | None = None) -> float:
    """Weighted circular mean, ``atan2(sum w sin, sum w cos)``, in ``[0, 360)`` degrees.

    This is the estimate of paper eq. 26 for a belief over headings.
    """
    a = np.radians(np.asarray(angle_deg, dtype=float))
    if a.size == 0:
        raise ValueError("circular_mean needs at least one angle")
    w = _weights(a, weights)
    return float(wrap360(np.degrees(np.arctan2(np.sum(w * np.sin(a)), np.sum(w * np.cos(a))))))


def circular_std(angle_deg: ArrayLike, weights: ArrayLike | None = None) -> float:
    """Weighted circular standard deviation ``sqrt(-2 ln R)`` in degrees (paper eq. 27).

    ``R`` is the mean resultant length. For concentrated distributions this equals
    the ordinary standard deviation; for a uniform one it is infinite.
    """
    a = np.radians(np.asarray(angle_deg, dtype=float))
    if a.size == 0:
        raise ValueError("circular_std needs at least one angle")
    w = _weights(a, weights)
    r = np.hypot(np.sum(w * np.sin(a)), np.sum(w * np.cos(a))) / np.sum(w)
    return _std_from_resultant(float(r))


def circular_std_rows(angle_deg: ArrayLike, weights: ArrayLike) -> np.ndarray:
    """:func:`circular_std` of each row of ``weights`` over the same angles, at once.

    ``angle_deg`` is ``(N,)`` and ``weights`` ``(M, N)``; the result ``(M,)`` equals
    calling :func:`circular_std` on every row, bit for bit.
    """
    a = np.radians(np.asarray(angle_deg, dtype=float))
    w = np.asarray(weights, dtype=float)
    if a.ndim != 1 or a.size == 0 or w.ndim != 2 or w.shape[1] != a.size:
        raise ValueError(
            f"circular_std_rows needs (N,) angles and (M, N) weights, got {a.shape} and {w.shape}"
        )
    if not np.all(np.isfinite(w)) or np.any(w < 0) or np.any(w.sum(axis=1) <= 0):
        raise ValueError("weights must be finite, non-negative and not all zero in a row")
    r = np.hypot((w * np.sin(a)).sum(axis=1), (w * np.cos(a)).sum(axis=1)) / w.sum(axis=1)
    return np.array([_std_from_resultant(float(v)) for v in r])


def peak_headings(log_likelihoods: ArrayLike, step_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Best heading of each row of a log-likelihood on a circular grid, refined.

    The arg-max of each row, moved by the vertex of the parabola through it and its two
    neighbours (at most half a step; not moved where the three do not curve down).

    Parameters
    ----------
    log_likelihoods : array_like
        ``(M, N)`` log-likelihoods at ``0, step, ..., (N - 1) step`` degrees.
    step_deg : float
        Grid step in degrees.

    Returns
    -------
    headings : numpy.ndarray
        ``(M,)`` refined best headings in ``[0, 360)``.
    best : numpy.ndarray
        ``(M,)`` index of each row's grid maximum.
    """
    lls = np.asarray(log_likelihoods, dtype=np.float64)
    if lls.ndim != 2 or lls.shape[1] == 0:
        raise ValueError(f"peak_headings needs (M, N) log-likelihoods, got shape {lls.shape}")
    m, n = lls.shape
    rows = np.arange(m)
    best = np.argmax(lls, axis=1)
    y0, y1, y2 = lls[rows, (best - 1) % n], lls[rows, best], lls[rows, (best + 1) % n]
    with np.errstate(invalid="ignore"):  # -inf neighbours: no refinement
        denom = y0 - 2.0 * y1 + y2
        peaked = np.isfinite(denom) & (denom < 0)
    frac = np.zeros(m)
    frac[peaked] = 0.5 * (y0[peaked] - y2[peaked]) / denom[peaked]
    heading = np.mod(best * step_deg + np.clip(frac, -0.5, 0.5) * step_deg, 360.0)
    return heading, best


def _std_from_resultant(r: float) -> float:
    """``sqrt(-2 ln R)`` in degrees (infinite for ``R = 0``; ``R`` capped at 1)."""
    r = min(r, 1.0)
    if r <= 0.0:
        return float("inf")
    return float(np.degrees(np.sqrt(max(-2.0 * math.log(r), 0.0))))


def interp_circular(values: np.ndarray, step_deg: float, query_deg: ArrayLike) -> np.ndarray:
    """Linear interpolation of a function sampled on a circular grid of headings.

    ``values[k]`` is the value at ``k * step_deg``; queries wrap around 360°. Exact
    where a query falls on the grid; a ``-inf`` neighbour gives ``-inf`` (a
    log-likelihood that rules a heading out stays ruled out).

    Parameters
    ----------
    values : numpy.ndarray
        ``(n,)`` samples at ``0, step, ..., (n - 1) step`` degrees, or ``(..., n)``: one
        such function per row, all interpolated at the same queries.
    step_deg : float
        Grid step in degrees (``n * step_deg == 360``).
    query_deg : array_like
        Angles to evaluate, any real values (wrapped).

    Returns
    -------
    numpy.ndarray
        Interpolated values, shaped like ``query_deg`` (``values.shape[:-1] +
        query_deg.shape`` for several rows).
    """
    n = values.shape[-1]
    pos = np.mod(np.asarray(query_deg, dtype=np.float64), 360.0) / step_deg
    i0 = np.floor(pos).astype(np.int64)
    frac = pos - i0
    a = values[..., i0 % n]
    b = values[..., (i0 + 1) % n]
    with np.errstate(invalid="ignore"):
        return np.where(frac == 0.0, a, (1.0 - frac) * a + frac * b)
