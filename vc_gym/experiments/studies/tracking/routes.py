"""The tracking experiment's routes: a seeded route over the field (start pose, waypoints
with turns on the spot, the time and pose of one kidnapping) as a :class:`Route` that
travels as a job's JSON argument (:func:`make_route`), and the controller that drives the
robot along it from its true pose, scanning with the head whenever it does not walk
(:class:`RouteDriver`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.envs.learning import HEAD_SCAN_DEG, kidnap_pose
from vc_gym.experiments.views.checks import checked_bounds
from vc_gym.validation import positive_float

__all__ = [
    "ARRIVED_M",
    "MAX_FORWARD_M_S",
    "MAX_TURN_DEG_S",
    "MIN_LEG_M",
    "ROUTE_MARGIN_M",
    "TURN_RANGE_DEG",
    "TURN_SHARE",
    "Route",
    "RouteDriver",
    "make_route",
]

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
