"""The tracking experiment's job: drive the robot along one route in a scene at a light
level, kidnap it once, and feed a tracker every frame the head-camera image, the head pan
and the noisy odometry; record the true pose, the belief and its stated uncertainty per
frame, a particle tracker's particles at a few moments, the milliseconds per update, and
optionally the route as MP4 (:func:`route_job`).
"""

from __future__ import annotations

import json
import math
import time
from typing import Any

import numpy as np

from vc_gym.experiments.studies.tracking.routes import Route, RouteDriver
from vc_gym.jobs.workers import worker_cache

__all__ = ["SNAPSHOT_PARTICLES", "route_job"]

#: Most particles kept of a snapshot (every k-th), for the belief plot.
SNAPSHOT_PARTICLES = 300


def route_job(
    scene: str,
    atlas: str,
    light: float,
    route: dict[str, Any],
    name: str,
    tracker: Any,
    snapshots_s: list[float] | None = None,
    video: str | None = None,
    spots: list[list[float]] | None = None,
) -> dict[str, Any]:
    """Job: drive one route in ``scene`` at ``light`` with tracker ``tracker`` watching.

    Parameters
    ----------
    scene : str
        Registered scene.
    atlas : str
        The saved atlas (``.npz``).
    light : float
        Room illumination during the route.
    route : dict
        :meth:`Route.to_dict`.
    name, tracker
        The tracker's name (for the timing) and spec.
    snapshots_s : list of float, optional
        Times at which to keep the tracker's ``particles`` (when it has them).
    video : str, optional
        Also write the route as MP4 there (head camera beside the top view).
    spots : list of (x, y), optional
        The training spots marked in the video.

    Returns
    -------
    dict
        ``frames``: per frame ``t_s``, ``true`` (x, y, θ), ``estimate`` (x, y, θ),
        ``heading_spread_deg``, ``position_std_m`` (x, y); ``particles``: ``{time:
        [[x, y, θ], ...]}``; ``timing``: ``{name: median ms per update}``.
    """
    from vc_gym.compass import Camera, CompassAtlas
    from vc_gym.localization import make_tracker
    from vc_gym.sim.aibo_room import AiboRoomEnv

    r = Route.from_dict(route)
    room_kwargs = {"illumination": float(light)} if light != 1.0 else {}
    room = worker_cache(
        ("room", scene, json.dumps(room_kwargs, sort_keys=True)),
        lambda: AiboRoomEnv(scene=scene, **room_kwargs),
    )
    loaded = worker_cache(("atlas", atlas), lambda: CompassAtlas.load(atlas))
    chosen = make_tracker(tracker)
    dt = room.control_dt
    steps = int(round(r.duration_s / dt))
    kidnap_k = int(round(r.kidnap_s / dt))
    snapshots = {int(round(s / dt)): s for s in (snapshots_s or [])}
    driver = RouteDriver(r.waypoints, dt)
    frames: dict[str, list] = {
        k: [] for k in ("t_s", "true", "estimate", "heading_spread_deg", "position_std_m")
    }
    particles: dict[str, list] = {}
    costs: list[float] = []
    obs, info = room.reset(seed=r.reset_seeds[0], options={"pose": r.start})
    chosen.reset(loaded, Camera(hfov_deg=room.camera.hfov_deg), dt)
    filming = _route_video(video, room, chosen, spots) if video else None
    try:
        for k in range(steps + 1):
            if k == kidnap_k:  # put elsewhere, as the homing task kidnaps; nobody tells
                obs, info = room.reset(seed=r.reset_seeds[1], options={"pose": r.kidnap_pose})
                driver.skip()
            elif k > 0:
                forward, turn, pan = driver.command(info["pose"])
                obs, _, fell, _, info = room.step(
                    room.velocity_action(forward_m_s=forward, turn_deg_s=turn, pan_deg=pan)
                )
                if fell:
                    raise RuntimeError(f"the robot fell at t = {k * dt:.1f} s")
            t0 = time.perf_counter()
            state = chosen.update(
                obs["image"], float(obs["head"][0]), np.asarray(obs["odometry"], np.float64)
            )
            costs.append(1e3 * (time.perf_counter() - t0))
            t = round(k * dt, 6)
            true = [round(float(v), 4) for v in info["pose"]]
            frames["t_s"].append(t)
            frames["true"].append(true)
            frames["estimate"].append(
                [round(float(v), 4) for v in (*state.position, state.heading_deg)]
            )
            frames["heading_spread_deg"].append(round(float(state.heading_spread_deg), 4))
            frames["position_std_m"].append([round(float(v), 4) for v in state.position_std_m])
            if k in snapshots and getattr(chosen, "particles", None) is not None:
                p = np.asarray(chosen.particles, np.float64)
                every = max(1, math.ceil(len(p) / SNAPSHOT_PARTICLES))
                particles[f"{snapshots[k]:g}"] = np.round(p[::every], 3).tolist()
            if filming is not None:
                filming(k, t, obs, info, state, r.kidnap_s if k >= kidnap_k else None)
    except BaseException:
        if filming is not None:
            filming.video.abort()
        raise
    if filming is not None:
        filming.video.close()
    return {
        "frames": frames,
        "particles": particles,
        "timing": {name: float(np.median(costs))},
    }


class _RouteVideo:
    """The route as an :class:`~vc_gym.experiments.video.EpisodeVideo` of the room."""

    def __init__(self, video: Any):
        self.video = video

    def __call__(self, k, t, obs, info, state, kidnapped_at_s) -> None:
        from vc_gym.experiments.episode import EpisodeStep

        shown = {**info}
        if kidnapped_at_s is not None:
            shown["kidnapped_at_s"] = kidnapped_at_s
        self.video(
            EpisodeStep(
                index=k,
                sim_time_s=t,
                observation=obs,
                info=shown,
                true_pose=tuple(float(v) for v in info["pose"]),
                estimate={
                    "heading_deg": float(state.heading_deg),
                    "heading_spread_deg": float(state.heading_spread_deg),
                    "position": [float(v) for v in state.position],
                    "position_std_m": [float(v) for v in state.position_std_m],
                },
            )
        )


def _route_video(path: str, room: Any, tracker: Any, spots: Any) -> _RouteVideo:
    from vc_gym.experiments.video import EpisodeVideo

    marked = {f"spot{i}": tuple(p) for i, p in enumerate(spots or [])}
    return _RouteVideo(EpisodeVideo(path, room, tracker=tracker, spots=marked))
