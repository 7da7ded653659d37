"""The translational filter of the paper (3.6.2, eq. 30-32).

The belief is a direct position estimate ``τ̂``. The motion update adds the odometry
translation (eq. 31), the sensor update mixes in the likelihood-weighted mean of the
training spots (eq. 30) with the same mixing constant as the heading filter (eq. 32).
It works on per-spot goodness values from any source (the compass atlas, a baseline,
a test double).
"""

from __future__ import annotations

import math

import numpy as np

from vc_gym.filters.heading_grid import mixing_lambda
from vc_gym.validation import MAX_ABS_METRES

__all__ = ["MAX_GOODNESS", "TranslationalFilter", "weighted_spot_position"]

#: Largest goodness value ``L_i`` (a likelihood ratio, about 1 at home) eq. 30 takes:
#: a million is far beyond any spot's fit, and sums of values near float64's limit
#: overflow to inf.
MAX_GOODNESS = 1e6


def _vector(
    name: str, value: object, n: int, limit: float = MAX_ABS_METRES, unit: str = " m"
) -> np.ndarray:
    """``value`` as ``n`` finite float64 numbers within ``±limit`` (``unit`` in the
    message), else a ``ValueError`` naming ``name``."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be {n} real numbers, got {value!r}") from None
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be {n} finite numbers, got {value!r}")
    if np.any(np.abs(a) > limit):  # sums of such values overflow to inf
        raise ValueError(f"{name} must be within ±{limit:g}{unit}, got {value!r}")
    return a


def weighted_spot_position(spots: np.ndarray, goodness: np.ndarray) -> np.ndarray:
    """Eq. 30: ``τ̂ = Σ L_i T_i / Σ L_i``.

    Parameters
    ----------
    spots : numpy.ndarray
        ``(q, 2)`` training spot positions ``T_i``.
    goodness : numpy.ndarray
        ``(q,)`` goodness values ``L_i`` (normalised at home) in
        ``[0, MAX_GOODNESS]``.

    Raises
    ------
    ValueError
        On negative, too large, non-finite or all-zero goodness, or mismatched shapes.
    """
    spots = np.asarray(spots, dtype=np.float64)
    q = spots.shape[0]
    g = _vector("goodness", goodness, q, MAX_GOODNESS, unit="")
    if np.any(g < 0) or g.sum() <= 0:
        raise ValueError(
            f"goodness must be in [0, {MAX_GOODNESS:g}] and not all zero, got {goodness!r}"
        )
    return (g / g.sum()) @ spots


class TranslationalFilter:
    """Position estimate from per-spot goodness values (paper eq. 30-32).

    Parameters
    ----------
    spots : array_like
        ``(q, 2)`` world positions of the training spots ``T_i`` (metres).
    half_life_s : float
        Half of the estimate is replaced by sensor readings after this time
        (paper 4.2: the same λ as the orientational filter, 0.3 s).
    dt_s : float
        Default time between updates.
    start : tuple of float, optional
        Initial estimate (default: the centroid of the spots).
    """

    def __init__(
        self,
        spots: np.ndarray,
        half_life_s: float = 0.3,
        dt_s: float = 1.0 / 30.0,
        start: tuple[float, float] | None = None,
    ):
        s = np.asarray(spots, dtype=np.float64)
        if s.ndim != 2 or s.shape[1] != 2 or s.shape[0] < 1 or not np.all(np.isfinite(s)):
            raise ValueError(f"spots must be a finite (q, 2) array, got shape {s.shape}")
        if np.any(np.abs(s) > MAX_ABS_METRES):
            raise ValueError(f"spots must lie within ±{MAX_ABS_METRES:g} m, got {spots!r}")
        mixing_lambda(half_life_s, dt_s)  # validates
        self.spots = s.copy()
        self.spots.setflags(write=False)
        self.half_life_s = float(half_life_s)
        self.dt_s = float(dt_s)
        self._tau = np.zeros(2)
        self.reset(start)

    @property
    def position(self) -> tuple[float, float]:
        """The current estimate ``τ̂`` as ``(x, y)``."""
        return float(self._tau[0]), float(self._tau[1])

    def reset(self, start: tuple[float, float] | None = None) -> None:
        """Restart at ``start`` (default: the centroid of the spots)."""
        self._tau = (
            self.spots.mean(axis=0).copy() if start is None else _vector("start", start, 2).copy()
        )

    def predict(self, dx: float, dy: float) -> None:
        """Motion update (eq. 31): add the odometry translation in world coordinates."""
        d = _vector("odometry (dx, dy)", (dx, dy), 2)
        self._tau = self._tau + d

    def update(self, goodness: np.ndarray, dt_s: float | None = None) -> tuple[float, float]:
        """Sensor update (eq. 32) from per-spot goodness values; returns the new estimate."""
        measured = weighted_spot_position(self.spots, goodness)
        return self.update_position(measured, dt_s)

    def update_position(
        self, measured: tuple[float, float] | np.ndarray, dt_s: float | None = None
    ) -> tuple[float, float]:
        """Sensor update from a position reading ``τ̂(z)`` already computed (eq. 32)."""
        m = _vector("measured position", measured, 2)
        dt = self.dt_s if dt_s is None else dt_s
        lam = mixing_lambda(self.half_life_s, dt)
        self._tau = lam * m + (1.0 - lam) * self._tau
        return self.position

    def distance_to(self, point: tuple[float, float]) -> float:
        """Euclidean distance from the estimate to ``point``."""
        p = _vector("point", point, 2)
        return float(math.hypot(*(self._tau - p)))
