"""Every heading sensor under one protocol: the visual compass against the baselines.

The paper argues against other ways to get a heading (section 6); this experiment
measures them. In every scene each sensor learns the same frames at the orientation
experiment's training spot (8 directions × a head scan, true yaws), then says the
heading of the same seeded views at the spot, 1, 2 and 4 m from it, at full and half
light. The magnetometer reads the true heading of each view through its own noise and
a seeded disturbance field. The same sensors then run the real-photo protocol of
``vc-gym experiment real-rotation`` on ``../shared/data/real`` (learn 9 alternate
photos, estimate crops of the other 9).

``results.json`` holds, per sensor, the median and 90th percentile |heading error|
per scene, distance and light, and on the real sets; ``run.json`` the learn and
localise milliseconds per frame (timings are not figures); ``sensors.png`` error
against distance and accuracy against cost, with the accuracy/cost front.
"""

from __future__ import annotations

import math
import os
import time
import zlib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from vc_gym.angles import wrap180
from vc_gym.experiments.real_data import ROTATION_SETS, default_real_data_dir, load_rotation_set
from vc_gym.experiments.real_rotation import rotation_set_errors
from vc_gym.experiments.spot_sensors import fit_colors, room, teach
from vc_gym.experiments.studies import get_experiment
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    check_scenes,
    median_timings,
    open_run,
    pick_size,
    scene_field_bounds,
)
from vc_gym.experiments.studies.orientation_grid import rear_half_centre
from vc_gym.experiments.views import frames_at_pose, learning_turn
from vc_gym.heading_sensors import NoisyMagneticCompass, make_sensor
from vc_gym.jobs.job import Job
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.jobs.run import ExperimentRun
from vc_gym.sim.scenes import scene_names

__all__ = [
    "DISTANCES_M",
    "LIGHTS",
    "SENSORS",
    "cost_lines",
    "run_sensors",
    "summary_lines",
]

#: Sensors compared, by the name the results use: a sensor spec
#: (:func:`vc_gym.heading_sensors.make_sensor`).
SENSORS: dict[str, Any] = {
    "visual_compass": "visual_compass",
    "visual_compass_mean_exposure": {"type": "visual_compass", "exposure": "mean"},
    "image_difference": "image_difference",
    "sector_color": "sector_color",
    "feature": "feature",
    "magnetic": "magnetic",
}
#: How far from the training spot the views are taken (metres).
DISTANCES_M = (0.0, 1.0, 2.0, 4.0)
#: Light while localising (learned at 1.0).
LIGHTS = (1.0, 0.5)
#: Keep views this far inside the field's bounds (metres).
VIEW_MARGIN_M = 0.3
#: The magnetometer's field: sources of disturbance per scene, their peak deviation and
#: radius (steel furniture), and its white noise.
MAGNETIC_FIELD = {"n_sources": 4, "deviation_deg": 25.0, "radius_m": 0.6, "noise_deg": 3.0}
#: Trackers of the homing part: ``atlas`` is the paper's grid tracker on the learned
#: atlas; every other name is an image sensor as its heading sensor
#: (``vc-gym experiment homing --sensor NAME``); the magnetometer sits in the head.
HOMING_SENSORS = (
    "atlas",
    "visual_compass",
    "image_difference",
    "sector_color",
    "feature",
    "magnetic",
)
#: What the sensor experiment reports of each homing run.
HOMING_FIGURES = (
    "episodes",
    "success_rate",
    "mean_stop_distance_cm",
    "median_stop_distance_cm",
    "far_stops",
    "timed_out",
    "mean_heading_error_deg",
)
SIZES = {
    "quick": {"learn_frames": 2, "views": 2, "homing_episodes": 0},
    "paper": {"learn_frames": 8, "views": 8, "homing_episodes": 11},
    "full": {"learn_frames": 8, "views": 20, "homing_episodes": 33},
}


