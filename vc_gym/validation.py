"""Small argument checks shared by every part of vc_gym."""

from __future__ import annotations

import math
import numbers
from collections.abc import Collection, Mapping
from typing import Any

import numpy as np

__all__ = [
    "MAX_ABS_DEG",
    "MAX_ABS_METRES",
    "MAX_EPISODES",
    "MAX_HALF_LIFE_S",
    "MAX_HOMING_S",
    "MAX_LEARNING_PHASE_S",
    "MAX_LEARN_TIME_S",
    "MAX_SEED",
    "MAX_SEEDS",
    "check_action",
    "check_reset_options",
    "check_seed",
    "finite_float",
    "finite_real",
    "flag",
    "head_pans",
    "int_at_least",
    "int_in_range",
    "nonnegative_float",
    "nonnegative_float_at_most",
    "positive_float",
    "positive_float_at_most",
]

#: Largest magnitude of a length (metres) a filter or env takes in one input: a step
#: of a million metres is a units mistake, and far beyond it sums overflow.
MAX_ABS_METRES = 1e6
#: Largest magnitude of an angle (degrees) taken in one input: float64 still holds it
#: to a millionth of a degree, and squares of it do not overflow.
MAX_ABS_DEG = 1e9
#: Largest seed taken (numpy's classic 32-bit seed range). Seeds derived from one
#: (``seed + 1 + episode``) stay far inside 64 bits.
MAX_SEED = 2**32 - 1
#: Most episodes (kidnappings) per learning seed one command runs: 300 times the
#: paper's 33, about a week of simulated homing on one core.
MAX_EPISODES = 10_000
#: Most learning seeds (or training seeds) one command takes.
MAX_SEEDS = 1_000
#: Longest learning time per direction (s; ``learn_time_s``): 12 times the paper's 5 s;
#: the scripted learning of 4 spots x 8 directions then takes 32 simulated minutes.
MAX_LEARN_TIME_S = 60.0
#: Longest homing time limit (s; ``max_homing_s``): an hour, 60 times the paper's
#: minute. It also bounds the task's ``stop_time_s`` and ``vc_gym/Homing-v0``'s
#: ``min_walk_s``: a stop, or a walk before stops count, longer than the longest homing
#: could never end an episode.
MAX_HOMING_S = 3600.0
#: Longest learning phase of an agent that learns the place itself (s;
#: ``max_learning_s`` with ``learning="agent"``): an hour, as long as the longest
#: homing and 12 times the default 300 s.
MAX_LEARNING_PHASE_S = 3600.0
#: Longest mixing half-life (s) of the heading filter of the scripted learning phase
#: (``LearningConfig.half_life_s``): 200 times the paper's 0.3 s and as long as the
#: longest learning time per direction; at a 0.1 s step the filter then replaces 0.1 %
#: of its belief a step, which is no mixing to speak of.
MAX_HALF_LIFE_S = 60.0


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


def head_pans(name: str, value: object) -> tuple[float, ...]:
    """``value`` as a non-empty tuple of head pans within ±90° (degrees), else a
    ``ValueError``."""
    try:
        pans = tuple(float(p) for p in value)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        pans = ()
    if not pans or not all(abs(p) <= 90 for p in pans):
        raise ValueError(f"{name} must be non-empty pans within ±90°, got {value!r}")
    return pans


def open_fraction(name: str, value: object) -> float:
    """``float(value)`` if it is a real number in ``(0, 1)`` (a probability that must
    be neither impossible nor certain), else a ``ValueError``."""
    v = positive_float(name, value)
    if v >= 1.0:
        raise ValueError(f"{name} must be in (0, 1), got {value!r}")
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


