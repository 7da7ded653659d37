"""Small argument checks shared by every part of vc_gym."""

from __future__ import annotations

import math

__all__ = ["finite_float"]


def finite_float(name: str, value: object) -> float:
    """``float(value)`` if it is a finite real number, else a ``ValueError`` naming ``name``."""
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v