def view_poses_at(
    spot: Sequence[float],
    bounds: Sequence[float],
    distance_m: float,
    n: int,
    rng: np.random.Generator,
) -> list[list[float]]:
    """``n`` poses ``distance_m`` from ``spot`` in random directions, inside the field
    (``VIEW_MARGIN_M`` from its edges), each with a random heading; fewer (possibly
    none) where the field has no room at that distance."""
    x0, x1, y0, y1 = (float(v) for v in bounds)
    m = VIEW_MARGIN_M
    poses: list[list[float]] = []
    for _ in range(200 * max(n, 1)):
        if len(poses) == n:
            break
        a = rng.uniform(0.0, 2.0 * math.pi)
        x, y = spot[0] + distance_m * math.cos(a), spot[1] + distance_m * math.sin(a)
        if x0 + m <= x <= x1 - m and y0 + m <= y <= y1 - m:
            poses.append([round(x, 4), round(y, 4), round(float(rng.uniform(0.0, 360.0)), 3)])
    return poses


def _is_magnetic(spec: Any) -> bool:
    """Whether a sensor spec names the magnetometer (it reads poses, not images)."""
    kind = spec.get("type") if isinstance(spec, Mapping) else spec
    return kind == "magnetic"


def _magnetometer(scene: str, bounds: Sequence[float], seed: int) -> NoisyMagneticCompass:
    rng = np.random.default_rng([seed, 97, zlib.crc32(scene.encode())])
    return NoisyMagneticCompass.random_field(bounds, rng, **MAGNETIC_FIELD)


def sensors_scene_job(
    scene: str,
    spot: list[float],
    bounds: list[float],
    sensors: dict[str, Any],
    learn_frames: int,
    views: list[dict[str, Any]],
    seed: int,
) -> dict[str, Any]:
    """Job: every sensor learns the spot of one scene, then reads every view.

    Returns ``{"views": [{"distance_m", "light", "pose", "errors": {sensor: |error|},
    "spreads": {sensor: spread}}], "timing": {"<sensor>/learn": ms per frame,
    "<sensor>/localise": ms per frame}}``.
    """
    rooms = {light: room(scene, light) for light in sorted({v["light"] for v in views} | {1.0})}
    learning = learning_turn(rooms[1.0], spot, learn_frames, seed)
    camera = learning[0][1].replace(yaw_deg=0.0)
    built, timing = {}, {}
    for name, spec in sensors.items():
        if _is_magnetic(spec):
            built[name] = _magnetometer(scene, bounds, seed)
            continue
        sensor = make_sensor(spec)
        fit_colors(sensor, learning)  # once per place: not part of the per-frame cost
        t0 = time.perf_counter()
        teach(sensor, learning)
        timing[f"{name}/learn"] = 1e3 * (time.perf_counter() - t0) / len(learning)
        built[name] = sensor
    out, cost = [], {name: [] for name in built}
    for i, view in enumerate(views):
        pose = view["pose"]
        (image, pan, _), *_ = frames_at_pose(
            rooms[view["light"]], tuple(pose), 1, seed=seed + 100 + i
        )
        truth = pose[2] + pan
        errors, spreads = {}, {}
        for name, sensor in built.items():
            t0 = time.perf_counter()
            if isinstance(sensor, NoisyMagneticCompass):
                rng = np.random.default_rng([seed, 7, i])
                est = sensor.estimate(sensor.read((pose[0], pose[1], truth), rng))
            else:
                est = sensor.estimate(image, camera)
            cost[name].append(1e3 * (time.perf_counter() - t0))
            errors[name] = round(abs(float(wrap180(est.heading_deg - truth))), 3)
            spreads[name] = round(min(float(est.spread_deg), 1e6), 3)
        out.append({**view, "errors": errors, "spreads": spreads})
    for name, ms in cost.items():
        timing[f"{name}/localise"] = float(np.median(ms))
    return {"views": out, "timing": timing}


def sensors_real_job(folder: str, sensors: dict[str, Any]) -> dict[str, Any]:
    """Job: the real-photo crop protocol for every image sensor on one rotation set."""
    photos = load_rotation_set(folder)
    out, timing = {}, {}
    for name, spec in sensors.items():
        if _is_magnetic(spec):
            continue
        r = rotation_set_errors(photos, make_sensor(spec), prepare=teach, setup=fit_colors)
        e = np.asarray(r["errors_deg"])
        out[name] = _error_stats(e)
        timing[f"{name}/learn"] = r["learn_ms"]
        timing[f"{name}/localise"] = r["localise_ms"]
    return {"sensors": out, "timing": timing}


