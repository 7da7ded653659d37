"""The orientation experiment's grid of views: put the robot at poses over the field and
record what every tracker believes about its heading (paper 5.1, fig. 4).

Shared by the orientation, environments, parameter, illumination and tracker
experiments. A mode (:data:`VIEW_MODES`) says where the maps are learned: ``paper`` at
the paper's single spot (the centre of the rear field half, :func:`rear_half_centre`);
``spot-grid`` the same way at every spot of a grid over the field (:data:`GRID_SPACING_M`
apart, :class:`~vc_gym.envs.learning.GridLearning`, shared colour classes, home the spot
nearest the paper's), plus four shorter turns :data:`GRID_AROUND_M` around each spot
into its map, with exposure-normalised colour classes (so that it holds at half light);
the trackers take the heading from the map that fits best (eq. 28), and distances are
measured from the nearest spot. Between full scorings the built-in trackers score only
the spots that fitted best (:data:`MODE_TRACKER_OPTIONS`), so a frame costs a few maps,
not two dozen.

:func:`orientation_stage` learns a mode's spots and runs one :func:`view_job` per grid
position (:func:`view_jobs`); :func:`views_summary` turns their outputs into the error
against distance (fig. 4 right) and :func:`headline_errors` into a row of a study.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from vc_gym.compass import Camera, CompassAtlas
from vc_gym.experiments.atlases import atlas_key, atlas_spec, ensure_atlases
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    check_tracker_spec,
    scene_field_bounds,
)
from vc_gym.experiments.views import (
    COMPASS,
    PAPER_ERROR_DEG,
    PAPER_RANGE_M,
    distance_table,
    evaluate_view,
    field_grid,
    frames_at_pose,
    spots_array,
    view_poses,
)
from vc_gym.jobs.job import Job
from vc_gym.jobs.run import ExperimentRun
from vc_gym.jobs.workers import worker_cache

__all__ = [
    "DEFAULT_TRACKERS",
    "GRID_AROUND_M",
    "GRID_MARGIN_M",
    "GRID_SPACING_M",
    "HEADLINE",
    "MODE_TRACKER_OPTIONS",
    "VIEW_MODES",
    "check_trackers",
    "headline_errors",
    "mode_trackers",
    "orientation_stage",
    "rear_half_centre",
    "training_spots",
    "view_job",
    "view_jobs",
    "views_stage",
    "views_summary",
]

#: The trackers an experiment compares unless told otherwise (the built-in ones).
DEFAULT_TRACKERS = ("grid", "kalman", "particle")
_BUILT_IN_TRACKERS = frozenset(DEFAULT_TRACKERS)

#: How the heading is learned over the field, by name (``--modes``): the compass
#: options of each mode (:class:`~vc_gym.compass.CompassConfig` fields).
VIEW_MODES: dict[str, dict[str, Any]] = {"paper": {}, "spot-grid": {"exposure": "mean"}}
#: Options each mode gives the built-in trackers (grid, kalman, particle): the spot-grid
#: mode's atlas has two dozen spots in robolab, so its trackers score every spot every
#: 8th frame and, in between, only the two that fitted best
#: (:class:`~vc_gym.localization.SpotShortlist`; a shortlist of three rescored every 4th
#: frame was hardly better and cost more).
MODE_TRACKER_OPTIONS: dict[str, dict[str, Any]] = {
    "paper": {},
    "spot-grid": {"shortlist": 2, "rescore_every": 8},
}
#: Spacing of the spot-grid mode's grid of spots (metres) and its margin inside the field
#: (1.0 m: 24 spots in robolab; the README compares it with a coarser grid).
GRID_SPACING_M = 1.0
GRID_MARGIN_M = 0.5
#: The spot-grid mode's maps also learn four turns this far around each spot
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
        seen = frames_at_pose(env, tuple(pose), frames, seed=seed + k)
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


def _round(v: Any) -> Any:
    return round(float(v), 3) if isinstance(v, float) else v


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


def views_stage(mode: str, scene: str) -> str:
    """Name of the stage that runs ``mode``'s view jobs in ``scene``."""
    return f"views-{scene}" if mode == "paper" else f"views-{mode}-{scene}"
