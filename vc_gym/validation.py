"""Small argument checks shared by every part of vc_gym."""

from __future__ import annotations

import math
import numbers

import numpy as np

__all__ = [
    "MAX_ABS_DEG",
    "MAX_ABS_METRES",
    "finite_float",
    "finite_real",
    "flag",
    "int_at_least",
    "nonnegative_float",
    "positive_float",
]

#: Largest magnitude of a length (metres) a filter or env takes in one input: a step
#: of a million metres is a units mistake, and far beyond it sums overflow.
MAX_ABS_METRES = 1e6
#: Largest magnitude of an angle (degrees) taken in one input: float64 still holds it
#: to a millionth of a degree, and squares of it do not overflow.
MAX_ABS_DEG = 1e9


def finite_float(name: str, value: object) -> float:
    """``float(value)`` if it is a finite real number, else a ``ValueError`` naming ``name``."""
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v


def finite_real(name: str, value: object) -> float:
    """``float(value)`` for a finite real number; strings and bools are refused (a
    setting given ``"56.9"`` or ``True`` is a mistake, not a number)."""
    v = _real(name, value)
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


def flag(name: str, value: object) -> bool:
    """``bool(value)`` for ``True`` or ``False`` (numpy's too), else a ``ValueError``:
    a switch given ``1`` or ``"yes"`` is a mistake."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def int_at_least(name: str, value: object, minimum: int) -> int:
    """``int(value)`` if it is an integer >= ``minimum``, else a ``ValueError``.

    Parameters
    ----------
    name : str
        Name of the argument, used in the error message.
    value : object
        The value to check. Python and numpy integers are accepted; bools, floats
        (even ``2.0``) and strings are refused.
    minimum : int
        Smallest allowed value.

    Returns
    -------
    int
        ``value`` as a Python ``int``.

    Raises
    ------
    ValueError
        If ``value`` is not an integer or is below ``minimum``.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    v = int(value)
    if v < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {v}")
    return v
