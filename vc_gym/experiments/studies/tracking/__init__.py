"""The tracking experiment: does a tracker keep the pose of a robot that walks across the
whole field, and does it find the robot again after a kidnapping?

Beyond the paper, whose robot stood still (5.1) or walked home (5.2). The place is
learned once per (scene, learning seed) as maps on a grid of spots over the whole field,
the orientation experiment's ``spot-grid`` learning (its compass options, its tracker
options), with the four turns around each spot kept as atlas entries of their own
(``keep_around``). Each job then drives the robot along one seeded route
(:func:`make_route`) with the room dimmed to a light level: a controller that knows the
*true* pose (this measures tracking, not control) turns towards each waypoint and walks
there at up to 0.4 m/s, turns on the spot by 90-360° at some waypoints, and scans with
its head whenever it does not walk forward, as the homing agents do
(:class:`RouteDriver`). Once, at a time drawn in the middle of the route, the robot is
kidnapped: put at a random pose the way the homing task puts it (a reset of the room
at that pose), and the tracker is not told. Every frame the tracker gets the head-camera
image, the head pan and the robot's noisy odometry since the previous frame, exactly
what ``CompassObservation`` gives it in the homing task; the true pose and the belief
are recorded.

Figures (``results.json``; per scene, light and tracker, pooled, per learning seed and
mean ± std over seeds): the mean heading and position errors after the first
``settle_s`` (10 s), without and with the re-localisation window after the kidnapping;
the time to re-localise (:func:`relocalisation_time`) and the share of kidnappings
re-localised within 10 s; the 2σ coverage of the stated heading spread and position
standard deviation (:func:`two_sigma_coverage`); and the errors against time in 1 s
bins. Milliseconds per update go to ``run.json`` only. Plots: ``errors_<scene>.png``
(errors against time, a curve per route, the kidnapping marked) and
``belief_<scene>.png`` (one route on the top view: true and believed paths, ±2σ
ellipses, particles of a tracker that has them).

The parts live in modules of their own: the routes and their driver in
:mod:`~vc_gym.experiments.studies.tracking.routes`, the job that drives one route in
:mod:`~vc_gym.experiments.studies.tracking.job`, the measures and the pooled figures in
:mod:`~vc_gym.experiments.studies.tracking.figures`, the plots in
:mod:`~vc_gym.experiments.studies.tracking.plots`. This module sizes and runs the
experiment, says its results in a few lines, and re-exports the names of its
``__all__`` (the jobs name ``route_job`` here, as ``...studies.tracking:route_job``).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any

from vc_gym.experiments.atlases import atlas_key, atlas_spec, ensure_atlases
from vc_gym.experiments.options import check_light_list, check_seed_list
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    check_scenes,
    median_timings,
    open_run,
    pick_size,
    safe_name,
    scene_field_bounds,
)
from vc_gym.experiments.studies.orientation_grid import (
    GRID_AROUND_M,
    VIEW_MODES,
    check_trackers,
    mode_trackers,
    training_spots,
)
from vc_gym.experiments.studies.tracking.figures import (
    RELOCALISED_HEADING_DEG,
    RELOCALISED_HOLD_S,
    RELOCALISED_POSITION_M,
    RELOCALISED_WITHIN_S,
    relocalisation_time,
    route_figures,
    tracker_summary,
    two_sigma_coverage,
)
from vc_gym.experiments.studies.tracking.job import route_job
from vc_gym.experiments.studies.tracking.plots import plot_belief, plot_errors, snapshot_times
from vc_gym.experiments.studies.tracking.routes import (
    ARRIVED_M,
    MAX_FORWARD_M_S,
    MAX_TURN_DEG_S,
    MIN_LEG_M,
    ROUTE_MARGIN_M,
    Route,
    RouteDriver,
    make_route,
)
from vc_gym.jobs.job import Job
from vc_gym.sim.scenes import scene_names
from vc_gym.validation import (
    MAX_EPISODES,
    MAX_LEARN_TIME_S,
    int_in_range,
    positive_float,
    positive_float_at_most,
)

__all__ = [
    "ARRIVED_M",
    "DEFAULT_TRACKERS",
    "MAX_FORWARD_M_S",
    "MAX_TURN_DEG_S",
    "MIN_LEG_M",
    "RELOCALISED_HEADING_DEG",
    "RELOCALISED_HOLD_S",
    "RELOCALISED_POSITION_M",
    "RELOCALISED_WITHIN_S",
    "ROUTE_MARGIN_M",
    "SIZES",
    "Route",
    "RouteDriver",
    "cost_lines",
    "make_route",
    "relocalisation_time",
    "route_figures",
    "route_job",
    "run_tracking",
    "summary_lines",
    "two_sigma_coverage",
]

#: The trackers compared unless told otherwise (``pose``: a pose belief over the whole
#: field on maps re-drawn for a position, the atlas' turns around each spot its input).
DEFAULT_TRACKERS = ("pose", "grid", "particle")

#: Sizes: ``routes`` per learning seed, each ``route_s`` of simulated time with the
#: kidnapping at a time drawn in ``kidnap_s``; errors count from ``settle_s``;
#: ``spots_m``: spacing of the learned spots (``None``: the spot-grid mode's 1.0 m);
#: ``trackers``: the default trackers (``None``: :data:`DEFAULT_TRACKERS`); ``scenes``
#: ``None``: every registered scene.
SIZES = {
    "quick": {
        "scenes": ["robolab"],
        "lights": [1.0],
        "seeds": 1,
        "routes": 1,
        "route_s": 8.0,
        "kidnap_s": [4.0, 4.0],
        "settle_s": 1.0,
        "learn_time_s": 0.3,
        "spots_m": 4.0,
        "trackers": ["grid"],
    },
    "paper": {
        "scenes": ["robolab"],
        "lights": [1.0, 0.5],
        "seeds": 1,
        "routes": 2,
        "route_s": 60.0,
        "kidnap_s": [25.0, 35.0],
        "settle_s": 10.0,
        "learn_time_s": 5.0,
        "spots_m": None,
        "trackers": None,
    },
}
#: ``full``: ``paper`` in every scene over three learning seeds.
SIZES["full"] = {**SIZES["paper"], "scenes": None, "seeds": 3}


# ---------------------------------------------------------------------- the runner
def run_tracking(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    trackers: Sequence[Any] | None = None,
    scenes: Sequence[str] | None = None,
    seeds: Sequence[int] | None = None,
    lights: Sequence[float] | None = None,
    episodes: int | None = None,
    learn_time_s: float | None = None,
) -> dict[str, Any]:
    """Run the tracking experiment and write its results and plots.

    Parameters
    ----------
    out_dir : path-like
        The run folder (resumable).
    opts : ExperimentOptions
        Seed, size (:data:`SIZES`), backend, ``--atlas``, ``--video`` (the first N
        routes as MP4).
    trackers : sequence, optional
        Tracker specs (default by size; ``full``: :data:`DEFAULT_TRACKERS`).
    scenes : sequence of str, optional
        Default by size (``full``: every registered scene).
    seeds : sequence of int, optional
        Learning seeds (default by size, from ``opts.seed`` on: 0, 1, 2).
    lights : sequence of float, optional
        Room illuminations during the routes, in ``(0, 1]`` (default 1.0 and 0.5; the
        atlases are learned at full light).
    episodes : int, optional
        Routes per (scene, learning seed) (default 2), each with one kidnapping.
    learn_time_s : float, optional
        Learning time per direction (default by size; the paper's 5 s).

    Returns
    -------
    dict
        The results written to ``results.json``.
    """
    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    named = check_trackers(trackers or size["trackers"] or DEFAULT_TRACKERS)
    scenes = check_scenes(scenes or size["scenes"] or scene_names())
    seeds = list(seeds) if seeds else [opts.seed + k for k in range(size["seeds"])]
    check_seed_list("seeds", seeds)
    if len(set(seeds)) != len(seeds):
        raise ValueError(f"seeds given twice: {seeds}")
    lights = [positive_float("lights", v) for v in (lights or size["lights"])]
    check_light_list("lights", lights)
    routes = int_in_range(
        "episodes", size["routes"] if episodes is None else episodes, 1, MAX_EPISODES
    )
    learn_time_s = positive_float_at_most(
        "learn_time_s",
        size["learn_time_s"] if learn_time_s is None else learn_time_s,
        MAX_LEARN_TIME_S,
    )
    settings = {
        "trackers": named,
        "scenes": scenes,
        "seeds": seeds,
        "lights": lights,
        "routes": routes,
        "learn_time_s": learn_time_s,
        **{k: size[k] for k in ("route_s", "kidnap_s", "settle_s", "spots_m")},
    }
    run = open_run(out_dir, "tracking", opts, settings)
    jobs_trackers = mode_trackers(named, "spot-grid")
    bounds = {scene: scene_field_bounds(scene) for scene in scenes}
    spots = {s: training_spots(b, "spot-grid", size["spots_m"]) for s, b in bounds.items()}
    specs = {
        (scene, seed): atlas_spec(
            scene,
            seed,
            "grid",
            learn_time_s,
            VIEW_MODES["spot-grid"],
            spots=spots[scene],
            around_m=GRID_AROUND_M,
            keep_around=True,
            learning={"landmarks": True},  # the bearings tracker's; no other tracker's
        )
        for scene in scenes
        for seed in seeds
    }
    paths = ensure_atlases(run, list(specs.values()), opts.atlas_dir)

    jobs, where = [], []
    for scene in scenes:
        for light in lights:
            for seed in seeds:
                for index in range(routes):
                    route = make_route(
                        bounds[scene], seed, index, size["route_s"], size["kidnap_s"]
                    )
                    first = seed == seeds[0] and index == 0
                    for t, (name, spec) in enumerate(jobs_trackers.items()):
                        key = (
                            f"{scene}-light{light:g}-seed{seed}-route{index}-t{t}-{safe_name(name)}"
                        )
                        kwargs = {
                            "scene": scene,
                            "atlas": paths[atlas_key(specs[(scene, seed)])],
                            "light": light,
                            "route": route.to_dict(),
                            "name": name,
                            "tracker": spec,
                            "snapshots_s": snapshot_times(route, size["settle_s"]) if first else [],
                        }
                        if len(jobs) < opts.video:
                            folder = run.out / "videos"
                            folder.mkdir(exist_ok=True)
                            kwargs["video"] = str((folder / f"{key}.mp4").resolve())
                            kwargs["spots"] = [list(p) for p in spots[scene]]
                        # route_job is re-exported here: the job keeps the name
                        # "vc_gym.experiments.studies.tracking:route_job"
                        jobs.append(Job(key, f"{__name__}:route_job", kwargs))
                        where.append((scene, light, seed, index, name, route))
    outputs = run.run("routes", jobs)

    grouped: dict[tuple, list[dict[str, Any]]] = {}
    for (scene, light, seed, index, name, route), out in zip(where, outputs, strict=True):
        if out is None:
            continue
        grouped.setdefault((scene, light, name), []).append(
            {
                "seed": seed,
                "index": index,
                "route": route.to_dict(),
                "frames": out["frames"],
                "particles": out.get("particles", {}),
            }
        )
    results: dict[str, Any] = {
        "criteria": {
            "settle_s": size["settle_s"],
            "relocalised_position_m": RELOCALISED_POSITION_M,
            "relocalised_heading_deg": RELOCALISED_HEADING_DEG,
            "relocalised_hold_s": RELOCALISED_HOLD_S,
            "relocalised_within_s": RELOCALISED_WITHIN_S,
        },
        "scenes": {},
    }
    for scene in scenes:
        per_light = {}
        for light in lights:
            per_tracker = {
                name: tracker_summary(grouped[(scene, light, name)], size["settle_s"])
                for name in named
                if (scene, light, name) in grouped
            }
            per_light[f"{light:g}"] = {"trackers": per_tracker}
        results["scenes"][scene] = {"spots": len(spots[scene]), "lights": per_light}
        plot_errors(run.out / f"errors_{scene}.png", scene, lights, named, grouped)
        plot_belief(
            run.out / f"belief_{scene}.png",
            scene,
            lights[0],
            seeds[0],
            named,
            grouped,
            bounds[scene],
            spots[scene],
        )
    costs = median_timings(run.timings.get("routes", {}).values())
    return run.finish(results, {"ms_per_update_median": costs})


# ---------------------------------------------------------------------- lines
def cost_lines(run_info: Mapping[str, Any]) -> list[str]:
    """Median ms per update of every tracker over the routes (from ``run.json``)."""
    costs = run_info.get("ms_per_update_median") or {}
    if not costs:
        return []
    return [
        "cost per frame (median ms per update): "
        + ", ".join(f"{n} {v:.2f}" for n, v in costs.items() if v is not None)
    ]


def summary_lines(results: Mapping[str, Any]) -> list[str]:
    """Per scene, light and tracker: errors, re-localisation and 2σ coverage."""
    crit = results.get("criteria", {})
    settle = crit.get("settle_s", 10.0)
    lines = [
        f"errors after {settle:g} s without the re-localisation window (with it); "
        "mean ± std over learning seeds"
    ]

    def pm(over: Mapping[str, Any], key: str, unit: str, digits: int) -> str:
        v = over.get(key)
        return "-" if v is None else f"{v[0]:.{digits}f} ± {v[1]:.{digits}f}{unit}"

    def pct(v: float | None) -> str:
        return "-" if v is None else f"{100 * v:.0f} %"

    for scene, r in results.get("scenes", {}).items():
        lines.append(f"{scene} ({r['spots']} spots):")
        for light, per in r["lights"].items():
            for name, t in per["trackers"].items():
                o = t["over_seeds"]
                reloc = (
                    f"median {t['median_relocalisation_s']:.1f} s"
                    if t["median_relocalisation_s"] is not None
                    else "never"
                )
                heading = pm(o, "mean_heading_error_deg", "°", 1)
                position = pm(o, "mean_position_error_m", " m", 2)
                lines.append(
                    f"  light {light}, {name[:40]}: heading {heading} "
                    f"({t['mean_heading_error_with_relocalisation_deg']}°), position {position} "
                    f"({t['mean_position_error_with_relocalisation_m']} m)"
                )
                lines.append(
                    f"      re-localised {t['relocalised']}/{t['routes']} ({reloc}; "
                    f"{pct(t['relocalised_within_10s'])} within 10 s); 2σ covers heading "
                    f"{pct(t['heading_coverage_2sigma'])}, position "
                    f"{pct(t['position_coverage_2sigma'])}"
                )
    for f in results.get("failed_jobs", []):
        lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
    return lines
