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
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.envs.learning import HEAD_SCAN_DEG, kidnap_pose
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
from vc_gym.experiments.studies.kidnapping import mean_std
from vc_gym.experiments.studies.orientation_grid import (
    GRID_AROUND_M,
    VIEW_MODES,
    check_trackers,
    mode_trackers,
    training_spots,
)
from vc_gym.experiments.views.checks import checked_bounds
from vc_gym.experiments.views.top_view import field_axes, scene_top_view
from vc_gym.jobs.job import Job
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.jobs.workers import worker_cache
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
    "full": {
        "scenes": None,
        "lights": [1.0, 0.5],
        "seeds": 3,
        "routes": 2,
        "route_s": 60.0,
        "kidnap_s": [25.0, 35.0],
        "settle_s": 10.0,
        "learn_time_s": 5.0,
        "spots_m": None,
        "trackers": None,
    },
}

#: Re-localised: the position error stays within this (m) ...
RELOCALISED_POSITION_M = 0.3
#: ... and the heading error within this (degrees) ...
RELOCALISED_HEADING_DEG = 10.0
#: ... for at least this long (s).
RELOCALISED_HOLD_S = 2.0
#: The share of kidnappings re-localised within this many seconds is reported.
RELOCALISED_WITHIN_S = 10.0

#: Start, waypoints and kidnapping poses keep this far inside the field's edges (m).
ROUTE_MARGIN_M = 0.3
#: Shortest walk between two waypoints (m).
MIN_LEG_M = 0.8
#: Share of the waypoints where the robot turns on the spot, and by how much (degrees,
#: either way).
TURN_SHARE = 0.4
TURN_RANGE_DEG = (90.0, 360.0)
#: The controller's top forward speed (m/s; the learned agents' ``StopAction``) and
#: turn rate (deg/s; the scripted agent's).
MAX_FORWARD_M_S = 0.4
MAX_TURN_DEG_S = 60.0
#: A waypoint is reached within this distance (m).
ARRIVED_M = 0.15
#: Errors against time are averaged in bins this long (s) in ``results.json``.
BIN_S = 1.0
#: Most particles kept of a snapshot (every k-th), for the belief plot.
SNAPSHOT_PARTICLES = 300
#: The error figures of a set of routes, averaged over learning seeds.
OVER_SEEDS = (
    "mean_heading_error_deg",
    "mean_position_error_m",
    "mean_heading_error_with_relocalisation_deg",
    "mean_position_error_with_relocalisation_m",
    "relocalised_within_10s",
    "heading_coverage_2sigma",
    "position_coverage_2sigma",
)


# ---------------------------------------------------------------------- routes
@dataclass(frozen=True)
class Route:
    """One route: where the robot starts, where it walks, when and where it is kidnapped.

    Attributes
    ----------
    start : (x, y, yaw_deg)
        The start pose, world frame.
    waypoints : tuple of (x, y, turn_deg)
        The points walked to in turn; on reaching one the robot turns on the spot by
        ``turn_deg`` (0: none; positive left) before walking on.
    kidnap_s : float
        When the robot is kidnapped (a multiple of the control period), seconds.
    kidnap_pose : (x, y, yaw_deg)
        Where it is put.
    duration_s : float
        Length of the route in simulated seconds.
    reset_seeds : (int, int)
        Seeds of the room's resets at the start and at the kidnapping (odometry errors).
    """

    start: tuple[float, float, float]
    waypoints: tuple[tuple[float, float, float], ...]
    kidnap_s: float
    kidnap_pose: tuple[float, float, float]
    duration_s: float
    reset_seeds: tuple[int, int]

    def to_dict(self) -> dict[str, Any]:
        """The route as JSON values (a job's argument)."""
        return json.loads(json.dumps(asdict(self)))

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Route:
        """The inverse of :meth:`to_dict`."""
        return cls(
            start=tuple(float(v) for v in d["start"]),
            waypoints=tuple(tuple(float(v) for v in w) for w in d["waypoints"]),
            kidnap_s=float(d["kidnap_s"]),
            kidnap_pose=tuple(float(v) for v in d["kidnap_pose"]),
            duration_s=float(d["duration_s"]),
            reset_seeds=tuple(int(v) for v in d["reset_seeds"]),
        )


