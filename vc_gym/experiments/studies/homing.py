"""The paper's homing experiment (5.2, fig. 5): stop positions over many kidnappings.

For every learning seed the robot learns the four spots 1 m around home once (the
atlas is saved and shared by every job), then each kidnapping is one job: a random pose
on the field from its own seed, homing with the scripted agent (or a learned one) and
any tracker until it has stood still for 5 s. The results hold every stop position, the
mean and standard deviation per axis (the paper: mean (−22, +12) cm, standard deviation
(17, 15) cm over 33 kidnappings), mean stop distance, success within 30 cm and stops
more than 50 cm from home, per learning seed and over all of them; and the likelihood
field of one spot over a 50 cm grid (fig. 5 right: the goodness of the map learned at
T = (100, 0) cm where the robot stands).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.agents.learned import PRETRAINED_MODEL, LearnedHomingAgent
from vc_gym.compass import Camera, CompassAtlas
from vc_gym.deprecation import moved_names
from vc_gym.envs.homing import home_offset
from vc_gym.envs.learning import HOME
from vc_gym.experiments.atlases import atlas_key, atlas_spec, ensure_atlases
from vc_gym.experiments.episode import (
    HOMING_MODES,
    canonical_homing_mode,
    check_agent_env,
    default_homing_mode,
    default_tracker,
    load_agent,
)
from vc_gym.experiments.spot_sensors import spot_sensor_job
from vc_gym.experiments.studies import kidnapping
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    check_tracker_spec,
    open_run,
    pick_size,
    scene_field_bounds,
)
from vc_gym.experiments.studies.kidnapping import EPISODE_JOB
from vc_gym.experiments.views import field_grid, frames_at_pose, plot_goodness_field, spot_goodness
from vc_gym.heading_sensors import IMAGE_SENSORS, SENSOR_GRID, current_sensor_name
from vc_gym.jobs.job import Job
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.jobs.workers import worker_cache
from vc_gym.localization import tracker_label
from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.sim.scenes import check_scene_name
from vc_gym.validation import flag, positive_float

__all__ = ["run_homing", "summary_lines"]

#: Names that moved to :mod:`~vc_gym.experiments.studies.kidnapping` (shared by every
#: experiment that homes): served here for one release, with a DeprecationWarning.
__getattr__ = moved_names(
    __name__,
    {
        name: (kidnapping, name)
        for name in (
            "PAPER_MEAN_CM",
            "PAPER_STD_CM",
            "episode_job",
            "mean_std",
            "spread_over_seeds",
            "summarise_stops",
        )
    },
)

#: How the place is learned and the scripted agent homes, by name (see
#: :data:`~vc_gym.experiments.episode.HOMING_MODES`).
MODES = HOMING_MODES
#: Frames per learning direction of a ``--sensor`` at home, by size.
SENSOR_FRAMES = {"quick": 2, "paper": 8, "full": 8}
#: ``--sensor`` name of the magnetometer (it reads the true heading, not images).
MAGNETIC = "magnetic"

SIZES = {
    "quick": {
        "episodes": 2,
        "learn_time_s": 0.3,
        "max_homing_s": 15.0,
        "field_spacing_m": 2.0,
        "field_headings": 2,
        "field_frames": 2,
    },
    "paper": {
        "episodes": 33,
        "learn_time_s": 5.0,
        "max_homing_s": 60.0,
        "field_spacing_m": 0.5,
        "field_headings": 4,
        "field_frames": 4,
    },
    "full": {
        "episodes": 33,
        "learn_time_s": 5.0,
        "max_homing_s": 60.0,
        "field_spacing_m": 0.5,
        "field_headings": 8,
        "field_frames": 8,
    },
}


def field_job(
    scene: str, atlas: str, x: float, y: float, headings: list[float], frames: int, seed: int
) -> dict[str, Any]:
    """Job: the mean normalised goodness of every spot at ``(x, y)`` (fig. 5 right)."""
    room = worker_cache(("room", scene), lambda: AiboRoomEnv(scene=scene))
    loaded = worker_cache(("atlas", atlas), lambda: CompassAtlas.load(atlas))
    camera = Camera(hfov_deg=room.camera.hfov_deg)
    per_heading = []
    for k, h in enumerate(headings):
        seen = frames_at_pose(room, (x, y, h), frames, seed=seed + k)
        per_heading.append(spot_goodness(seen, loaded, camera))
    return {
        "position": [x, y],
        "goodness": {n: float(np.mean([g[n] for g in per_heading])) for n in loaded.names},
    }


def run_homing(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    agent: str = "scripted",
    tracker: Any = None,
    seeds: Sequence[int] | None = None,
    episodes: int | None = None,
    scene: str = "robolab",
    learn_time_s: float | None = None,
    max_homing_s: float | None = None,
    success_radius_m: float = 0.3,
    relearn: str = "scene",
    field: bool = True,
    mode: str | None = None,
    sensor: str | None = None,
    home_offset_m: Sequence[float] | None = None,
    allow_imports: bool = False,
) -> dict[str, Any]:
    """Run the homing experiment and write ``results.json``, ``run.json`` and plots.

    Parameters
    ----------
    out_dir : path-like
        The run folder (resumable).
    opts : ExperimentOptions
        Seed, size, backend, ``--atlas``, ``--video``, progress.
    agent : str
        ``"scripted"``, ``"pretrained"`` or a learned agent's ``model.zip``.
    tracker : str or dict, optional
        The tracker of every episode (a name, ``"module:factory"`` or a dict); default
        a learned agent's own (the one it trained with), else the mode's (``grid``;
        ``pose-grid`` for ``pose-home``).
    seeds : sequence of int, optional
        Learning seeds (default: ``[opts.seed]``); kidnapping ``i`` of seed ``s`` uses
        seed ``s + 1 + i`` (so ``vc-gym demo --seed s`` is its first episode).
    episodes : int, optional
        Kidnappings per learning seed (default by size: 33, the paper's).
    scene : str
        Registered scene (a learned agent brings its own).
    learn_time_s, max_homing_s : float, optional
        Learning time per direction and homing time limit (defaults by size).
    success_radius_m : float
        A stop within this distance of home is a success.
    relearn : str
        ``"scene"``: learn once per seed (the paper's protocol); ``"episode"``: learn
        anew in every episode (slow).
    field : bool
        Also measure the likelihood field of fig. 5 (right).
    mode : str, optional
        ``"check-home"``, ``"paper"`` or ``"pose-home"`` (:data:`MODES`: how the place
        is learned, which tracker is the default and how the scripted agent homes). Default
        :func:`~vc_gym.experiments.episode.default_homing_mode`: check-home for the
        scripted agent, the mode of its training places for a learned one.
    sensor : str, optional
        An image sensor of :data:`vc_gym.heading_sensors.IMAGE_SENSORS` (``"feature"``,
        ``"image_difference"``, ...) as the grid tracker's heading sensor: for every
        learning seed it learns a turn at home with the true yaws
        (:data:`SENSOR_FRAMES` frames per direction) and is saved in ``DIR/sensors``;
        position still comes from the atlas. ``"magnetic"``: a magnetometer in the
        robot's head (:class:`~vc_gym.heading_sensors.MagnetometerCompass`, nothing learned).
        Needs the grid tracker.
    home_offset_m : (float, float), optional
        The scripted agent's goal relative to the tracker's home (world frame, m;
        ``ScriptedHomingPolicy(home_offset_m)``), e.g. a learned agent's measured one,
        to see what that goal alone is worth. A learned agent brings its own.
    allow_imports : bool
        Let a learned agent's ``config.json`` name its tracker by import path (imports
        that module): the command line's ``--allow-imports``, only for files you trust.

    Returns
    -------
    dict
        The results written to ``results.json``.
    """
    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    episodes = size["episodes"] if episodes is None else episodes
    learn_time_s = size["learn_time_s"] if learn_time_s is None else learn_time_s
    max_homing_s = size["max_homing_s"] if max_homing_s is None else max_homing_s
    seeds = [opts.seed] if seeds is None else [int(s) for s in seeds]
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an int >= 1, got {episodes!r}")
    if not seeds or any(s < 0 for s in seeds) or len(set(seeds)) != len(seeds):
        raise ValueError(f"seeds must be distinct ints >= 0, got {seeds}")
    for name, v in (
        ("learn_time_s", learn_time_s),
        ("max_homing_s", max_homing_s),
        ("success_radius_m", success_radius_m),
    ):
        positive_float(name, v)
    if relearn not in ("scene", "episode"):
        raise ValueError(f"relearn must be 'scene' or 'episode', got {relearn!r}")
    if mode is not None:
        mode = canonical_homing_mode(mode)
    if home_offset_m is not None:
        if agent != "scripted":
            raise ValueError(
                "home_offset_m is the scripted agent's goal; a learned agent brings its own "
                "(its config.json)"
            )
        home_offset_m = list(home_offset(home_offset_m))
    if agent == "pretrained":
        agent = str(PRETRAINED_MODEL)
    flag("allow_imports", allow_imports)
    if agent != "scripted":
        agent = str(Path(agent).resolve())
        # a bad model fails here, not in a worker
        loaded = LearnedHomingAgent(agent, allow_imports)
        check_agent_env(loaded, str(loaded.config_path))  # and a config the env refuses
        scene = loaded.scene
    else:
        check_scene_name(scene)
        loaded = load_agent(agent)
    mode = default_homing_mode(loaded) if mode is None else mode
    tracker = check_tracker_spec(default_tracker(loaded, mode) if tracker is None else tracker)
    if sensor is not None:
        sensor = current_sensor_name(sensor)  # a deprecated name warns and is replaced
        grid_options = _sensor_tracker_options(sensor, tracker, relearn)

    settings = {
        "agent": "scripted" if agent == "scripted" else Path(agent).parent.name,
        "tracker": tracker,
        "scene": scene,
        "seeds": seeds,
        "episodes_per_seed": episodes,
        "learn_time_s": learn_time_s,
        "max_homing_s": max_homing_s,
        "success_radius_m": success_radius_m,
        "relearn": relearn,
        "field": field,
        **({"mode": mode} if mode != "paper" else {}),
        **({"sensor": sensor} if sensor else {}),
        **({"home_offset_m": home_offset_m} if home_offset_m is not None else {}),
        **(
            {"sensor_frames": SENSOR_FRAMES[opts.size]}
            if sensor is not None and sensor != MAGNETIC
            else {}
        ),
    }
    run = open_run(out_dir, "homing", opts, settings)
    specs = {
        s: atlas_spec(scene, s, "scripted", learn_time_s, learning=MODES[mode].learning)
        for s in seeds
    }
    atlases = (
        ensure_atlases(run, list(specs.values()), opts.atlas_dir) if relearn == "scene" else {}
    )
    trackers = {s: tracker for s in seeds}
    if sensor is not None and sensor != MAGNETIC:
        files = _learn_home_sensors(run, scene, sensor, seeds, SENSOR_FRAMES[opts.size])
        trackers = {
            s: {**grid_options, "type": SENSOR_GRID, "sensor": sensor, "sensor_file": files[s]}
            for s in seeds
        }
    videos = run.out / "videos"
    jobs = []
    for s in seeds:
        for i in range(episodes):
            n = len(jobs)
            kwargs = {
                "agent": agent,
                "tracker": trackers[s],
                "scene": scene,
                "learn_time_s": learn_time_s,
                "success_radius_m": success_radius_m,
                "max_homing_s": max_homing_s,
                "atlas": atlases.get(atlas_key(specs[s])),
                "learning_seed": s,
                "episode_seed": s + 1 + i,
                **({"mode": mode} if mode != "paper" else {}),
                **({"magnetometer": True} if sensor == MAGNETIC else {}),
                **({"home_offset_m": home_offset_m} if home_offset_m is not None else {}),
                **({"allow_imports": True} if allow_imports and agent != "scripted" else {}),
            }
            if n < opts.video:
                kwargs["video"] = str((videos / f"seed{s}-episode{i:03d}.mp4").resolve())
            jobs.append(Job(f"seed{s}-episode{i:03d}", EPISODE_JOB, kwargs))
    if opts.video:
        videos.mkdir(exist_ok=True)
    outputs = run.run("episodes", jobs)
    done = [o for o in outputs if o is not None]
    results: dict[str, Any] = {
        "paper": {
            "mean_stop_offset_cm": list(kidnapping.PAPER_MEAN_CM),
            "std_stop_offset_cm": list(kidnapping.PAPER_STD_CM),
            "episodes": 33,
        },
    }
    per_seed = []
    for s in seeds:
        eps = [o for o in done if o["learning_seed"] == s]
        if eps:
            per_seed.append({"seed": s, **kidnapping.summarise_stops(eps, success_radius_m)})
    results["per_seed"] = per_seed
    if done:
        overall = kidnapping.summarise_stops(done, success_radius_m)
        if len(per_seed) > 1:
            overall.update(kidnapping.spread_over_seeds(per_seed))
        results["overall"] = overall
        _plot_stops(run.out / "stop_positions.png", done, settings, overall)
    if field and relearn == "scene":
        results["likelihood_field"] = _likelihood_field(
            run, opts, size, scene, atlases, specs[seeds[0]]
        )
    results["per_episode"] = done
    costs = [t.get("tracker_ms_per_update") for t in run.timings.get("episodes", {}).values()]
    costs = [c for c in costs if c is not None]
    info = {"tracker_ms_per_update_median": float(np.median(costs)) if costs else None}
    return run.finish(results, info)


def _sensor_tracker_options(sensor: str, tracker: Any, relearn: str) -> dict[str, Any]:
    """The grid tracker options ``tracker`` gives, checked for a ``--sensor`` run."""
    if sensor not in (*IMAGE_SENSORS, MAGNETIC):
        raise ValueError(f"--sensor {sensor!r}: choose one of {[*IMAGE_SENSORS, MAGNETIC]}")
    kind = tracker if isinstance(tracker, str) else tracker.get("type")
    if kind != "grid":
        raise ValueError(f"--sensor needs the grid tracker, got {kind!r}")
    if relearn != "scene":
        raise ValueError("--sensor needs relearn='scene' (the sensor is learned once a seed)")
    return {} if isinstance(tracker, str) else {k: v for k, v in tracker.items() if k != "type"}


def _learn_home_sensors(
    run: Any, scene: str, sensor: str, seeds: Sequence[int], frames: int
) -> dict[int, str]:
    """Teach ``sensor`` a turn at home for every learning seed; the saved files."""
    folder = run.out / "sensors"
    folder.mkdir(exist_ok=True)
    jobs = [
        Job(
            f"{sensor}-seed{s}",
            f"{spot_sensor_job.__module__}:spot_sensor_job",
            {
                "scene": scene,
                "sensor": sensor,
                "spot": list(HOME),
                "learn_frames": frames,
                "seed": int(s) * 1000 + 500,
                "path": str((folder / f"{sensor}-{scene}-seed{s}.npz").resolve()),
            },
        )
        for s in seeds
    ]
    outputs = run.run("sensors", jobs)
    missing = [j.key for j, o in zip(jobs, outputs, strict=True) if o is None]
    if missing:
        raise RuntimeError(f"learning the {sensor} sensor failed for {missing} (see results)")
    return {s: o["path"] for s, o in zip(seeds, outputs, strict=True)}


def _likelihood_field(run, opts, size, scene, atlases, spec) -> dict[str, Any]:
    bounds = scene_field_bounds(scene)
    grid = field_grid(bounds, size["field_spacing_m"], margin_m=0.0)
    path = atlases[atlas_key(spec)]
    rng = np.random.default_rng([opts.seed, 5])
    jobs = []
    for i, (x, y) in enumerate(grid):
        headings = sorted(rng.uniform(0, 360, size["field_headings"]).round(3).tolist())
        kwargs = {
            "scene": scene,
            "atlas": path,
            "x": round(float(x), 4),
            "y": round(float(y), 4),
            "headings": headings,
            "frames": size["field_frames"],
            "seed": int(opts.seed * 100_000 + i * 100),
        }
        jobs.append(Job(f"field-{i:04d}", f"{__name__}:field_job", kwargs))
    outputs = [o for o in run.run("field", jobs) if o is not None]
    names = list(outputs[0]["goodness"]) if outputs else []
    field_out = {
        "learning_seed": spec["seed"],
        "spacing_m": size["field_spacing_m"],
        "positions": [o["position"] for o in outputs],
        "goodness": {n: [round(o["goodness"][n], 5) for o in outputs] for n in names},
    }
    if outputs:
        spot = "east" if "east" in names else names[0]
        loaded = CompassAtlas.load(path)
        plot_goodness_field(
            run.out / "likelihood_field.png",
            np.array(field_out["positions"]),
            np.array(field_out["goodness"][spot]),
            tuple(loaded.positions[loaded.names.index(spot)]),
            bounds,
        )
        field_out["plotted_spot"] = spot
    return field_out


def _plot_stops(path: Path, episodes, settings, overall) -> None:
    from matplotlib.patches import Circle

    fig = new_figure(figsize=(6, 5), layout="constrained")
    ax = fig.subplots()
    seeds = sorted({e["learning_seed"] for e in episodes})
    for s in seeds:
        off = np.array([e["stop_offset_m"] for e in episodes if e["learning_seed"] == s]) * 100
        ax.scatter(off[:, 0], off[:, 1], s=22, label=f"stops, learning seed {s}")
    for x, y in ((100, 0), (0, 100), (-100, 0), (0, -100)):
        ax.plot(x, y, "x", color="goldenrod", ms=10, mew=3)
    ax.plot(0, 0, "+", color="k", ms=14, mew=2, label="home")
    m = overall["mean_stop_offset_cm"]
    ax.plot(*m, "o", mfc="none", mec="tab:red", ms=12, mew=2, label=f"mean ({m[0]}, {m[1]}) cm")
    ax.plot(
        *kidnapping.PAPER_MEAN_CM,
        "s",
        mfc="none",
        mec="k",
        ms=10,
        label="paper's mean (−22, 12) cm",
    )
    ax.add_patch(
        Circle((0, 0), settings["success_radius_m"] * 100, fill=False, ls="--", color="0.5")
    )
    off = np.array([e["stop_offset_m"] for e in episodes]) * 100
    lim = max(150.0, float(np.abs(off).max()) + 20.0) if off.size else 150.0
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x offset from home (cm)")
    ax.set_ylabel("y offset from home (cm)")
    tracker = tracker_label(settings["tracker"])
    ax.set_title(
        f"{settings['agent']} ({tracker} tracker, {settings.get('mode', 'paper')} mode), "
        f"{overall['episodes']} kidnappings:\n"
        f"success {overall['success_rate']:.0%}, mean distance "
        f"{overall['mean_stop_distance_cm']:.0f} cm, {overall['far_stops']} stops > 50 cm",
        fontsize=10,
    )
    ax.legend(fontsize=7, loc="upper right")
    save_figure(fig, path, dpi=100)


def summary_lines(results: dict[str, Any]) -> list[str]:
    """The homing result in a few lines, next to the paper's."""
    mode = results.get("settings", {}).get("mode", "paper")
    lines = [f"mode: {mode} (how the place is learned and the robot homes)"]
    for p in results.get("per_seed", []):
        lines.append(
            f"learning seed {p['seed']}: {p['episodes']} kidnappings, mean stop offset "
            f"{p['mean_stop_offset_cm']} cm, std {p['std_stop_offset_cm']} cm, mean distance "
            f"{p['mean_stop_distance_cm']} cm, success {p['success_rate']:.0%}, "
            f"{p['far_stops']} stops > 50 cm, {p['timed_out']} timed out, mean homing time "
            f"{p['mean_homing_time_s']} s"
        )
    o = results.get("overall")
    if o and len(results.get("per_seed", [])) > 1:
        s, d = o["success_rate_over_seeds"], o["mean_stop_distance_cm_over_seeds"]
        lines.append(
            f"over {len(results['per_seed'])} learning seeds: success {s[0]:.0%} ± {s[1]:.0%}, "
            f"mean distance {d[0]:.1f} ± {d[1]:.1f} cm (mean ± std over seeds)"
        )
    lines.append("paper: mean stop offset (-22, 12) cm, std (17, 15) cm over 33 kidnappings")
    for f in results.get("failed_jobs", []):
        lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
    return lines