def _error_stats(errors: np.ndarray) -> dict[str, Any]:
    return {
        "median_abs_error_deg": round(float(np.median(errors)), 2),
        "p90_abs_error_deg": round(float(np.percentile(errors, 90)), 2),
        "within_10deg": round(float(np.mean(errors <= 10.0)), 4),
        "n": int(errors.size),
    }


def run_sensors(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    scenes: Sequence[str] | None = None,
    data_dir: str | os.PathLike | None = None,
) -> dict[str, Any]:
    """Run the sensor comparison; write ``results.json``, ``run.json``, ``sensors.png``.

    Parameters
    ----------
    out_dir : path-like
        The run folder (resumable).
    opts : ExperimentOptions
        Seed (view poses, head scans, the magnetometer's field) and size.
    scenes : sequence of str, optional
        Registered scenes (default: every registered scene).
    data_dir : path-like, optional
        Folder of the real rotation sets (default ``../shared/data/real`` when it
        exists; without it the real part is skipped and the results say so).

    Returns
    -------
    dict
        Per sensor: per scene, distance and light the median and 90th percentile
        |heading error|; the same pooled over scenes; on the real sets.
    """
    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    scenes = check_scenes(list(scenes) if scenes else list(scene_names()))
    real = Path(data_dir) if data_dir is not None else default_real_data_dir()
    if real is not None and not all((real / s).is_dir() for s in ROTATION_SETS):
        raise ValueError(f"--data {real}: expected the folders {sorted(ROTATION_SETS)}")
    settings = {
        "scenes": scenes,
        "sensors": SENSORS,
        "distances_m": list(DISTANCES_M),
        "lights": list(LIGHTS),
        "magnetic_field": MAGNETIC_FIELD,
        **size,
    }
    run = open_run(out_dir, "sensors", opts, settings)
    jobs = []
    for s_i, scene in enumerate(scenes):
        bounds = scene_field_bounds(scene)
        spot = rear_half_centre(bounds)
        rng = np.random.default_rng([opts.seed, 61, zlib.crc32(scene.encode())])
        views = [
            {"distance_m": d, "light": light, "pose": pose}
            for d in DISTANCES_M
            for pose in view_poses_at(spot, bounds, d, size["views"], rng)
            for light in LIGHTS
        ]
        kwargs = {
            "scene": scene,
            "spot": list(spot),
            "bounds": list(bounds),
            "sensors": SENSORS,
            "learn_frames": size["learn_frames"],
            "views": views,
            "seed": int(opts.seed * 1_000_000 + s_i * 10_000),
        }
        jobs.append(Job(scene, f"{__name__}:sensors_scene_job", kwargs))
    outputs = run.run("views", jobs)
    results: dict[str, Any] = {
        "paper": {"claim": "section 6: other heading sensors are worse suited to the task"},
        "simulated": _summarise_views([o for o in outputs if o is not None], scenes),
    }
    if real is not None:
        real_jobs = [
            Job(s, f"{__name__}:sensors_real_job", {"folder": str(real / s), "sensors": SENSORS})
            for s in ROTATION_SETS
        ]
        real_out = run.run("real", real_jobs)
        results["real"] = {
            s: o["sensors"] for s, o in zip(ROTATION_SETS, real_out, strict=True) if o is not None
        }
    else:
        results["real"] = None
        results["real_skipped"] = "no ../shared/data/real folder (give --data DIR)"
    if size["homing_episodes"]:
        results["homing"] = _homing(run, opts, size["homing_episodes"])
    cost = _cost_info(run)
    _plot(run.out / "sensors.png", results, cost)
    return run.finish(results, cost)


def _homing(run: ExperimentRun, opts: ExperimentOptions, episodes: int) -> dict[str, Any]:
    """The homing experiment (robolab, learning seed ``opts.seed``) with every tracker of
    :data:`HOMING_SENSORS`, each a run of its own in ``DIR/homing/<name>`` on the same
    atlas and kidnappings."""
    out: dict[str, Any] = {}
    atlas_dir = opts.atlas_dir
    run_homing = get_experiment("homing").runner()
    for name in HOMING_SENSORS:
        sub = ExperimentOptions(
            seed=opts.seed,
            size=opts.size,
            backend=run.backend,
            atlas_dir=atlas_dir,
            progress=opts.progress,
        )
        folder = run.out / "homing" / name
        r = run_homing(
            folder, sub, episodes=episodes, field=False, sensor=None if name == "atlas" else name
        )
        if atlas_dir is None and (folder / "atlases").is_dir():
            atlas_dir = folder / "atlases"  # every sensor homes on the same atlas
        overall = r.get("overall", {})
        out[name] = {k: overall.get(k) for k in HOMING_FIGURES}
    return out


