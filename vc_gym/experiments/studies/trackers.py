"""The tracker benchmark: every tracker × scenes × seeds, on the homing task and the field.

For each scene and learning seed the four spots around home are learned once and every
tracker homes from the same kidnappings (same seeds, so the episodes differ only by the
tracker); for each scene one spot is learned for the orientation grid, where all
trackers see the same frames. A tracker is a name (``grid``, ``kalman``, ``particle``),
a ``"package.module:factory"`` of the user's own, or a ``{"type": ...}`` dict. The
leaderboard (``leaderboard.png`` and the printed table) ranks them by homing success,
then stop distance; cost per update comes from ``run.json`` (timings are not figures).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.experiments.atlases import atlas_key, atlas_spec, ensure_atlases
from vc_gym.experiments.episode import (
    DEFAULT_HOMING_MODE,
    HOMING_MODES,
    canonical_homing_mode,
)
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    median_timings,
    open_run,
    pick_size,
    safe_name,
)
from vc_gym.experiments.studies.kidnapping import (
    EPISODE_JOB,
    spread_over_seeds,
    summarise_stops,
)
from vc_gym.experiments.studies.orientation_grid import (
    DEFAULT_TRACKERS,
    check_trackers,
    orientation_stage,
)
from vc_gym.experiments.views import COMPASS
from vc_gym.jobs.job import Job
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.jobs.run import ExperimentRun

__all__ = ["run_trackers", "summary_lines"]

SIZES = {
    "quick": {
        "scenes": ["robolab"],
        "seeds": 1,
        "episodes": 1,
        "learn_time_s": 0.3,
        "max_homing_s": 10.0,
        "views": {"spacing_m": 2.0, "headings": 1, "frames": 3, "learn_time_s": 0.5},
    },
    "paper": {
        "scenes": ["robolab", "office"],
        "seeds": 1,
        "episodes": 6,
        "learn_time_s": 5.0,
        "max_homing_s": 60.0,
        "views": {"spacing_m": 1.0, "headings": 1, "frames": 8, "learn_time_s": 5.0},
    },
    "full": {
        "scenes": None,  # every registered scene
        "seeds": 3,
        "episodes": 33,
        "learn_time_s": 5.0,
        "max_homing_s": 60.0,
        "views": {"spacing_m": 0.5, "headings": 2, "frames": 10, "learn_time_s": 5.0},
    },
}


def run_trackers(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    trackers: Sequence[Any] | None = None,
    scenes: Sequence[str] | None = None,
    seeds: Sequence[int] | None = None,
    episodes: int | None = None,
    mode: str = DEFAULT_HOMING_MODE,
) -> dict[str, Any]:
    """Benchmark trackers on the homing task and the orientation grid.

    Parameters
    ----------
    out_dir : path-like
        The run folder (resumable).
    opts : ExperimentOptions
        Seed, size, backend, ``--atlas``, ``--video`` (first N homing episodes).
    trackers : sequence, optional
        Tracker specs (default: grid, kalman, particle).
    scenes : sequence of str, optional
        Default by size (``full``: every registered scene).
    seeds : sequence of int, optional
        Learning seeds (default by size, from ``opts.seed`` on).
    episodes : int, optional
        Kidnappings per (scene, seed, tracker).
    mode : str
        The homing mode (:data:`~vc_gym.experiments.episode.HOMING_MODES`):
        ``"check-home"`` (default) or ``"paper"``.

    Returns
    -------
    dict
        Per tracker: homing figures (pooled, and mean ± std over seeds) and heading
        errors on the grid, and the leaderboard order.
    """
    from vc_gym.sim.scenes import check_scene_name, scene_names

    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    named = check_trackers(trackers or DEFAULT_TRACKERS)
    scenes = list(scenes or size["scenes"] or scene_names())
    for s in scenes:
        check_scene_name(s)
    seeds = list(seeds) if seeds else [opts.seed + k for k in range(size["seeds"])]
    episodes = size["episodes"] if episodes is None else int(episodes)
    if episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    mode = canonical_homing_mode(mode)
    settings = {"trackers": named, "scenes": scenes, "seeds": seeds, "episodes": episodes}
    if mode != "paper":  # a paper-mode run's settings (and so its jobs) have no mode key
        settings["mode"] = mode
    run = open_run(out_dir, "trackers", opts, settings)

    homing = _homing(run, opts, size, named, scenes, seeds, episodes, mode)
    views: dict[str, Any] = {}
    for scene in scenes:
        _, summary, spot, _ = orientation_stage(
            run, opts, size["views"], scene, named, stage=f"views-{scene}"
        )
        views[scene] = {"training_spot": list(spot), **summary}

    board = []
    for name in named:
        eps = [e for per in homing[name].values() for e in per]
        row: dict[str, Any] = {"tracker": name}
        if eps:
            row["homing"] = summarise_stops(eps, 0.3)
            by_seed = [
                summarise_stops([e for e in eps if e["learning_seed"] == s], 0.3)
                for s in seeds
                if any(e["learning_seed"] == s for e in eps)
            ]
            row["homing"].update(spread_over_seeds(by_seed))
            row["homing"]["per_scene"] = {
                sc: summarise_stops(per, 0.3) for sc, per in homing[name].items() if per
            }
        row["heading"] = {
            sc: {
                k: v["trackers"][name][k]
                for k in ("mean_abs_error_within_2m_deg", "mean_abs_error_deg", "within_10deg")
            }
            for sc, v in views.items()
            if name in v.get("trackers", {})
        }
        board.append(row)
    board.sort(
        key=lambda r: (
            -r.get("homing", {}).get("success_rate", -1.0),
            r.get("homing", {}).get("mean_stop_distance_cm", float("inf")),
        )
    )
    results = {
        "leaderboard": board,
        "compass_heading": {
            sc: {
                k: v["trackers"][COMPASS][k]
                for k in ("mean_abs_error_within_2m_deg", "mean_abs_error_deg")
            }
            for sc, v in views.items()
            if COMPASS in v.get("trackers", {})
        },
        "per_episode": {n: h for n, h in homing.items()},
    }
    costs = _costs(run)
    _plot(run.out / "leaderboard.png", board, costs)
    return run.finish(results, {"ms_per_update_median": costs})


def _homing(run: ExperimentRun, opts, size, named, scenes, seeds, episodes, mode):
    learning = HOMING_MODES[mode].learning
    specs = {
        (sc, s): atlas_spec(sc, s, "scripted", size["learn_time_s"], learning=learning)
        for sc in scenes
        for s in seeds
    }
    paths = ensure_atlases(run, list(specs.values()), opts.atlas_dir)
    jobs, where = [], []
    for name, spec in named.items():
        for (sc, s), aspec in specs.items():
            for i in range(episodes):
                kwargs = {
                    "agent": "scripted",
                    "tracker": spec,
                    "scene": sc,
                    "learn_time_s": size["learn_time_s"],
                    "success_radius_m": 0.3,
                    "max_homing_s": size["max_homing_s"],
                    "atlas": paths[atlas_key(aspec)],
                    "learning_seed": s,
                    "episode_seed": s + 1 + i,
                    **({"mode": mode} if mode != "paper" else {}),
                }
                if len(jobs) < opts.video:
                    folder = run.out / "videos"
                    folder.mkdir(exist_ok=True)
                    kwargs["video"] = str((folder / f"{len(jobs):03d}.mp4").resolve())
                key = f"{safe_name(name)}-{sc}-seed{s}-episode{i:03d}"
                jobs.append(Job(key, EPISODE_JOB, kwargs))
                where.append((name, sc))
    out: dict[str, dict[str, list]] = {n: {sc: [] for sc in scenes} for n in named}
    for (name, sc), o in zip(where, run.run("episodes", jobs), strict=True):
        if o is not None:
            out[name][sc].append(o)
    return out


def _costs(run: ExperimentRun) -> dict[str, float]:
    """Median ms per update of each tracker: homing episodes and grid views together."""
    timings: list[dict[str, float]] = []
    for stage, jobs in run.timings.items():
        for key, t in jobs.items():
            if stage == "episodes":
                ms = t.get("tracker_ms_per_update")
                name = run_job_tracker(run, key)
                if ms is not None and name is not None:
                    timings.append({name: ms})
            elif stage.startswith("views"):
                timings.append(t)
    return median_timings(timings)


def run_job_tracker(run: ExperimentRun, key: str) -> str | None:
    """The tracker name of an episode job's key (``<tracker>-<scene>-seed..``)."""
    names = run.settings["trackers"]
    for name in names:
        if key.startswith(safe_name(name) + "-"):
            return name
    return None


