"""The tracking experiment's plots: the heading and position errors against time, a
curve per route with its kidnapping marked (:func:`plot_errors`), and one route's true
and believed paths on the scene's top view with ±2σ ellipses and a particle tracker's
particles at a few moments (:func:`plot_belief`, the moments from
:func:`snapshot_times`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from vc_gym.experiments.studies.tracking.figures import (
    RELOCALISED_HEADING_DEG,
    RELOCALISED_POSITION_M,
    frame_errors,
)
from vc_gym.experiments.studies.tracking.routes import Route
from vc_gym.experiments.views.top_view import field_axes, scene_top_view
from vc_gym.jobs.output import new_figure, save_figure

__all__ = ["plot_belief", "plot_errors", "snapshot_times"]


def snapshot_times(route: Route, settle_s: float) -> list[float]:
    """When the belief plot shows the particles: settled, just before the kidnapping,
    2 s after it, at the end."""
    dt = 0.1
    times = [settle_s, route.kidnap_s - dt, route.kidnap_s + 2.0, route.duration_s]
    return sorted({round(min(max(t, 0.0), route.duration_s), 6) for t in times})


def plot_errors(path: Path, scene, lights, named, grouped) -> None:
    """Heading and position error against time: a row per (light, tracker), a curve per
    route coloured by learning seed, each kidnapping a dashed line."""
    rows = [(light, name) for light in lights for name in named if (scene, light, name) in grouped]
    if not rows:
        return
    fig = new_figure(figsize=(11, 2.3 * len(rows) + 0.8), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(rows), 2, sharex=True, squeeze=False))
    seeds = sorted({e["seed"] for (sc, _, _), es in grouped.items() if sc == scene for e in es})
    colours = {s: f"C{i % 10}" for i, s in enumerate(seeds)}
    for (light, name), (ax_h, ax_p) in zip(rows, axes, strict=True):
        labelled = set()
        for entry in grouped[(scene, light, name)]:
            e = frame_errors(entry["frames"])
            c = colours[entry["seed"]]
            label = None if entry["seed"] in labelled else f"seed {entry['seed']}"
            labelled.add(entry["seed"])
            ax_h.plot(e["t"], np.abs(e["heading"]), color=c, lw=0.9, label=label)
            ax_p.plot(e["t"], e["position"], color=c, lw=0.9)
            for ax in (ax_h, ax_p):
                ax.axvline(entry["route"]["kidnap_s"], color=c, ls="--", lw=0.9)
        ax_h.axhline(RELOCALISED_HEADING_DEG, color="0.5", ls=":", lw=0.8)
        ax_p.axhline(RELOCALISED_POSITION_M, color="0.5", ls=":", lw=0.8)
        ax_h.set_ylim(0.0, 180.0)
        ax_p.set_ylim(bottom=0.0)
        ax_h.set_ylabel(f"light {light:g}, {name}\n|heading error| (°)", fontsize=8)
        ax_p.set_ylabel("position error (m)", fontsize=8)
        ax_h.legend(fontsize=7, loc="upper left")
    for ax in axes[-1]:
        ax.set_xlabel("time (s); dashed: the kidnapping")
    fig.suptitle(
        f"{scene}: tracking a walking robot (dotted: re-localised within "
        f"{RELOCALISED_POSITION_M} m and {RELOCALISED_HEADING_DEG:g}°)",
        fontsize=10,
    )
    save_figure(fig, path, dpi=90)


#: Colours of the particle snapshots on the belief plot, in time order.
_MOMENT_COLOURS = ("black", "tab:orange", "white", "tab:purple")


def plot_belief(path: Path, scene, light, seed, named, grouped, bounds, spots) -> None:
    """The first route at ``light``, one panel per tracker: the true path, the believed
    one, ±2σ ellipses and heading arrows every few seconds, particles at a few moments."""
    from matplotlib.patches import Ellipse

    panels = []
    for name in named:
        entries = [e for e in grouped.get((scene, light, name), []) if e["seed"] == seed]
        entries = [e for e in entries if e["index"] == 0]
        if entries:
            panels.append((name, entries[0]))
    if not panels:
        return
    background, extent = scene_top_view(scene)
    fig = new_figure(figsize=(5.5 * len(panels), 4.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(panels), squeeze=False)[0])
    for ax, (name, entry) in zip(axes, panels, strict=True):
        ax.imshow(background, extent=extent, alpha=0.55)
        field_axes(ax, bounds)
        sp = np.asarray(spots)
        ax.plot(sp[:, 0], sp[:, 1], "x", color="gold", ms=5, mew=1.5, label="training spots")
        frames = entry["frames"]
        t = np.asarray(frames["t_s"])
        true = np.asarray(frames["true"])
        est = np.asarray(frames["estimate"])
        std = np.asarray(frames["position_std_m"])
        kid = entry["route"]["kidnap_s"]
        before = t < kid - 1e-9
        moments = sorted(entry["particles"], key=float)
        for i, moment in enumerate(moments):
            p = np.asarray(entry["particles"][moment])
            ax.scatter(
                p[:, 0],
                p[:, 1],
                s=3,
                color=_MOMENT_COLOURS[i % len(_MOMENT_COLOURS)],
                alpha=0.6,
                label=f"particles at {float(moment):g} s",
                zorder=2,
            )
        ax.plot(true[before, 0], true[before, 1], color="tab:red", lw=1.8, label="true path")
        ax.plot(true[~before, 0], true[~before, 1], color="tab:red", lw=1.8, ls=(0, (4, 1)))
        ax.plot(est[:, 0], est[:, 1], color="tab:cyan", lw=1.0, label="believed path")
        k = int(np.argmax(~before)) if (~before).any() else None
        if k:
            ax.annotate(
                "",
                xy=true[k, :2],
                xytext=true[k - 1, :2],
                arrowprops={"arrowstyle": "->", "color": "magenta", "lw": 1.2},
            )
            ax.plot(*true[k, :2], "o", color="magenta", ms=6, label=f"kidnapped at {kid:g} s")
        every = max(1, int(round(max(t[-1] / 12.0, 1.0) / (t[1] - t[0]))))
        for i in range(0, len(t), every):
            ax.add_patch(
                Ellipse(
                    est[i, :2],
                    4 * std[i, 0],
                    4 * std[i, 1],
                    fill=False,
                    ec="tab:cyan",
                    lw=0.7,
                    alpha=0.8,
                )
            )
            h = math.radians(est[i, 2])
            ax.arrow(
                est[i, 0],
                est[i, 1],
                0.3 * math.cos(h),
                0.3 * math.sin(h),
                color="tab:blue",
                width=0.01,
                head_width=0.08,
                length_includes_head=True,
            )
        ax.set_title(f"{name}: seed {seed}, route 0, light {light:g} (ellipses: ±2σ)", fontsize=9)
        ax.legend(fontsize=6, loc="lower left")
    fig.suptitle(f"{scene}: true pose and belief", fontsize=10)
    save_figure(fig, path, dpi=90)
