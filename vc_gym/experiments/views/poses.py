"""Where the robot is put: a regular grid over the field and random headings (paper 5.1)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from vc_gym.experiments.views.checks import checked_bounds, int_at_least, positions_array
from vc_gym.validation import finite_float, positive_float

__all__ = ["field_grid", "view_poses"]

#: Most positions :func:`field_grid` makes (a guard against a mistyped spacing).
_MAX_GRID_POINTS = 1_000_000


def field_grid(
    bounds: tuple[float, float, float, float], spacing_m: float, margin_m: float = 0.25
) -> np.ndarray:
    """Positions on a regular grid over a field (paper 5.1: ~33 cm; fig. 5 right: 50 cm).

    The grid covers ``bounds`` shrunk by ``margin_m`` on every side, ``spacing_m``
    apart, and is centred in it (the spare length left by the spacing is split
    evenly between both ends of each axis).

    Parameters
    ----------
    bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the field, world metres.
    spacing_m : float
        Distance between neighbouring grid points, > 0.
    margin_m : float
        Distance kept from the field's edges, >= 0; must leave a non-empty area.

    Returns
    -------
    numpy.ndarray
        ``(N, 2)`` float64 positions ``(x, y)``, ordered by ``x`` then ``y``.

    Raises
    ------
    ValueError
        Bounds that are not 4 finite numbers with ``xmin < xmax``, ``ymin < ymax``;
        a non-positive or non-finite spacing; a negative margin or one that leaves no
        area; more than a million points.
    """
    x0, x1, y0, y1 = checked_bounds(bounds)
    spacing = positive_float("spacing_m", spacing_m)
    margin = finite_float("margin_m", margin_m)
    if margin < 0:
        raise ValueError(f"margin_m must be >= 0, got {margin_m!r}")
    axes = []
    for lo, hi, name in ((x0, x1, "x"), (y0, y1, "y")):
        span = (hi - lo) - 2.0 * margin
        if span < 0:
            raise ValueError(
                f"margin_m={margin} leaves nothing of the field's {name} extent {hi - lo:g} m"
            )
        n = int(math.floor(span / spacing + 1e-9)) + 1
        if n > _MAX_GRID_POINTS:
            raise ValueError(f"spacing_m={spacing} gives too many grid points ({n} along {name})")
        start = lo + margin + 0.5 * (span - (n - 1) * spacing)
        axes.append(start + spacing * np.arange(n))
    if axes[0].size * axes[1].size > _MAX_GRID_POINTS:
        raise ValueError(
            f"spacing_m={spacing} gives too many grid points ({axes[0].size * axes[1].size})"
        )
    xx, yy = np.meshgrid(axes[0], axes[1], indexing="ij")
    return np.column_stack([xx.ravel(), yy.ravel()])


def view_poses(
    positions: np.ndarray | Sequence[tuple[float, float]],
    headings_per_position: int,
    rng: np.random.Generator,
) -> np.ndarray:
    """Poses at every position with random headings (the robot placed by hand, 5.1).

    Parameters
    ----------
    positions : array_like
        ``(N, 2)`` positions ``(x, y)``, world metres (e.g. :func:`field_grid`).
    headings_per_position : int
        How many poses per position, >= 1.
    rng : numpy.random.Generator
        Draws the headings, uniform in ``[0, 360)``.

    Returns
    -------
    numpy.ndarray
        ``(N * headings_per_position, 3)`` poses ``(x, y, yaw_deg)``; the poses of one
        position are consecutive.

    Raises
    ------
    ValueError
        Positions not of shape ``(N, 2)`` or not finite, a count that is not an int
        >= 1, or ``rng`` not a Generator.
    """
    p = positions_array(positions)
    k = int_at_least("headings_per_position", headings_per_position, 1)
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    xy = np.repeat(p, k, axis=0)
    yaw = rng.uniform(0.0, 360.0, size=xy.shape[0])
    return np.column_stack([xy, yaw])
