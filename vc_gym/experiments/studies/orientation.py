"""The paper's orientation experiment (5.1, fig. 4): heading over the field from one spot.

The robot learns the panorama at a single spot (the paper: the centre of the rear
field half) in a full turn, and is then put by hand at every point of a grid over the
field (~33 cm spacing) with several random headings; at each pose it stands scanning
with its head for some frames while every tracker (and the single-frame compass)
estimates its heading. Each grid position is one job. The results give the heading
error and spread against the distance from the training spot (fig. 4 right; the
paper: the mean error exceeds 10° only beyond 2 m) and the arrow field of the heading
estimates (fig. 4 left).

Modes (:data:`VIEW_MODES`): ``paper`` is the paper's single spot; ``improved`` learns
the same way at every spot of a grid over the field (:data:`GRID_SPACING_M` apart,
:class:`~vc_gym.envs.learning.GridLearning`, shared colour classes, home the spot
nearest the paper's), plus four shorter turns :data:`GRID_AROUND_M` around each spot
into its map, with exposure-normalised colour classes (so that it holds at half
light), the trackers take the heading from the map that fits best (eq. 28), and
distances are measured from the nearest spot; between full scorings the built-in
trackers score only the two spots that fitted best (:data:`MODE_TRACKER_OPTIONS`), so
a frame costs about five maps, not two dozen. ``light`` dims the room for the views
(the maps are learned at full light).

:func:`view_job` and :func:`views_summary` are shared by the environments, parameter,
illumination and tracker experiments.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.compass import Camera, CompassAtlas
from vc_gym.experiments.atlases import atlas_key, atlas_spec, ensure_atlases
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    median_timings,
    open_run,
    pick_size,
    scene_field_bounds,
)
from vc_gym.experiments.studies.homing import check_tracker_spec
from vc_gym.experiments.views import (
    COMPASS,
    PAPER_ERROR_DEG,
    PAPER_RANGE_M,
    distance_table,
    evaluate_view,
    field_grid,
    look,
    plot_arrow_field,
    plot_error_vs_distance,
    spots_array,
    view_poses,
)
from vc_gym.jobs.runner import ExperimentRun, Job, worker_cache
from vc_gym.validation import positive_float

__all__ = [
    "check_scenes",
    "DEFAULT_TRACKERS",
    "MODE_TRACKER_OPTIONS",
    "VIEW_MODES",
    "training_spots",
    "views_stage",
    "HEADLINE",
    "headline_errors",
    "mode_trackers",
    "one_scene",
    "cost_lines",
    "rear_half_centre",
    "run_environments",
    "run_orientation",
    "summary_lines",
    "view_job",
    "view_jobs",
    "views_summary",
]

DEFAULT_TRACKERS = ("grid", "kalman", "particle")
_BUILT_IN_TRACKERS = frozenset(DEFAULT_TRACKERS)

# ``spots_m``: spacing of the improved mode's spots (GRID_SPACING_M unless given; the
# tests' quick size learns a coarser grid, 6 spots in robolab, to stay quick)
SIZES = {
    "quick": {"spacing_m": 2.0, "headings": 1, "frames": 4, "learn_time_s": 0.5, "spots_m": 2.0},
    "paper": {"spacing_m": 0.5, "headings": 2, "frames": 10, "learn_time_s": 5.0},
    "full": {"spacing_m": 0.33, "headings": 3, "frames": 15, "learn_time_s": 5.0},
}


#: How the heading is learned over the field, by name (``--modes``): the compass
#: options of each mode (:class:`~vc_gym.compass.CompassConfig` fields).
VIEW_MODES: dict[str, dict[str, Any]] = {"paper": {}, "improved": {"exposure": "mean"}}
#: Options each mode gives the built-in trackers (grid, kalman, particle): the improved
#: mode's atlas has two dozen spots in robolab, so its trackers score every spot every
#: 8th frame and, in between, only the two that fitted best
#: (:class:`~vc_gym.localization.SpotShortlist`; chosen on seed 0 of robolab: 5.3°, where
#: the three best every 4th frame gave 5.1° at 1.3 times the cost).
MODE_TRACKER_OPTIONS: dict[str, dict[str, Any]] = {
    "paper": {},
    "improved": {"shortlist": 2, "rescore_every": 8},
}
#: Spacing of the improved mode's grid of spots (metres) and its margin inside the field
#: (1.0 m: 24 spots in robolab; 1.5 m, 12 spots, gave 6.2 ± 0.5° over seeds 0-2 against
#: 5.1 ± 0.2°, README).
GRID_SPACING_M = 1.0
GRID_MARGIN_M = 0.5
#: The improved mode's maps also learn four turns this far around each spot
#: (:class:`~vc_gym.envs.learning.GridLearning`'s ``around_m``).
GRID_AROUND_M = 0.5


def training_spots(
    bounds: Sequence[float], mode: str = "paper", spacing_m: float | None = None
) -> list[tuple[float, float]]:
    """The spots a mode learns: the paper's one, or a grid ``spacing_m`` apart
    (default :data:`GRID_SPACING_M`) with the one nearest it first."""
    if spacing_m is None:
        spacing_m = GRID_SPACING_M
    if mode not in VIEW_MODES:
        raise ValueError(f"mode must be one of {list(VIEW_MODES)}, got {mode!r}")
    centre = rear_half_centre(bounds)
    if mode == "paper":
        return [centre]
    grid = field_grid(tuple(bounds), spacing_m, margin_m=GRID_MARGIN_M)
    order = np.argsort(np.hypot(grid[:, 0] - centre[0], grid[:, 1] - centre[1]), kind="stable")
    return [(round(float(x), 4), round(float(y), 4)) for x, y in grid[order]]


def mode_trackers(trackers: Mapping[str, Any], mode: str) -> dict[str, Any]:
    """``trackers`` with ``mode``'s options (:data:`MODE_TRACKER_OPTIONS`) given to every
    built-in tracker; other trackers and options set explicitly are left as they are."""
    options = MODE_TRACKER_OPTIONS[mode]
    out = {}
    for name, spec in trackers.items():
        kind = spec if isinstance(spec, str) else spec.get("type")
        if options and kind in _BUILT_IN_TRACKERS:
            spec = {**options, **({"type": spec} if isinstance(spec, str) else spec)}
        out[name] = spec
    return out


def rear_half_centre(bounds: Sequence[float]) -> tuple[float, float]:
    """The centre of the field half with x < centre: the paper's training spot (5.1)."""
    x0, x1, y0, y1 = (float(v) for v in bounds)
    return (round(x0 + (x1 - x0) / 4.0, 4), round((y0 + y1) / 2.0, 4))