def make_route(
    bounds: Sequence[float],
    seed: int,
    route: int,
    duration_s: float = 60.0,
    kidnap_window_s: Sequence[float] = (25.0, 35.0),
    dt_s: float = 0.1,
) -> Route:
    """A seeded route over the field ``bounds`` (the same arguments, the same route).

    Everything is drawn from ``numpy.random.default_rng([seed, route, 7])``: the start
    pose and the kidnapping pose uniform over the field (:data:`ROUTE_MARGIN_M` inside
    its edges, uniform heading), the kidnapping time uniform in ``kidnap_window_s``
    (rounded to ``dt_s``), and waypoints uniform over the field, each at least
    :data:`MIN_LEG_M` from the one before, :data:`TURN_SHARE` of them with a turn on
    the spot of 90-360° either way. There are more waypoints than the route can reach
    at :data:`MAX_FORWARD_M_S`.

    Parameters
    ----------
    bounds : (xmin, xmax, ymin, ymax)
        The field, world metres.
    seed, route : int
        The learning seed and the route's index.
    duration_s : float
        Length of the route, seconds.
    kidnap_window_s : (float, float)
        When the kidnapping may happen, within ``(0, duration_s)``.
    dt_s : float
        The control period, seconds.

    Returns
    -------
    Route

    Raises
    ------
    ValueError
        Bad bounds, a field too small for legs of :data:`MIN_LEG_M`, a kidnapping window
        outside the route, bad seeds.
    """
    x0, x1, y0, y1 = checked_bounds(bounds)
    m = ROUTE_MARGIN_M
    if math.hypot(x1 - x0 - 2 * m, y1 - y0 - 2 * m) < 2 * MIN_LEG_M:
        raise ValueError(f"the field {bounds} is too small for routes of {MIN_LEG_M} m legs")
    duration_s = positive_float("duration_s", duration_s)
    dt_s = positive_float("dt_s", dt_s)
    a, b = (float(v) for v in kidnap_window_s)
    if not 0.0 < a <= b < duration_s:
        raise ValueError(
            f"the kidnapping window must lie within (0, {duration_s:g}) s, got {kidnap_window_s}"
        )
    rng = np.random.default_rng([int(seed), int(route), 7])
    inner = (x0, x1, y0, y1)
    start = kidnap_pose(rng, inner, m)
    kidnap_s = round(round(float(rng.uniform(a, b)) / dt_s) * dt_s, 6)
    kidnapped = kidnap_pose(rng, inner, m)
    count = math.ceil(duration_s * MAX_FORWARD_M_S / MIN_LEG_M) + 3
    waypoints: list[tuple[float, float, float]] = []
    last = start[:2]
    while len(waypoints) < count:
        x, y = float(rng.uniform(x0 + m, x1 - m)), float(rng.uniform(y0 + m, y1 - m))
        if math.hypot(x - last[0], y - last[1]) < MIN_LEG_M:
            continue
        turn = 0.0
        if rng.random() < TURN_SHARE:
            turn = float(rng.choice((-1.0, 1.0)) * rng.uniform(*TURN_RANGE_DEG))
        waypoints.append((round(x, 4), round(y, 4), round(turn, 2)))
        last = (x, y)
    seeds = rng.integers(2**31, size=2)
    return Route(
        start=tuple(round(v, 4) for v in start),
        waypoints=tuple(waypoints),
        kidnap_s=kidnap_s,
        kidnap_pose=tuple(round(v, 4) for v in kidnapped),
        duration_s=duration_s,
        reset_seeds=(int(seeds[0]), int(seeds[1])),
    )


