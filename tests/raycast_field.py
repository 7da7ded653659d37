"""A ray-cast field for the pose trackers' tests: a 5 x 4 m room, six spots 1 m apart
with four turns 0.5 m around each, and a walk between random waypoints with the head
scanning, odometry with scale errors and noise, and an optional kidnapping."""

from __future__ import annotations

import math

import numpy as np

from vc_gym.compass import Camera, CompassAtlas, wrap180
from vc_gym.exposure import gain_table
from vc_gym.worlds.room import make_room, render_room_view

WIDTH_M, DEPTH_M = 5.0, 4.0
SPOTS = [(x, y) for x in (-1.0, 0.0, 1.0) for y in (-0.75, 0.75)]
AROUND = {"e": (0.5, 0.0), "w": (-0.5, 0.0), "n": (0.0, 0.5), "s": (0.0, -0.5)}
YAWS = [body + pan for body in range(0, 360, 45) for pan in (-22.5, 0.0, 22.5)]
FIELD = ((-1.6, -1.2), (1.6, 1.2))


def field_room():
    """The room (seeded)."""
    return make_room(np.random.default_rng(5), width_m=WIDTH_M, depth_m=DEPTH_M)


def field_atlas(room, learn_room_turn, config=None) -> CompassAtlas:
    """Six spots 1 m apart, each with four shorter turns 0.5 m around it (compass
    ``config``: default the paper's)."""
    entries, colors = {}, None
    for i, (x, y) in enumerate(SPOTS):
        vc = learn_room_turn(room, x, y, colors, YAWS, config)
        colors = vc.colors
        entries[f"spot{i}"] = ((x, y), vc)
        for side, (dx, dy) in AROUND.items():
            turn = learn_room_turn(room, x + dx, y + dy, colors, YAWS[1::3], config)
            entries[f"spot{i}.{side}"] = ((x + dx, y + dy), turn)
    return CompassAtlas(entries, home="spot0")


def walk(
    room,
    atlas,
    tracker,
    frames: int = 200,
    kidnap_at: int | None = None,
    seed: int = 1,
    light: float = 1.0,
):
    """Errors per frame of a walk between random waypoints with the head scanning, the
    room's light times ``light``."""
    rng = np.random.default_rng(seed)
    tracker.reset(atlas, Camera(), 0.1)
    pose = np.array([0.2, -0.3, 30.0])
    goal = rng.uniform(*FIELD)
    out = []
    for f in range(frames):
        if f == kidnap_at:
            pose = np.array([*rng.uniform(*FIELD), rng.uniform(0, 360)])
        d = goal - pose[:2]
        if math.hypot(*d) < 0.2:
            goal = rng.uniform(*FIELD)
            d = goal - pose[:2]
        err = wrap180(math.degrees(math.atan2(d[1], d[0])) - pose[2])
        turn = float(np.clip(err, -6.0, 6.0))
        fwd = 0.04 if abs(err) < 30 else 0.0
        th = math.radians(pose[2])
        pose += (fwd * math.cos(th), fwd * math.sin(th), turn)
        pose[2] %= 360.0
        pan = 30.0 * math.sin(0.3 * f)
        image = render_room_view(room, pose[0], pose[1], Camera(yaw_deg=pose[2] + pan))
        if light != 1.0:
            image = np.take(gain_table(light), image)
        noise = rng.normal(0, (0.002, 0.002, 0.2))
        odo = (fwd * 1.05 + noise[0], noise[1], turn * 0.97 + noise[2])
        s = tracker.update(image, pan, odo)
        ex, ey = s.position[0] - pose[0], s.position[1] - pose[1]
        heading_error = abs(wrap180(s.heading_deg - pose[2]))
        out.append((heading_error, math.hypot(ex, ey), s.heading_spread_deg))
    return np.array(out)