def check_trackers(trackers: Sequence[Any] | Mapping[str, Any]) -> dict[str, Any]:
    """``{name: spec}`` of trackers that can travel to workers (names must be unique)."""
    if isinstance(trackers, Mapping):
        named = {str(name): check_tracker_spec(spec) for name, spec in trackers.items()}
    else:
        named = {}
        for spec in trackers:
            spec = check_tracker_spec(spec)
            name = (
                spec
                if isinstance(spec, str)
                else json.dumps(spec, sort_keys=True, separators=(",", ":"))
            )
            if name in named:
                raise ValueError(f"tracker {name!r} given twice")
            named[name] = spec
    if not named:
        raise ValueError("no trackers given")
    if COMPASS in named:
        raise ValueError(f"{COMPASS!r} is always reported (the single-frame compass)")
    return named


def view_job(
    scene: str,
    atlas: str,
    spot: list[float] | list[list[float]],
    poses: list[list[float]],
    frames: int,
    seed: int,
    trackers: dict[str, Any],
    room: dict[str, Any] | None = None,
    time_learning: bool = False,
) -> dict[str, Any]:
    """Job: stand at every pose of one grid position; what each tracker believed.

    ``spot`` is the training spot ``[x, y]`` or a list of them; ``distance_m`` is
    measured from the nearest. Returns ``{"views": [{"pose", "distance_m", "estimates":
    {tracker: {...}}}], "timing": {tracker: ms per update}}``; with ``time_learning`` the
    timing also holds ``"learn"``: milliseconds to learn one frame into a map of the
    atlas' config.
    """
    from vc_gym.sim.aibo_room import AiboRoomEnv

    room = dict(room or {})
    env = worker_cache(
        ("room", scene, json.dumps(room, sort_keys=True)),
        lambda: AiboRoomEnv(scene=scene, **room),
    )
    loaded = worker_cache(("atlas", atlas), lambda: CompassAtlas.load(atlas))
    camera = Camera(hfov_deg=env.camera.hfov_deg)
    spots = spots_array(spot)
    views, costs = [], {}
    for k, pose in enumerate(poses):
        seen = look(env, tuple(pose), frames, seed=seed + k)
        figures, timing = evaluate_view(seen, loaded, camera, env.control_dt, pose[2], trackers)
        views.append(
            {
                "pose": [round(float(v), 4) for v in pose],
                "distance_m": round(
                    float(np.min(np.hypot(spots[:, 0] - pose[0], spots[:, 1] - pose[1]))), 4
                ),
                "estimates": {
                    name: {k2: round(v, 4) for k2, v in est.items()}
                    for name, est in figures.items()
                },
            }
        )
        for name, ms in timing.items():
            costs.setdefault(name, []).append(ms)
        if time_learning:
            costs.setdefault("learn", []).append(_learn_ms(loaded, seen, camera, pose[2]))
    return {"views": views, "timing": {n: float(np.median(v)) for n, v in costs.items()}}


