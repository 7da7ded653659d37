"""Argument checks shared by the view modules: field bounds, positions, spots, counts."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["checked_bounds", "int_at_least", "one_spot", "positions_array", "spots_array"]


def checked_bounds(bounds: object, name: str = "bounds") -> tuple[float, float, float, float]:
    """``(xmin, xmax, ymin, ymax)`` as 4 finite floats with ``min < max``, or a ValueError."""
    try:
        vals = tuple(float(v) for v in bounds)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be (xmin, xmax, ymin, ymax), got {bounds!r}") from None
    if len(vals) != 4 or not all(math.isfinite(v) for v in vals):
        raise ValueError(
            f"{name} must be 4 finite numbers (xmin, xmax, ymin, ymax), got {bounds!r}"
        )
    x0, x1, y0, y1 = vals
    if not (x0 < x1 and y0 < y1):
        raise ValueError(f"{name} must have xmin < xmax and ymin < ymax, got {bounds!r}")
    return vals  # type: ignore[return-value]


def int_at_least(name: str, value: object, low: int) -> int:
    """``value`` as an int >= ``low`` (bools refused), or a ValueError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise ValueError(f"{name} must be an int >= {low}, got {value!r}")
    return int(value)


def positions_array(positions: object) -> np.ndarray:
    """``positions`` as a finite ``(N, 2)`` float64 array, or a ValueError."""
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"positions must have shape (N, 2), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("positions must be finite")
    return p


def spots_array(spot: object) -> np.ndarray:
    """One spot ``(x, y)`` or several ``[(x, y), ...]`` as a finite ``(N, 2)`` array."""
    try:
        a = np.asarray(spot, dtype=np.float64)
    except (TypeError, ValueError):
        a = np.zeros(0)
    if a.shape == (2,):
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != 2 or len(a) == 0 or not np.all(np.isfinite(a)):
        raise ValueError(f"spot must be (x, y) or a list of (x, y), got {spot!r}")
    return a


def one_spot(spot: object) -> tuple[float, float]:
    """Exactly one spot ``(x, y)`` as floats, or a ValueError."""
    spots = spots_array(spot)
    if len(spots) != 1:
        raise ValueError(f"spot must be (x, y), got {spot!r}")
    return float(spots[0, 0]), float(spots[0, 1])