def _summarise_views(outputs: Sequence[Mapping[str, Any]], scenes: Sequence[str]) -> dict:
    views = [v for o in outputs for v in o["views"]]
    names = list(views[0]["errors"]) if views else []
    table: dict[str, Any] = {}
    for name in names:
        per: dict[str, Any] = {"all_scenes": {}, "scenes": {}}
        for light in LIGHTS:
            for d in DISTANCES_M:
                key = f"{d:g}m_light{light:g}"
                sel = [v for v in views if v["distance_m"] == d and v["light"] == light]
                if sel:
                    per["all_scenes"][key] = _error_stats(
                        np.array([v["errors"][name] for v in sel])
                    )
                for scene, o in zip(scenes, outputs, strict=False):
                    mine = [v for v in o["views"] if v["distance_m"] == d and v["light"] == light]
                    if mine:
                        per["scenes"].setdefault(scene, {})[key] = _error_stats(
                            np.array([v["errors"][name] for v in mine])
                        )
        for light in LIGHTS:
            near = [
                v["errors"][name] for v in views if v["distance_m"] <= 2.0 and v["light"] == light
            ]
            per[f"within_2m_light{light:g}"] = _error_stats(np.array(near)) if near else None
        table[name] = per
    return {"sensors": table, "views": len(views)}


def _cost_info(run: Any) -> dict[str, Any]:
    """Median learn and localise ms per frame of every sensor (for ``run.json``)."""
    per_stage = {stage: median_timings(t.values()) for stage, t in run.timings.items()}
    return {"ms_per_frame_median": per_stage}


def cost_lines(run_info: Mapping[str, Any]) -> list[str]:
    """The sensors' cost per frame, from ``run.json``."""
    sim = run_info.get("ms_per_frame_median", {}).get("views", {})
    names = sorted({k.split("/")[0] for k in sim})
    lines = []
    for name in names:
        learn = sim.get(f"{name}/learn")
        loc = sim.get(f"{name}/localise")
        lines.append(
            f"{name:24s} learn {'-' if learn is None else f'{learn:.2f}'} ms/frame, "
            f"localise {'-' if loc is None else f'{loc:.3f}'} ms/frame (208x160, median)"
        )
    return lines