def _learn_ms(atlas: CompassAtlas, frames, camera: Camera, heading_deg: float) -> float:
    """Milliseconds per frame to learn ``frames`` into a fresh map (paper 5.3: 4 ms)."""
    import time

    from vc_gym.compass import VisualCompass

    vc = VisualCompass(atlas.compasses[0].config, atlas.compasses[0].colors)
    t0 = time.perf_counter()
    for image, pan, _ in frames:
        vc.learn(image, camera.replace(yaw_deg=heading_deg + pan))
    return 1e3 * (time.perf_counter() - t0) / len(frames)


def view_jobs(
    prefix: str,
    scene: str,
    atlas: str,
    spot: tuple[float, float] | Sequence[tuple[float, float]],
    bounds: Sequence[float],
    size: Mapping[str, Any],
    seed: int,
    trackers: Mapping[str, Any],
    room: Mapping[str, Any] | None = None,
    time_learning: bool = False,
) -> list[Job]:
    """One :func:`view_job` per grid position (seeded poses, ``size``'s grid)."""
    grid = field_grid(tuple(bounds), size["spacing_m"])
    rng = np.random.default_rng([seed, 51])
    poses = view_poses(grid, size["headings"], rng)
    jobs = []
    for i in range(len(grid)):
        mine = poses[i * size["headings"] : (i + 1) * size["headings"]]
        kwargs = {
            "scene": scene,
            "atlas": atlas,
            "spot": [list(p) for p in spot] if np.ndim(spot) == 2 else list(spot),
            "poses": [[round(float(v), 4) for v in p] for p in mine],
            "frames": size["frames"],
            "seed": int(seed * 1_000_000 + i * 100),
            "trackers": dict(trackers),
            "room": dict(room or {}),
            "time_learning": time_learning,
        }
        jobs.append(Job(f"{prefix}{i:04d}", f"{__name__}:view_job", kwargs))
    return jobs


def views_summary(
    outputs: Sequence[Mapping[str, Any] | None], names: Sequence[str]
) -> dict[str, Any]:
    """Per tracker: the distance table (fig. 4 right) and errors within / beyond 2 m."""
    views = [v for o in outputs if o is not None for v in o["views"]]
    out: dict[str, Any] = {"views": len(views), "trackers": {}}
    if not views:
        return out
    dist = np.array([v["distance_m"] for v in views])
    near = dist <= PAPER_RANGE_M
    for name in (*names, COMPASS):
        err = np.array([v["estimates"][name]["heading_error_deg"] for v in views])
        spread = np.array([v["estimates"][name]["heading_spread_deg"] for v in views])
        table = distance_table(dist, err, spread, bin_m=0.5)
        near_bins = [b for b in table if b["bin_end_m"] <= PAPER_RANGE_M + 1e-9]
        out["trackers"][name] = {
            "mean_abs_error_deg": round(float(np.abs(err).mean()), 2),
            "median_abs_error_deg": round(float(np.median(np.abs(err))), 2),
            "mean_abs_error_within_2m_deg": round(float(np.abs(err[near]).mean()), 2)
            if near.any()
            else None,
            "mean_abs_error_beyond_2m_deg": round(float(np.abs(err[~near]).mean()), 2)
            if (~near).any()
            else None,
            "within_10deg": round(float(np.mean(np.abs(err) <= 10.0)), 4),
            "paper_claim_holds": bool(near_bins)
            and all(b["mean_abs_error_deg"] < PAPER_ERROR_DEG for b in near_bins),
            "by_distance": [{k: _round(v) for k, v in b.items()} for b in table],
        }
    return out


#: The figures a parameter or light-level row keeps of :func:`views_summary`.
HEADLINE = (
    "mean_abs_error_deg",
    "median_abs_error_deg",
    "mean_abs_error_within_2m_deg",
    "within_10deg",
)