class RouteDriver:
    """Drives the robot along waypoints from its *true* pose (the tracker is only watched).

    Each :meth:`command` turns towards the current waypoint (2.5 deg/s per degree off,
    at most :data:`MAX_TURN_DEG_S`) and walks when it is within 30° of it (at most
    :data:`MAX_FORWARD_M_S`, slower when near); within :data:`ARRIVED_M` the waypoint is
    reached, and the robot turns on the spot by the waypoint's ``turn_deg`` (measured on
    the true heading) before it heads for the next one. As the homing agents do, the
    head scans (the next pan of ``head_scan_deg`` at each step) whenever the robot does
    not walk forward, and looks straight ahead while it walks. After the last waypoint
    the robot stands, scanning.

    Parameters
    ----------
    waypoints : sequence of (x, y, turn_deg)
        The route's waypoints.
    dt_s : float
        The control period, seconds.
    head_scan_deg : sequence of float
        Head pans cycled while not walking forward.
    """

    def __init__(
        self,
        waypoints: Sequence[Sequence[float]],
        dt_s: float,
        head_scan_deg: Sequence[float] = HEAD_SCAN_DEG,
    ):
        self.waypoints = [tuple(float(v) for v in w) for w in waypoints]
        self.dt_s = positive_float("dt_s", dt_s)
        self.head_scan_deg = tuple(float(p) for p in head_scan_deg)
        self.index = 0
        self._turn_left_deg = 0.0
        self._last_yaw: float | None = None
        self._scan_i = 0

    def skip(self) -> None:
        """After a kidnapping: forget the waypoint (and turn) in progress, head for the next."""
        if self._turn_left_deg == 0.0:
            self.index += 1
        self._turn_left_deg = 0.0
        self._last_yaw = None

    def command(self, pose: Sequence[float]) -> tuple[float, float, float]:
        """``(forward m/s, turn deg/s, head pan deg)`` for the true ``pose`` (x, y, yaw)."""
        x, y, yaw = (float(v) for v in pose)
        if self._turn_left_deg != 0.0 and self._last_yaw is not None:
            turned = float(wrap180(yaw - self._last_yaw))
            left = self._turn_left_deg - turned
            # done when less than a degree is left, or the turn went past its end
            done = abs(left) < 1.0 or left * self._turn_left_deg < 0.0
            self._turn_left_deg = 0.0 if done else left
        self._last_yaw = yaw
        if self._turn_left_deg != 0.0:
            rate = min(MAX_TURN_DEG_S, abs(self._turn_left_deg) / self.dt_s)
            return 0.0, math.copysign(rate, self._turn_left_deg), self._next_pan()
        while self.index < len(self.waypoints):
            wx, wy, turn = self.waypoints[self.index]
            d = math.hypot(wx - x, wy - y)
            if d > ARRIVED_M:
                break
            self.index += 1
            if turn:
                self._turn_left_deg = turn
                rate = min(MAX_TURN_DEG_S, abs(turn) / self.dt_s)
                return 0.0, math.copysign(rate, turn), self._next_pan()
        else:
            return 0.0, 0.0, self._next_pan()
        err = float(wrap180(math.degrees(math.atan2(wy - y, wx - x)) - yaw))
        turn_rate = float(np.clip(2.5 * err, -MAX_TURN_DEG_S, MAX_TURN_DEG_S))
        forward = 0.0 if abs(err) > 30.0 else min(MAX_FORWARD_M_S, max(0.1, d))
        return forward, turn_rate, (self._next_pan() if forward == 0.0 else 0.0)

    def _next_pan(self) -> float:
        self._scan_i = (self._scan_i + 1) % len(self.head_scan_deg)
        return self.head_scan_deg[self._scan_i]


# ---------------------------------------------------------------------- the job
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


# ---------------------------------------------------------------------- figures
def relocalisation_time(
    t_s: Sequence[float],
    position_error_m: Sequence[float],
    heading_error_deg: Sequence[float],
    kidnap_s: float,
    position_m: float = RELOCALISED_POSITION_M,
    heading_deg: float = RELOCALISED_HEADING_DEG,
    hold_s: float = RELOCALISED_HOLD_S,
) -> float | None:
    """Seconds from the kidnapping until the tracker has the robot again, or ``None``.

    The first frame at or after ``kidnap_s`` from which on the position error stays
    within ``position_m`` and the absolute heading error within ``heading_deg`` for at
    least ``hold_s`` (every frame up to ``hold_s`` later, and the route lasts that
    long); its time minus ``kidnap_s``. ``None`` when there is no such frame within the
    route.

    Parameters
    ----------
    t_s : sequence of float
        Frame times, increasing.
    position_error_m, heading_error_deg : sequence of float
        The errors at those frames (the heading error's sign is ignored).
    kidnap_s : float
        Time of the kidnapping.
    position_m, heading_deg, hold_s : float
        The criteria.
    """
    t = np.asarray(t_s, np.float64)
    pos = np.asarray(position_error_m, np.float64)
    head = np.asarray(heading_error_deg, np.float64)
    if not (t.ndim == 1 and t.size and t.shape == pos.shape == head.shape):
        raise ValueError("t_s and the errors must be non-empty 1-D sequences of one length")
    ok = (pos <= position_m) & (np.abs(head) <= heading_deg)
    eps = 1e-9
    # bad[j]: frames up to j that break the criteria; a window [i, end] is clean when
    # none break it between i and end
    broken = np.concatenate([[0], np.cumsum(~ok)])
    for i in np.flatnonzero((t >= kidnap_s - eps) & ok):
        end_t = t[i] + hold_s
        if t[-1] < end_t - eps:
            return None  # the route ends before the hold could be seen
        j = int(np.searchsorted(t, end_t + eps, side="right"))  # frames in [t_i, t_i + hold]
        if broken[j] - broken[i] == 0:
            return round(float(t[i] - kidnap_s), 6)
    return None


