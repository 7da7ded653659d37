"""Heading error against the distance from the training spot (paper 5.1, fig. 4 right):
the table per distance bin and its plot, next to the paper's claim."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.validation import finite_float, positive_float

__all__ = ["PAPER_ERROR_DEG", "PAPER_RANGE_M", "distance_table", "plot_error_vs_distance"]

#: The paper's claim (5.1): the mean heading error stays below 10° ...
PAPER_ERROR_DEG = 10.0
#: ... within 2 m of the training spot.
PAPER_RANGE_M = 2.0


def distance_table(
    distances: Sequence[float] | np.ndarray,
    errors: Sequence[float] | np.ndarray,
    spreads: Sequence[float] | np.ndarray,
    bin_m: float = 0.5,
) -> list[dict[str, float]]:
    """Heading error and spread per distance from the training spot (fig. 4 right).

    Bin ``k`` holds the views with ``k · bin_m <= distance < (k + 1) · bin_m``; only
    bins with views are listed.

    Parameters
    ----------
    distances : array_like
        Distance of each view from the training spot, metres, >= 0.
    errors : array_like
        Signed heading error of each view, degrees (wrapped to ±180° here).
    spreads : array_like
        Reported heading spread of each view, degrees.
    bin_m : float
        Width of a distance bin.

    Returns
    -------
    list of dict
        Per non-empty bin, in order of distance: ``bin_start_m``, ``bin_end_m``,
        ``distance_m`` (mean distance of its views), ``n``, ``mean_abs_error_deg``,
        ``median_abs_error_deg``, ``mean_spread_deg`` (plain numbers).

    Raises
    ------
    ValueError
        Arrays that are not 1-D of one length or not finite, negative distances, or a
        bad ``bin_m``.
    """
    d = np.asarray(distances, dtype=np.float64)
    e = np.asarray(errors, dtype=np.float64)
    s = np.asarray(spreads, dtype=np.float64)
    if d.ndim != 1 or e.shape != d.shape or s.shape != d.shape:
        raise ValueError(
            f"distances, errors and spreads must be 1-D of one length, got shapes "
            f"{d.shape}, {e.shape}, {s.shape}"
        )
    for name, a in (("distances", d), ("errors", e), ("spreads", s)):
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be finite")
    if np.any(d < 0):
        raise ValueError("distances must be >= 0")
    width = positive_float("bin_m", bin_m)
    abs_err = np.abs(np.asarray(wrap180(e), dtype=np.float64))
    index = np.floor(d / width).astype(np.int64)
    rows = []
    for k in np.unique(index):
        sel = index == k
        rows.append(
            {
                "bin_start_m": float(k * width),
                "bin_end_m": float((k + 1) * width),
                "distance_m": float(d[sel].mean()),
                "n": int(sel.sum()),
                "mean_abs_error_deg": float(abs_err[sel].mean()),
                "median_abs_error_deg": float(np.median(abs_err[sel])),
                "mean_spread_deg": float(s[sel].mean()),
            }
        )
    return rows


def plot_error_vs_distance(
    path: str | os.PathLike,
    table_by_tracker: Mapping[str, Sequence[Mapping[str, float]]],
    paper_line_deg: float = PAPER_ERROR_DEG,
) -> None:
    """Mean |heading error| and mean spread vs distance from the spot (fig. 4 right).

    One line per tracker in each of two panels (error left, spread right), plotted at
    each bin's mean distance. Dashed lines mark the paper's claim (5.1): the mean error
    stays below ``paper_line_deg`` (10°) within :data:`PAPER_RANGE_M` (2 m).

    Parameters
    ----------
    path : path-like
        PNG to write (atomically).
    table_by_tracker : mapping
        ``{tracker name: distance_table(...)}``.
    paper_line_deg : float
        Height of the paper's error line.
    """
    if not isinstance(table_by_tracker, Mapping) or not table_by_tracker:
        raise ValueError("table_by_tracker must be a non-empty {name: distance table} mapping")
    line = finite_float("paper_line_deg", paper_line_deg)
    fig = new_figure(figsize=(11, 4.2))
    ax_e, ax_s = fig.subplots(1, 2, sharex=True)
    for name, rows in table_by_tracker.items():
        if not rows:
            continue
        dist = [r["distance_m"] for r in rows]
        ax_e.plot(dist, [r["mean_abs_error_deg"] for r in rows], "o-", label=str(name))
        ax_s.plot(dist, [r["mean_spread_deg"] for r in rows], "o-", label=str(name))
    ax_e.axhline(line, ls="--", c="k", lw=1, label=f"paper: < {line:g}° within {PAPER_RANGE_M:g} m")
    for ax in (ax_e, ax_s):
        ax.axvline(PAPER_RANGE_M, ls="--", c="0.4", lw=1)
        ax.set_xlabel("distance from the training spot (m)")
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
    ax_e.set_ylabel("mean |heading error| (deg)")
    ax_s.set_ylabel("mean heading spread (deg)")
    ax_e.set_title("heading error vs distance")
    ax_s.set_title("reported spread vs distance")
    ax_e.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)
