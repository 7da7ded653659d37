"""Kidnappings and where the robot stopped: the homing episode job and its statistics.

Shared by every experiment that homes (homing, agents, trackers, sensors through homing,
and the paper report): :func:`episode_job` runs one kidnapping with a saved atlas, and
:func:`summarise_stops` / :func:`spread_over_seeds` turn the stops into the figures of
the paper's homing experiment (5.2, fig. 5), next to its claims
(:data:`PAPER_MEAN_CM`, :data:`PAPER_STD_CM`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from vc_gym.experiments.atlases import SavedAtlas
from vc_gym.experiments.episode import make_homing_run, run_episode
from vc_gym.experiments.video import write_episode_video
from vc_gym.heading_sensors import MagnetometerCompass, NoisyMagneticCompass
from vc_gym.jobs.workers import worker_cache

__all__ = [
    "EPISODE_JOB",
    "FAR_STOP_M",
    "PAPER_MEAN_CM",
    "PAPER_STD_CM",
    "episode_job",
    "mean_std",
    "spread_over_seeds",
    "summarise_stops",
]

#: The paper's mean stop offset from home over 33 kidnappings (5.2), cm per axis ...
PAPER_MEAN_CM = (-22.0, 12.0)
#: ... and its standard deviation.
PAPER_STD_CM = (17.0, 15.0)
#: A stop this far from home is a "far stop": the robot trusted a position it had no
#: evidence for (or never found home).
FAR_STOP_M = 0.5
#: The job function of one kidnapping (:class:`~vc_gym.jobs.job.Job`'s ``fn``).
EPISODE_JOB = f"{__name__}:episode_job"


def _run_for(kwargs: Mapping[str, Any]):
    atlas = kwargs["atlas"]
    run = make_homing_run(
        kwargs["agent"],
        tracker=kwargs["tracker"],
        scene=kwargs["scene"],
        learn_time_s=kwargs["learn_time_s"],
        success_radius_m=kwargs["success_radius_m"],
        relearn="scene" if atlas else "episode",
        max_homing_s=kwargs["max_homing_s"],
        learner=SavedAtlas(atlas) if atlas else None,
        keep_image=kwargs.get("video") is not None,
        mode=kwargs.get("mode", "paper"),
        policy=None
        if kwargs.get("home_offset_m") is None
        else {"home_offset_m": tuple(kwargs["home_offset_m"])},
        allow_imports=kwargs.get("allow_imports", False),
    )
    if atlas:
        run.env.reset(seed=kwargs["learning_seed"])  # loads the saved atlas
    return run


def episode_job(
    agent: str,
    tracker: Any,
    scene: str,
    learn_time_s: float,
    success_radius_m: float,
    max_homing_s: float,
    atlas: str | None,
    learning_seed: int,
    episode_seed: int,
    video: str | None = None,
    mode: str = "paper",
    magnetometer: bool = False,
    home_offset_m: list[float] | None = None,
    allow_imports: bool = False,
) -> dict[str, Any]:
    """Job: one kidnapping (seed ``episode_seed``) with the saved ``atlas``.

    ``atlas=None`` learns anew in the episode (``relearn="episode"``). With ``video``
    the episode is also written there as MP4. ``mode`` is the homing mode (its policy;
    a saved atlas brings its own learning). With ``magnetometer`` the grid tracker's
    heading sensor is a magnetometer in the robot's head (the disturbance field of
    :meth:`NoisyMagneticCompass.random_field` seeded by the learning seed, its noise by
    the episode's). ``home_offset_m``: the scripted agent's goal correction.
    ``allow_imports``: a learned agent's ``config.json`` may name an import path. Returns
    the episode's figures.
    """
    kwargs = dict(locals())
    cache_key = json.dumps(
        {k: v for k, v in kwargs.items() if k not in ("episode_seed",)}, sort_keys=True
    )
    run = worker_cache(("homing-run", cache_key), lambda: _run_for(kwargs))
    if magnetometer:
        _fit_magnetometer(run, learning_seed, episode_seed)
    if video is not None:
        record = write_episode_video(run, episode_seed, video)
    else:
        record = run_episode(run, seed=episode_seed)
    out = record.summary()
    out["learning_seed"] = learning_seed
    ms = 1e3 * record.tracker_time_s / record.tracker_updates if record.tracker_updates else None
    out["timing"] = {"tracker_ms_per_update": ms}
    return out


def _fit_magnetometer(run: Any, learning_seed: int, episode_seed: int) -> None:
    """Make a magnetometer in the robot's head the grid tracker's heading sensor."""
    room = run.env.unwrapped.room
    field = NoisyMagneticCompass.random_field(
        room.scene.field_bounds, np.random.default_rng([learning_seed, 97])
    )
    robot = room.robot

    def head_pose() -> tuple[float, float, float]:
        x, y, yaw = robot.pose
        return x, y, yaw + float(robot.head[0])

    tracker = run.env.get_wrapper_attr("tracker")
    tracker.heading_sensor = MagnetometerCompass(
        field, head_pose, np.random.default_rng([episode_seed, 98])
    )


def summarise_stops(episodes: Sequence[Mapping[str, Any]], success_radius_m: float) -> dict:
    """Mean / std stop offset per axis (cm), distances, success and far stops."""
    off = np.array([e["stop_offset_m"] for e in episodes], np.float64) * 100.0
    dist = np.hypot(off[:, 0], off[:, 1])
    n = len(episodes)
    return {
        "episodes": n,
        "mean_stop_offset_cm": off.mean(axis=0).round(1).tolist(),
        "std_stop_offset_cm": off.std(axis=0, ddof=1).round(1).tolist() if n > 1 else None,
        "mean_stop_distance_cm": round(float(dist.mean()), 1),
        "median_stop_distance_cm": round(float(np.median(dist)), 1),
        "success_rate": round(float(np.mean([e["success"] for e in episodes])), 4),
        "success_radius_m": success_radius_m,
        "far_stops": int(
            sum(e["stopped"] and d > FAR_STOP_M * 100 for e, d in zip(episodes, dist, strict=True))
        ),
        "stopped": int(sum(e["stopped"] for e in episodes)),
        "timed_out": int(sum(e["timed_out"] for e in episodes)),
        "fell": int(sum(e["fell"] for e in episodes)),
        "mean_homing_time_s": round(float(np.mean([e["sim_time_s"] for e in episodes])), 1),
        "mean_heading_error_deg": round(
            float(np.mean([e["mean_heading_error_deg"] or 0.0 for e in episodes])), 2
        ),
    }


def mean_std(values: Sequence[float]) -> list[float]:
    """``[mean, sample std (ddof 1; 0 for one value)]``, rounded to 4 decimals."""
    v = np.asarray(values, np.float64)
    return [round(float(v.mean()), 4), round(float(v.std(ddof=1)) if v.size > 1 else 0.0, 4)]


def spread_over_seeds(per_seed: Sequence[Mapping[str, Any]]) -> dict[str, list[float]]:
    """``[mean, std]`` over learning seeds of :func:`summarise_stops`' success and distance."""
    return {
        "success_rate_over_seeds": mean_std([p["success_rate"] for p in per_seed]),
        "mean_stop_distance_cm_over_seeds": mean_std(
            [p["mean_stop_distance_cm"] for p in per_seed]
        ),
    }