def _plot(path: Path, board: Sequence[Mapping[str, Any]], costs: Mapping[str, float]) -> None:
    rows = [r for r in board if "homing" in r]
    if not rows:
        return
    fig = new_figure(figsize=(11, 3.8), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(1, 3)
    names = [r["tracker"] for r in rows]
    y = np.arange(len(rows))
    succ = [r["homing"]["success_rate_over_seeds"] for r in rows]
    ax1.barh(y, [100 * s[0] for s in succ], xerr=[100 * s[1] for s in succ], color="tab:green")
    ax1.set_yticks(y, names)
    ax1.invert_yaxis()
    ax1.set_xlabel("homing success within 30 cm (%)")
    dist = [r["homing"]["mean_stop_distance_cm_over_seeds"] for r in rows]
    ax2.barh(y, [d[0] for d in dist], xerr=[d[1] for d in dist], color="tab:blue")
    ax2.set_yticks(y, [""] * len(rows))
    ax2.invert_yaxis()
    ax2.set_xlabel("mean stop distance (cm)")
    for r in rows:
        errs = [
            h["mean_abs_error_within_2m_deg"]
            for h in r["heading"].values()
            if h["mean_abs_error_within_2m_deg"] is not None
        ]
        if errs and r["tracker"] in costs:
            ax3.plot(costs[r["tracker"]], float(np.mean(errs)), "o", ms=8)
            ax3.annotate(
                r["tracker"],
                (costs[r["tracker"]], float(np.mean(errs))),
                fontsize=8,
                xytext=(4, 4),
                textcoords="offset points",
            )
    ax3.set_xlabel("ms per update (this machine, median)")
    ax3.set_ylabel("mean |heading error| within 2 m (°)")
    ax3.grid(alpha=0.3)
    fig.suptitle("tracker leaderboard (mean ± std over learning seeds)", fontsize=11)
    save_figure(fig, path)


def summary_lines(results: Mapping[str, Any]) -> list[str]:
    """The leaderboard as a table."""
    lines = [
        f"{'tracker':24s} {'success':>14s} {'stop dist cm':>16s} {'far':>4s} "
        f"{'heading err <2 m':>17s}"
    ]
    for r in results.get("leaderboard", []):
        h = r.get("homing")
        errs = [
            v["mean_abs_error_within_2m_deg"]
            for v in r["heading"].values()
            if v["mean_abs_error_within_2m_deg"] is not None
        ]
        head = f"{np.mean(errs):.1f}°" if errs else "-"
        if h:
            s, d = h["success_rate_over_seeds"], h["mean_stop_distance_cm_over_seeds"]
            lines.append(
                f"{r['tracker'][:24]:24s} {100 * s[0]:6.0f} ± {100 * s[1]:3.0f} % "
                f"{d[0]:8.1f} ± {d[1]:5.1f} {h['far_stops']:4d} {head:>17s}"
            )
        else:
            lines.append(f"{r['tracker'][:24]:24s} {'(no episodes)':>14s} {head:>17s}")
    for f in results.get("failed_jobs", []):
        lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
    return lines