def headline_errors(summary: Mapping[str, Any], names: Sequence[str]) -> dict[str, Any]:
    """``{name: {figure: value}}`` of the :data:`HEADLINE` figures, compass included."""
    out = {}
    for name in (COMPASS, *names):
        t = summary["trackers"].get(name, {})
        out[name] = {k: t.get(k) for k in HEADLINE}
    return out


def one_scene(scenes: Sequence[str] | None, experiment: str) -> str:
    """The one scene of an experiment that runs in a single scene (default robolab)."""
    scenes = list(scenes or ["robolab"])
    if len(scenes) != 1:
        raise ValueError(f"the {experiment} runs in one scene, got {scenes}")
    return scenes[0]


def _round(v: Any) -> Any:
    return round(float(v), 3) if isinstance(v, float) else v


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


def orientation_stage(
    run: ExperimentRun,
    opts: ExperimentOptions,
    size: Mapping[str, Any],
    scene: str,
    trackers: Mapping[str, Any],
    compass: Mapping[str, Any] | None = None,
    room: Mapping[str, Any] | None = None,
    stage: str | None = None,
    time_learning: bool = False,
    mode: str = "paper",
) -> tuple[list[dict[str, Any] | None], dict[str, Any], Any, tuple]:
    """Learn ``mode``'s spots in ``scene`` with ``compass``; run the view jobs in ``room``
    with ``mode``'s tracker options (:func:`mode_trackers`).

    The atlas is learned at full light (``room`` applies to the views only). Returns the
    jobs' outputs, their summary, the spot (``paper``: ``(x, y)``; else the list of
    spots) and the field bounds.
    """
    bounds = scene_field_bounds(scene)
    spots = training_spots(bounds, mode, size.get("spots_m"))
    compass = {**VIEW_MODES[mode], **dict(compass or {})}
    if mode == "paper":
        spot: Any = spots[0]
        spec = atlas_spec(scene, opts.seed, "spot", size["learn_time_s"], compass, spot=spot)
    else:
        spot = spots
        spec = atlas_spec(
            scene,
            opts.seed,
            "grid",
            size["learn_time_s"],
            compass,
            spots=spots,
            around_m=GRID_AROUND_M,
        )
    atlas_path = ensure_atlases(run, [spec], opts.atlas_dir)[atlas_key(spec)]
    trackers = mode_trackers(trackers, mode)
    jobs = view_jobs(
        "pos-", scene, atlas_path, spot, bounds, size, opts.seed, trackers, room, time_learning
    )
    outputs = run.run(stage or views_stage(mode, scene), jobs)
    return outputs, views_summary(outputs, list(trackers)), spot, bounds


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
        :data:`VIEW_MODES` to run (default ``["paper"]``). With only ``paper`` the
        results hold ``scenes``; otherwise ``modes: {mode: {"scenes": ...}}``.
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


def _check_modes(modes: Sequence[str] | None) -> list[str]:
    modes = ["paper"] if modes is None else modes
    if isinstance(modes, str) or not modes or len(set(modes)) != len(list(modes)):
        raise ValueError(f"modes must be distinct names from {list(VIEW_MODES)}, got {modes}")
    for m in modes:
        if m not in VIEW_MODES:
            raise ValueError(f"unknown mode {m!r}; choose from {list(VIEW_MODES)}")
    return list(modes)


def views_stage(mode: str, scene: str) -> str:
    """Name of the stage that runs ``mode``'s view jobs in ``scene``."""
    return f"views-{scene}" if mode == "paper" else f"views-{mode}-{scene}"


def _run_views(name, out_dir, opts, trackers, scenes, modes=None, light=1.0) -> dict[str, Any]:
    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    named = check_trackers(trackers or DEFAULT_TRACKERS)
    scenes = check_scenes(scenes)
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
    from vc_gym.jobs.output import new_figure, save_figure

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


def check_scenes(scenes: Sequence[str]) -> list[str]:
    from vc_gym.sim.scenes import check_scene_name

    out = [check_scene_name(s) for s in scenes]
    if len(set(out)) != len(out):
        raise ValueError(f"scenes given twice: {out}")
    return out


def _cost_info(run: ExperimentRun, modes: Sequence[str], scenes: Sequence[str]) -> dict[str, Any]:
    """Median ms per update of every tracker over the view jobs, overall and per mode
    (for ``run.json``; :func:`cost_lines` prints them)."""

    def timings(mode: str) -> list[Any]:
        stages = [run.timings.get(views_stage(mode, scene), {}) for scene in scenes]
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
