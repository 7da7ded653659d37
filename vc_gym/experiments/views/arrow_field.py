"""An arrow per view in its estimated heading, coloured by its error (paper fig. 4 left)."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
from matplotlib.patches import Circle

from vc_gym.angles import wrap180
from vc_gym.experiments.views.checks import checked_bounds, spots_array
from vc_gym.experiments.views.error_vs_distance import PAPER_ERROR_DEG, PAPER_RANGE_M
from vc_gym.experiments.views.top_view import field_axes
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.validation import finite_float

__all__ = ["plot_arrow_field"]


def plot_arrow_field(
    path: str | os.PathLike,
    poses: np.ndarray,
    estimated_headings: Sequence[float] | np.ndarray,
    spot: tuple[float, float],
    field_bounds: tuple[float, float, float, float],
    title: str,
    reference_deg: float | None = None,
) -> None:
    """An arrow per view in the estimated heading, coloured by its error (fig. 4 left).

    Parameters
    ----------
    path : path-like
        PNG to write (atomically).
    poses : numpy.ndarray
        ``(N, 3)`` true poses ``(x, y, yaw_deg)`` of the views.
    estimated_headings : array_like
        ``(N,)`` estimated body headings, degrees.
    spot : tuple of float or sequence of them
        The training spot ``(x, y)`` (marked with a star, with the paper's 2 m circle),
        or several spots (marked with stars).
    field_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the field (drawn as its outline).
    title : str
        Figure title.
    reference_deg : float, optional
        Draw each arrow at ``reference_deg + error`` instead of the estimate: as if
        every robot had faced ``reference_deg``, so right estimates all point one way
        (the paper's figure: every arrow towards the opponent goal).
    """
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or not np.all(np.isfinite(p)):
        raise ValueError(f"poses must be a finite (N, 3) array, got shape {p.shape}")
    est = np.asarray(estimated_headings, dtype=np.float64)
    if est.shape != (p.shape[0],) or not np.all(np.isfinite(est)):
        raise ValueError(f"estimated_headings must be {p.shape[0]} finite numbers")
    spots = spots_array(spot)
    bounds = checked_bounds(field_bounds, "field_bounds")
    err = np.asarray(wrap180(est - p[:, 2]), dtype=np.float64)
    if reference_deg is None:
        direction = est
    else:
        direction = finite_float("reference_deg", reference_deg) + err
    th = np.radians(direction)
    fig = new_figure(figsize=(8, 6))
    ax = fig.subplots()
    field_axes(ax, bounds)
    length = 0.25
    q = ax.quiver(
        p[:, 0],
        p[:, 1],
        length * np.cos(th),
        length * np.sin(th),
        np.abs(err),
        cmap="viridis_r",
        clim=(0.0, 90.0),
        angles="xy",
        scale_units="xy",
        scale=1.0,
        width=0.004,
        pivot="tail",
    )
    fig.colorbar(q, ax=ax, label="|heading error| (deg, clipped at 90)", shrink=0.8)
    ax.plot(
        spots[:, 0],
        spots[:, 1],
        marker="*",
        ms=16 if len(spots) == 1 else 11,
        c="red",
        mec="k",
        ls="none",
        label="training spot" if len(spots) == 1 else "training spots",
    )
    if len(spots) == 1:
        ax.add_patch(
            Circle(
                tuple(spots[0]),
                PAPER_RANGE_M,
                fill=False,
                ls=":",
                ec="red",
                lw=1,
                label=f"{PAPER_RANGE_M:g} m (paper: error < {PAPER_ERROR_DEG:g}° inside)",
            )
        )
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(str(title))
    fig.tight_layout()
    save_figure(fig, path)
