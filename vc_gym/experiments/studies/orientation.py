"""The paper's orientation experiment (5.1, fig. 4): heading over the field from one spot.

The robot learns the panorama at a single spot (the paper: the centre of the rear
field half) in a full turn, and is then put by hand at every point of a grid over the
field (~33 cm spacing) with several random headings; at each pose it stands scanning
with its head for some frames while every tracker (and the single-frame compass)
estimates its heading. Each grid position is one job
(:mod:`~vc_gym.experiments.studies.orientation_grid`). The results give the heading
error and spread against the distance from the training spot (fig. 4 right; the
paper: the mean error exceeds 10° only beyond 2 m) and the arrow field of the heading
estimates (fig. 4 left).

Modes (:data:`~vc_gym.experiments.studies.orientation_grid.VIEW_MODES`): ``paper`` is
the paper's single spot; ``spot-grid`` learns a grid of spots over the field with
exposure-normalised colour classes, and distances are measured from the nearest spot.
``light`` dims the room for the views (the maps are learned at full light). The
environments experiment is the same in every registered scene.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.deprecation import moved_names, renamed
from vc_gym.experiments.studies import common, orientation_grid
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    median_timings,
    open_run,
    pick_size,
)
from vc_gym.experiments.studies.orientation_grid import check_trackers, orientation_stage
from vc_gym.experiments.views import (
    PAPER_ERROR_DEG,
    PAPER_RANGE_M,
    plot_arrow_field,
    plot_error_vs_distance,
)
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.jobs.run import ExperimentRun
from vc_gym.validation import positive_float

__all__ = [
    "cost_lines",
    "plot_views",
    "run_environments",
    "run_orientation",
    "summary_lines",
]

#: Names that moved to the shared :mod:`~vc_gym.experiments.studies.orientation_grid`
#: and :mod:`~vc_gym.experiments.studies.common`: served here for one release, with a
#: DeprecationWarning.
__getattr__ = moved_names(
    __name__,
    {
        **{
            name: (orientation_grid, name)
            for name in (
                "DEFAULT_TRACKERS",
                "HEADLINE",
                "MODE_TRACKER_OPTIONS",
                "VIEW_MODES",
                "headline_errors",
                "mode_trackers",
                "rear_half_centre",
                "training_spots",
                "view_job",
                "view_jobs",
                "views_stage",
                "views_summary",
            )
        },
        **{name: (common, name) for name in ("check_scenes", "one_scene")},
    },
)

# ``spots_m``: spacing of the spot-grid mode's spots (GRID_SPACING_M unless given; the
# tests' quick size learns a coarser grid, 6 spots in robolab, to stay quick)
SIZES = {
    "quick": {"spacing_m": 2.0, "headings": 1, "frames": 4, "learn_time_s": 0.5, "spots_m": 2.0},
    "paper": {"spacing_m": 0.5, "headings": 2, "frames": 10, "learn_time_s": 5.0},
    "full": {"spacing_m": 0.33, "headings": 3, "frames": 15, "learn_time_s": 5.0},
}


def plot_views(
    folder: Path,
    outputs: Sequence[Mapping[str, Any] | None],
    summary: Mapping[str, Any],
    spot: tuple[float, float] | Sequence[tuple[float, float]],
    bounds: Sequence[float],
    title: str,
    arrows_for: str = "grid",
    suffix: str = "",
) -> None:
    """``error_vs_distance{suffix}.png`` and ``arrow_field{suffix}.png``."""
    views = [v for o in outputs if o is not None for v in o["views"]]
    if not views:
        return
    tables = {n: s["by_distance"] for n, s in summary["trackers"].items()}
    plot_error_vs_distance(folder / f"error_vs_distance{suffix}.png", tables)
    name = arrows_for if arrows_for in summary["trackers"] else next(iter(summary["trackers"]))
    poses = np.array([v["pose"] for v in views])
    headings = np.array([v["estimates"][name]["heading_deg"] for v in views])
    plot_arrow_field(
        folder / f"arrow_field{suffix}.png",
        poses,
        headings,
        spot,
        tuple(bounds),
        f"{title}: {name} heading estimates",
        reference_deg=0.0,  # as in fig. 4: every correct arrow points to +x
    )


def run_orientation(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    trackers: Sequence[Any] | None = None,
    scenes: Sequence[str] | None = None,
    modes: Sequence[str] | None = None,
    light: float = 1.0,
) -> dict[str, Any]:
    """Run the orientation experiment (5.1, fig. 4) and write its results and plots.

    Parameters
    ----------
    out_dir : path-like
        The run folder (resumable).
    opts : ExperimentOptions
        Seed, size (grid spacing, headings and frames per position), backend, ...
    trackers : sequence, optional
        Tracker specs (default: grid, kalman, particle); the single-frame compass is
        always reported as ``"compass"``.
    scenes : sequence of str, optional
        Default ``["robolab"]`` (the paper's); one spot per scene.
    modes : sequence of str, optional
        Modes to run (default ``["paper"]``;
        :data:`~vc_gym.experiments.studies.orientation_grid.VIEW_MODES`). With only
        ``paper`` the results hold ``scenes``; otherwise ``modes: {mode: {"scenes": ...}}``.
    light : float
        Illumination of the room for the views, in (0, 1]; the maps are learned at
        full light (paper 5.3: half light).

    Returns
    -------
    dict
        The results written to ``results.json``.
    """
    return _run_views("orientation", out_dir, opts, trackers, scenes or ["robolab"], modes, light)


def run_environments(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    trackers: Sequence[Any] | None = None,
    scenes: Sequence[str] | None = None,
    modes: Sequence[str] | None = None,
    light: float = 1.0,
) -> dict[str, Any]:
    """The orientation experiment in every registered scene (paper 5.3: other places).

    Same parameters as :func:`run_orientation`; ``scenes`` defaults to every scene
    registered in this process (:func:`vc_gym.sim.scenes.scene_names`; a scene a user
    registered must also be registered in the workers, see that package).
    """
    from vc_gym.sim.scenes import scene_names

    return _run_views(
        "environments", out_dir, opts, trackers, scenes or list(scene_names()), modes, light
    )


#: Deprecated names of view modes, accepted with a ``DeprecationWarning``.
DEPRECATED_VIEW_MODES = {"improved": "spot-grid"}


def _check_modes(modes: Sequence[str] | None) -> list[str]:
    modes = ["paper"] if modes is None else modes
    if not isinstance(modes, str):
        current = []
        for m in modes:
            current.append(renamed("view mode", m, DEPRECATED_VIEW_MODES, stacklevel=3))
        modes = current
    known = list(orientation_grid.VIEW_MODES)
    if isinstance(modes, str) or not modes or len(set(modes)) != len(list(modes)):
        raise ValueError(f"modes must be distinct names from {known}, got {modes}")
    for m in modes:
        if m not in known:
            raise ValueError(f"unknown mode {m!r}; choose from {known}")
    return list(modes)


def _run_views(name, out_dir, opts, trackers, scenes, modes=None, light=1.0) -> dict[str, Any]:
    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    named = check_trackers(trackers or orientation_grid.DEFAULT_TRACKERS)
    scenes = common.check_scenes(scenes)
    modes = _check_modes(modes)
    light = positive_float("light", light)
    if light > 1.0:
        raise ValueError(f"light must be in (0, 1], got {light}")
    room = {"illumination": light} if light != 1.0 else None
    settings = {"trackers": named, "scenes": scenes, **size}
    if modes != ["paper"]:
        settings["modes"] = modes
    if room:
        settings["light"] = light
    run = open_run(out_dir, name, opts, settings)
    results: dict[str, Any] = {
        "paper": {"claim": "mean heading error < 10° within 2 m of the training spot"},
    }
    per_mode = {}
    for mode in modes:
        per_scene = {}
        for scene in scenes:
            outputs, summary, spot, bounds = orientation_stage(
                run, opts, size, scene, named, room=room, mode=mode
            )
            suffix = ("" if len(scenes) == 1 else f"_{scene}") + (
                "" if mode == "paper" else f"_{mode}"
            )
            where = f"spot {spot}" if mode == "paper" else f"{len(spot)} spots"
            plot_views(run.out, outputs, summary, spot, bounds, f"{scene}, {where}", suffix=suffix)
            entry = {"training_spot": list(spot)} if mode == "paper" else {"spots": spot}
            per_scene[scene] = {**entry, **summary}
        if len(scenes) > 1:
            _plot_scenes(run.out / f"scenes{'' if mode == 'paper' else '_' + mode}.png", per_scene)
        per_mode[mode] = per_scene
    if modes == ["paper"]:
        results["scenes"] = per_mode["paper"]
    else:
        results["modes"] = {m: {"scenes": per_mode[m]} for m in modes}
    return run.finish(results, _cost_info(run, modes, scenes))


def _plot_scenes(path: Path, per_scene: Mapping[str, Any], tracker: str = "grid") -> None:
    """Mean |heading error| vs distance, one line per scene (for one tracker)."""
    fig = new_figure(figsize=(6.5, 4), layout="constrained")
    ax = fig.subplots()
    for scene, r in per_scene.items():
        t = r["trackers"].get(tracker) or next(iter(r["trackers"].values()))
        rows = t["by_distance"]
        ax.plot(
            [b["distance_m"] for b in rows],
            [b["mean_abs_error_deg"] for b in rows],
            "o-",
            label=scene,
        )
    ax.axhline(PAPER_ERROR_DEG, ls="--", color="0.4", lw=1)
    ax.axvline(PAPER_RANGE_M, ls=":", color="0.4", lw=1)
    ax.set_xlabel("distance from the training spot (m)")
    ax.set_ylabel(f"mean |heading error| (°), {tracker} tracker")
    ax.set_yscale("log")
    ax.set_title("the orientation experiment in every scene (paper 5.3)", fontsize=10)
    ax.legend(fontsize=8)
    save_figure(fig, path)


def _cost_info(run: ExperimentRun, modes: Sequence[str], scenes: Sequence[str]) -> dict[str, Any]:
    """Median ms per update of every tracker over the view jobs, overall and per mode
    (for ``run.json``; :func:`cost_lines` prints them)."""

    def timings(mode: str) -> list[Any]:
        stages = [
            run.timings.get(orientation_grid.views_stage(mode, scene), {}) for scene in scenes
        ]
        return [t for jobs in stages for t in jobs.values()]

    info: dict[str, Any] = {
        "ms_per_update_median": median_timings([t for m in modes for t in timings(m)])
    }
    if list(modes) != ["paper"]:
        info["ms_per_update_median_by_mode"] = {m: median_timings(timings(m)) for m in modes}
    return info


def cost_lines(run_info: Mapping[str, Any]) -> list[str]:
    """Cost per frame of every tracker (median ms per update, from ``run.json``); with
    several modes, each mode's and its ratio to the paper mode's."""
    by_mode = run_info.get("ms_per_update_median_by_mode")
    if not by_mode:
        costs = run_info.get("ms_per_update_median") or {}
        return (
            [
                "cost per frame (median ms per update): "
                + ", ".join(f"{n} {v:.2f}" for n, v in costs.items() if v is not None)
            ]
            if costs
            else []
        )
    paper = by_mode.get("paper", {})
    lines = ["cost per frame (median ms per update, this run):"]
    for mode, costs in by_mode.items():
        parts = []
        for name, ms in costs.items():
            if ms is None:
                continue
            ratio = (
                f" (x{ms / paper[name]:.1f} of paper)"
                if paper.get(name) and mode != "paper"
                else ""
            )
            parts.append(f"{name} {ms:.2f}{ratio}")
        lines.append(f"  {mode}: " + ", ".join(parts))
    return lines


def summary_lines(results: Mapping[str, Any]) -> list[str]:
    """Mean heading error within and beyond 2 m of the spot, per mode, scene and tracker."""
    if "modes" in results:
        lines = []
        for mode, r in results["modes"].items():
            lines.append(f"{mode} mode:")
            lines += ["  " + line for line in summary_lines({"scenes": r["scenes"]})]
        for f in results.get("failed_jobs", []):
            lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
        return lines
    lines = []
    for scene, r in results.get("scenes", {}).items():
        where = f"spot {r['training_spot']}" if "training_spot" in r else f"{len(r['spots'])} spots"
        lines.append(f"{scene} ({where}, {r['views']} views):")
        for name, t in r["trackers"].items():
            beyond = t["mean_abs_error_beyond_2m_deg"]
            lines.append(
                f"  {name:10s} mean |error| {t['mean_abs_error_within_2m_deg']}° within 2 m, "
                + (f"{beyond}° beyond" if beyond is not None else "no view beyond")
                + "; paper's claim (< 10° within "
                f"2 m) {'holds' if t['paper_claim_holds'] else 'does not hold'}"
            )
    for f in results.get("failed_jobs", []):
        lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
    return lines
