"""Small argument checks shared by every part of vc_gym."""

from __future__ import annotations

import math
import numbers

__all__ = ["finite_float", "nonnegative_float", "positive_float"]


def finite_float(name: str, value: object) -> float:
    """``float(value)`` if it is a finite real number, else a ``ValueError`` naming ``name``."""
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v


def _real(name: str, value: object) -> float:
    # Strings and bools are refused: a config field given "0.5" or True is a mistake.
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be a real number, got {value!r}")
    return float(value)


def positive_float(name: str, value: object) -> float:
    """``float(value)`` if it is a finite real number > 0, else a ``ValueError``."""
    v = _real(name, value)
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return v


def nonnegative_float(name: str, value: object) -> float:
    """``float(value)`` if it is a finite real number >= 0, else a ``ValueError``."""
    v = _real(name, value)
    if not (math.isfinite(v) and v >= 0):
        raise ValueError(f"{name} must be finite and >= 0, got {value!r}")
    return v