def two_sigma_coverage(error: Sequence[float], sigma: Sequence[float]) -> float | None:
    """Share of the entries where ``|error| <= 2 sigma`` (``None`` for none).

    For the heading pass the frames' heading errors and spreads; for the position the
    ``(frames, 2)`` per-axis errors and standard deviations (a share of (frame, axis)
    pairs). A calibrated Gaussian belief covers about 95 %.
    """
    e = np.abs(np.asarray(error, np.float64))
    s = np.asarray(sigma, np.float64)
    if e.shape != s.shape:
        raise ValueError(f"error and sigma differ in shape: {e.shape} vs {s.shape}")
    if e.size == 0:
        return None
    return float(np.mean(e <= 2.0 * s))


def _errors(frames: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """Per frame: heading error (wrapped, deg), per-axis and total position error (m)."""
    true = np.asarray(frames["true"], np.float64).reshape(-1, 3)
    est = np.asarray(frames["estimate"], np.float64).reshape(-1, 3)
    axes = est[:, :2] - true[:, :2]
    return {
        "t": np.asarray(frames["t_s"], np.float64),
        "heading": np.asarray(wrap180(est[:, 2] - true[:, 2]), np.float64),
        "axes": axes,
        "position": np.hypot(axes[:, 0], axes[:, 1]),
        "spread": np.asarray(frames["heading_spread_deg"], np.float64),
        "std": np.asarray(frames["position_std_m"], np.float64).reshape(-1, 2),
    }


def _windows(e: Mapping[str, np.ndarray], kidnap_s: float, settle_s: float, reloc: float | None):
    """``(settled, evaluated)`` frame masks: from ``settle_s`` on; the same without the
    re-localisation window (from the kidnapping until re-localised, or the end)."""
    t = e["t"]
    settled = t >= settle_s - 1e-9
    end = math.inf if reloc is None else kidnap_s + reloc
    lost = (t >= kidnap_s - 1e-9) & (t < end - 1e-9)
    return settled, settled & ~lost


def _r(v: float | None, digits: int = 4) -> float | None:
    return None if v is None or not math.isfinite(v) else round(float(v), digits)


def _pooled(parts: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The figures of routes pooled frame by frame (``parts``: :func:`_route_parts`)."""

    def cat(key: str, mask: str) -> np.ndarray:
        arrays = [p["errors"][key][p[mask]] for p in parts]
        return np.concatenate(arrays) if arrays else np.zeros(0)

    def mean_abs(key: str, mask: str) -> float | None:
        v = np.abs(cat(key, mask))
        return float(v.mean()) if v.size else None

    relocs = [p["relocalisation_s"] for p in parts]
    found = [r for r in relocs if r is not None]
    return {
        "routes": len(parts),
        "mean_heading_error_deg": _r(mean_abs("heading", "evaluated"), 2),
        "mean_position_error_m": _r(mean_abs("position", "evaluated")),
        "mean_heading_error_with_relocalisation_deg": _r(mean_abs("heading", "settled"), 2),
        "mean_position_error_with_relocalisation_m": _r(mean_abs("position", "settled")),
        "relocalised": len(found),
        "relocalised_within_10s": _r(
            float(np.mean([r is not None and r <= RELOCALISED_WITHIN_S for r in relocs]))
        )
        if relocs
        else None,
        "median_relocalisation_s": _r(float(np.median(found)), 2) if found else None,
        "heading_coverage_2sigma": _r(
            two_sigma_coverage(cat("heading", "evaluated"), cat("spread", "evaluated"))
        ),
        "position_coverage_2sigma": _r(
            two_sigma_coverage(cat("axes", "evaluated"), cat("std", "evaluated"))
        ),
    }


def _route_parts(frames: Mapping[str, Any], kidnap_s: float, settle_s: float) -> dict[str, Any]:
    e = _errors(frames)
    reloc = relocalisation_time(e["t"], e["position"], e["heading"], kidnap_s)
    settled, evaluated = _windows(e, kidnap_s, settle_s, reloc)
    return {"errors": e, "relocalisation_s": reloc, "settled": settled, "evaluated": evaluated}


def route_figures(
    frames: Mapping[str, Any], kidnap_s: float, settle_s: float = 10.0
) -> dict[str, Any]:
    """One route's figures: errors after ``settle_s`` (without and with the
    re-localisation window), the re-localisation time, the 2σ coverage, and the mean
    absolute errors in :data:`BIN_S` bins (``error_over_time``: bin ``k`` holds the
    frames of ``[k, k + 1)`` s, the last one also the route's last frame).

    ``frames`` is a :func:`route_job`'s ``frames``.
    """
    parts = _route_parts(frames, kidnap_s, settle_s)
    e = parts["errors"]
    out = _pooled([parts])
    del out["routes"], out["relocalised"], out["median_relocalisation_s"]
    out["relocalisation_s"] = _r(parts["relocalisation_s"], 2)
    last = max(int(math.ceil(e["t"][-1] / BIN_S - 1e-9)) - 1, 0)  # the end in the last bin
    k = np.minimum(np.floor(e["t"] / BIN_S + 1e-9).astype(int), last)
    bins = np.unique(k)
    out["error_over_time"] = {
        "bin_s": BIN_S,
        "heading_deg": [round(float(np.abs(e["heading"][k == b]).mean()), 2) for b in bins],
        "position_m": [round(float(e["position"][k == b].mean()), 4) for b in bins],
    }
    return out


def _summary(entries: Sequence[Mapping[str, Any]], settle_s: float) -> dict[str, Any]:
    """Figures of one (scene, light, tracker): pooled, per seed, over seeds, per route."""
    parts = [_route_parts(e["frames"], e["route"]["kidnap_s"], settle_s) for e in entries]
    seeds = sorted({e["seed"] for e in entries})
    per_seed = {
        str(s): _pooled([p for p, e in zip(parts, entries, strict=True) if e["seed"] == s])
        for s in seeds
    }
    over = {}
    for key in OVER_SEEDS:
        values = [v[key] for v in per_seed.values() if v[key] is not None]
        over[key] = mean_std(values) if values else None
    routes = []
    for e in entries:
        r = e["route"]
        true = np.asarray(e["frames"]["true"], np.float64)
        k = int(round(r["kidnap_s"] / (e["frames"]["t_s"][1] - e["frames"]["t_s"][0])))
        routes.append(
            {
                "seed": e["seed"],
                "route": e["index"],
                "start_pose": r["start"],
                "kidnap_s": r["kidnap_s"],
                "kidnap_pose": r["kidnap_pose"],
                "kidnap_distance_m": round(float(np.hypot(*(true[k, :2] - true[k - 1, :2]))), 4),
                **route_figures(e["frames"], r["kidnap_s"], settle_s),
            }
        )
    return {**_pooled(parts), "per_seed": per_seed, "over_seeds": over, "per_route": routes}


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
    from vc_gym.sim.scenes import scene_names

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
                            "snapshots_s": _snapshot_times(route, size["settle_s"])
                            if first
                            else [],
                        }
                        if len(jobs) < opts.video:
                            folder = run.out / "videos"
                            folder.mkdir(exist_ok=True)
                            kwargs["video"] = str((folder / f"{key}.mp4").resolve())
                            kwargs["spots"] = [list(p) for p in spots[scene]]
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
                name: _summary(grouped[(scene, light, name)], size["settle_s"])
                for name in named
                if (scene, light, name) in grouped
            }
            per_light[f"{light:g}"] = {"trackers": per_tracker}
        results["scenes"][scene] = {"spots": len(spots[scene]), "lights": per_light}
        _plot_errors(run.out / f"errors_{scene}.png", scene, lights, named, grouped)
        _plot_belief(
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


def _snapshot_times(route: Route, settle_s: float) -> list[float]:
    """When the belief plot shows the particles: settled, just before the kidnapping,
    2 s after it, at the end."""
    dt = 0.1
    times = [settle_s, route.kidnap_s - dt, route.kidnap_s + 2.0, route.duration_s]
    return sorted({round(min(max(t, 0.0), route.duration_s), 6) for t in times})


# ---------------------------------------------------------------------- plots
def _plot_errors(path: Path, scene, lights, named, grouped) -> None:
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
            e = _errors(entry["frames"])
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


def _plot_belief(path: Path, scene, light, seed, named, grouped, bounds, spots) -> None:
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
