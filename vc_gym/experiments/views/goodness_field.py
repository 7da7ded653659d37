"""The normalised goodness of one spot's map over the field (paper fig. 5 right)."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from vc_gym.experiments.views.checks import checked_bounds, one_spot, positions_array
from vc_gym.experiments.views.top_view import field_axes
from vc_gym.jobs.output import new_figure, save_figure

__all__ = ["plot_goodness_field"]


def plot_goodness_field(
    path: str | os.PathLike,
    positions: np.ndarray,
    goodness: Sequence[float] | np.ndarray,
    spot: tuple[float, float],
    field_bounds: tuple[float, float, float, float],
) -> None:
    """The normalised goodness ``L̂`` of one spot over a grid of positions (fig. 5 right).

    Values at equal positions (several headings) are averaged. A regular grid (e.g.
    :func:`field_grid`) is drawn as a heat map with the value written in each cell,
    other positions as coloured squares.

    Parameters
    ----------
    path : path-like
        PNG to write (atomically).
    positions : numpy.ndarray
        ``(N, 2)`` positions ``(x, y)``.
    goodness : array_like
        ``(N,)`` goodness of the spot at each position (:func:`spot_goodness`).
    spot : tuple of float
        The training spot (marked with a star).
    field_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the field (drawn as its outline).
    """
    p = positions_array(positions)
    g = np.asarray(goodness, dtype=np.float64)
    if g.shape != (p.shape[0],) or not np.all(np.isfinite(g)):
        raise ValueError(f"goodness must be {p.shape[0]} finite numbers")
    if p.shape[0] == 0:
        raise ValueError("positions must not be empty")
    sx, sy = one_spot(spot)
    bounds = checked_bounds(field_bounds, "field_bounds")
    key = np.round(p, 6)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    mean = np.bincount(inverse, weights=g) / np.bincount(inverse)
    xs, ys = np.unique(uniq[:, 0]), np.unique(uniq[:, 1])
    fig = new_figure(figsize=(8, 6))
    ax = fig.subplots()
    regular = xs.size * ys.size == uniq.shape[0] and xs.size > 1 and ys.size > 1
    if regular:
        grid = np.full((ys.size, xs.size), np.nan)
        grid[np.searchsorted(ys, uniq[:, 1]), np.searchsorted(xs, uniq[:, 0])] = mean

        def edges(c: np.ndarray) -> np.ndarray:
            mid = 0.5 * (c[1:] + c[:-1])
            return np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])

        im = ax.pcolormesh(edges(xs), edges(ys), grid, cmap="magma", shading="flat")
        if uniq.shape[0] <= 400:
            mid = 0.5 * (np.nanmin(grid) + np.nanmax(grid))
            for (x, y), v in zip(uniq, mean, strict=True):
                ax.text(
                    x,
                    y,
                    f"{v:.2f}",
                    ha="center",
                    va="center",
                    fontsize=6,
                    color="k" if v > mid else "w",
                )
    else:
        im = ax.scatter(uniq[:, 0], uniq[:, 1], c=mean, cmap="magma", marker="s", s=60)
    field_axes(ax, bounds)
    fig.colorbar(im, ax=ax, label="normalised goodness L̂ (eq. 28)", shrink=0.8)
    ax.plot([sx], [sy], marker="*", ms=16, c="cyan", mec="k", ls="none", label="training spot")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title("goodness of the spot's map over the field (paper fig. 5 right)")
    fig.tight_layout()
    save_figure(fig, path)