def int_in_range(name: str, value: object, minimum: int, maximum: int) -> int:
    """``int(value)`` if it is an integer in ``[minimum, maximum]``, else a ``ValueError``.

    Parameters
    ----------
    name : str
        Name of the argument, used in the error message (e.g. ``"--workers"``).
    value : object
        The value to check. Python and numpy integers are accepted; bools, floats
        (even ``2.0``) and strings are refused.
    minimum, maximum : int
        Smallest and largest allowed value.

    Returns
    -------
    int
        ``value`` as a Python ``int``.

    Raises
    ------
    ValueError
        If ``value`` is not an integer or lies outside the range; the message names
        ``name`` and the range.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be an integer in {minimum}..{maximum}, got {value!r}")
    v = int(value)
    if not minimum <= v <= maximum:
        raise ValueError(f"{name} must be in {minimum}..{maximum}, got {v}")
    return v


def check_seed(name: str, value: object) -> int:
    """A seed: an integer in ``0..MAX_SEED`` (:func:`int_in_range`)."""
    return int_in_range(name, value, 0, MAX_SEED)


def check_action(action: object, shape: tuple[int, ...], name: str = "action") -> np.ndarray:
    """An action as a ``float64`` array, if it is a finite real numeric array of ``shape``.

    Integer and floating arrays (and lists of numbers) are accepted. Anything else is
    refused before it is cast: a complex array would lose its imaginary part, strings
    would be parsed as numbers, and a dict or an object array would raise a bare
    ``TypeError`` deep inside numpy.

    Parameters
    ----------
    action : array-like
        The action given to ``step``.
    shape : tuple of int
        The action space's shape.
    name : str
        Name used in the error message.

    Returns
    -------
    numpy.ndarray
        The action as a new ``float64`` array of ``shape``.

    Raises
    ------
    ValueError
        Naming the expected shape and dtype: for a non-numeric, complex or bool value,
        another shape, or a NaN or infinite entry.
    """
    expected = f"a real numeric array (int or float dtype) of shape {tuple(shape)}"
    if isinstance(action, (str, bytes, Mapping)):
        raise ValueError(f"{name} must be {expected}, got {type(action).__name__}")
    try:
        a = np.asarray(action)
    except (TypeError, ValueError) as exc:  # ragged nested sequences, odd objects
        raise ValueError(f"{name} must be {expected}, got {action!r:.80} ({exc})") from None
    if a.dtype.kind not in "iuf":
        raise ValueError(f"{name} must be {expected}, got dtype {a.dtype} ({action!r:.80})")
    if a.shape != tuple(shape):
        raise ValueError(f"{name} must be {expected}, got shape {a.shape}")
    a = a.astype(np.float64)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite, got {action!r:.200}")
    return a


def check_reset_options(options: object, known: Collection[str]) -> dict[str, Any]:
    """``reset``'s ``options`` as a new dict: ``None`` or a mapping of known keys.

    Parameters
    ----------
    options : mapping or None
        The ``options`` given to ``reset``.
    known : collection of str
        The option names the env takes.

    Returns
    -------
    dict
        A copy of ``options`` (empty for ``None``).

    Raises
    ------
    ValueError
        For anything but a mapping or ``None``, and for keys not in ``known``.
    """
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise ValueError(
            f"reset options must be a dict (or None), got {type(options).__name__}: {options!r:.80}"
        )
    unknown = [k for k in options if k not in known]
    if unknown:
        raise ValueError(
            f"unknown reset options {sorted(map(str, unknown))}; known: {sorted(known)}"
        )
    return dict(options)


def positive_float_at_most(name: str, value: object, maximum: float, unit: str = "") -> float:
    """``float(value)`` for a finite real number in ``(0, maximum]``, else a
    ``ValueError`` naming ``name`` and the range (strings and bools are refused).

    ``unit`` (e.g. ``"seconds"``) follows the range in the message:
    ``"learn_time_s must be in (0, 60] seconds, got 1000.0"``."""
    v = positive_float(name, value)
    if v > maximum:
        raise ValueError(f"{name} must be in (0, {maximum:g}]{_unit(unit)}, got {value!r}")
    return v


def nonnegative_float_at_most(name: str, value: object, maximum: float, unit: str = "") -> float:
    """``float(value)`` for a finite real number in ``[0, maximum]``, else a
    ``ValueError`` naming ``name`` and the range (strings and bools are refused);
    ``unit`` as for :func:`positive_float_at_most`."""
    v = nonnegative_float(name, value)
    if v > maximum:
        raise ValueError(f"{name} must be in [0, {maximum:g}]{_unit(unit)}, got {value!r}")
    return v


def _unit(unit: str) -> str:
    return f" {unit}" if unit else ""