def _plot(path: Path, results: Mapping[str, Any], cost: Mapping[str, Any]) -> None:
    """Left: median |error| vs distance (full light solid, half dashed) per sensor;
    right: median |error| within 2 m against localise ms per frame, with the front."""
    sensors = results["simulated"]["sensors"]
    homing = results.get("homing")
    fig = new_figure(figsize=(16 if homing else 11, 4.3), layout="constrained")
    axes = fig.subplots(1, 3 if homing else 2)
    ax, ax2 = axes[0], axes[1]
    colors = {n: f"C{i}" for i, n in enumerate(sensors)}
    for name, per in sensors.items():
        for light, style in ((1.0, "o-"), (0.5, "s--")):
            pts = [
                (d, per["all_scenes"][f"{d:g}m_light{light:g}"]["median_abs_error_deg"])
                for d in DISTANCES_M
                if f"{d:g}m_light{light:g}" in per["all_scenes"]
            ]
            if pts:
                ax.plot(
                    *zip(*pts, strict=True),
                    style,
                    color=colors[name],
                    ms=4,
                    label=name if light == 1.0 else None,
                )
    ax.set_yscale("log")
    ax.set_xlabel("distance from the training spot (m)")
    ax.set_ylabel("median |heading error| (°), all scenes")
    ax.set_title("accuracy vs distance (solid: full light, dashed: half)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ms = cost.get("ms_per_frame_median", {}).get("views", {})
    pts = []
    for name, per in sensors.items():
        loc = ms.get(f"{name}/localise")
        full, half = per.get("within_2m_light1"), per.get("within_2m_light0.5")
        if loc is None or full is None:
            continue
        err = full["median_abs_error_deg"]
        pts.append((loc, err, name))
        ax2.scatter([loc], [err], color=colors[name], s=45, zorder=3, label=name)
        if half is not None:
            ax2.scatter(
                [loc],
                [half["median_abs_error_deg"]],
                s=45,
                zorder=3,
                facecolors="none",
                edgecolors=colors[name],
            )
    front = _front(pts)
    if len(front) > 1:
        ax2.step(
            [p[0] for p in front],
            [p[1] for p in front],
            where="post",
            color="0.5",
            lw=1,
            ls=":",
            label="front (full light)",
        )
    ax2.scatter([], [], facecolors="none", edgecolors="0.4", label="(hollow: half light)")
    ax2.legend(fontsize=7)
    ax2.set_xscale("log")
    ax2.set_yscale("log")
    for axis in (ax2.xaxis, ax2.yaxis, ax.yaxis):
        axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        axis.set_minor_formatter(NullFormatter())
    ax2.set_xlabel("localise ms per frame (median, this machine)")
    ax2.set_ylabel("median |heading error| within 2 m (°)")
    ax2.set_title("accuracy against cost (lower left is better)", fontsize=10)
    ax2.grid(alpha=0.3, which="both")
    if homing:
        _plot_homing(axes[2], homing, colors)
    save_figure(fig, path)


def _plot_homing(ax: Any, homing: Mapping[str, Any], colors: Mapping[str, str]) -> None:
    """Homing success per tracker heading sensor, with stop distance and heading error."""
    names = list(homing)
    success = [100.0 * (homing[n]["success_rate"] or 0.0) for n in names]
    ax.bar(range(len(names)), success, color=[colors.get(n, "0.5") for n in names])
    for i, n in enumerate(names):
        h = homing[n]
        ax.annotate(
            f"{h['mean_stop_distance_cm']} cm\n{h['mean_heading_error_deg']}°",
            (i, success[i]),
            ha="center",
            va="bottom",
            fontsize=7,
        )
    ax.set_xticks(range(len(names)), names, rotation=25, ha="right", fontsize=8)
    ax.set_ylim(0, 115)
    ax.set_ylabel("homing success within 30 cm (%)")
    episodes = homing[names[0]]["episodes"] if names else 0
    ax.set_title(
        f"homing with each heading sensor ({episodes} kidnappings;\n"
        "labels: mean stop distance, mean heading error)",
        fontsize=10,
    )


def _front(points: Sequence[tuple[float, float, str]]) -> list[tuple[float, float, str]]:
    """The points no other point beats on both cost and error, by cost."""
    front: list[tuple[float, float, str]] = []
    for p in sorted(points):
        if not front or p[1] < front[-1][1]:
            front.append(p)
    return front


def summary_lines(results: Mapping[str, Any]) -> list[str]:
    """Per sensor: median / 90th percentile |error| at each distance (full light), within
    2 m at half light, and on the real sets."""
    lines = []
    sensors = results.get("simulated", {}).get("sensors", {})
    for name, per in sensors.items():
        parts = []
        for d in DISTANCES_M:
            s = per["all_scenes"].get(f"{d:g}m_light1")
            if s:
                parts.append(f"{d:g} m {s['median_abs_error_deg']}/{s['p90_abs_error_deg']}°")
        half = [
            per["all_scenes"][k]["median_abs_error_deg"]
            for k in per["all_scenes"]
            if k.endswith("light0.5")
        ]
        real = results.get("real") or {}
        r = [f"{s}: {v[name]['median_abs_error_deg']}°" for s, v in real.items() if name in v]
        lines.append(
            f"{name:24s} median/p90 |error|: "
            + ", ".join(parts)
            + (f"; half light medians {half}" if half else "")
            + (f"; real {', '.join(r)}" if r else "")
        )
    for name, h in (results.get("homing") or {}).items():
        lines.append(
            f"homing with {name:18s}: success {h['success_rate']:.0%}, mean stop distance "
            f"{h['mean_stop_distance_cm']} cm, {h['far_stops']} stops > 50 cm, mean heading "
            f"error {h['mean_heading_error_deg']}° ({h['episodes']} kidnappings)"
        )
    if results.get("real_skipped"):
        lines.append(f"real photos skipped: {results['real_skipped']}")
    for f in results.get("failed_jobs", []):
        lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
    return lines
