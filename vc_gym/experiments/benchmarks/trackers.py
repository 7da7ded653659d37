"""Cost of one tracker update, every registered tracker side by side in one run.

An atlas of four spots 1 m around home is learned in a seeded ray-cast room (8 × 45°
with head pans, like the task's learning phase); a walk of frames with odometry is
rendered once. Each round then feeds every tracker the same walk, tracker after
tracker, so machine noise hits them alike; the median per-update time of each is
reported next to the cost of the atlas alone (the part every tracker shares:
``CompassAtlas.estimate_position``), and each tracker's heading and position error
on the walk.
"""

from __future__ import annotations

import math
import time

import numpy as np
from tqdm import tqdm

from vc_gym.angles import wrap180
from vc_gym.compass import Camera, CompassAtlas, CompassConfig, VisualCompass
from vc_gym.localization import TRACKERS, make_tracker
from vc_gym.poses import compose
from vc_gym.validation import check_seed, int_in_range
from vc_gym.worlds.room import make_room, render_room_view

__all__ = ["bench_trackers"]

SPOTS = {"east": (1.0, 0.0), "north": (0.0, 1.0), "west": (-1.0, 0.0), "south": (0.0, -1.0)}
PANS = (-22.5, 0.0, 22.5)
#: Most frames of the walk (each is rendered and kept in memory).
MAX_FRAMES = 10_000
#: Most rounds.
MAX_REPEATS = 1_000


def _atlas(room) -> CompassAtlas:
    yaws = [body + pan for body in range(0, 360, 45) for pan in PANS]
    first = VisualCompass(CompassConfig())
    first.fit_colors(
        [render_room_view(room, 0.0, 0.0, Camera(yaw_deg=a)) for a in range(0, 360, 45)]
    )
    spots = {}
    for name, (x, y) in SPOTS.items():
        vc = VisualCompass(CompassConfig(), first.colors)
        for a in yaws:
            vc.learn(render_room_view(room, x, y, Camera(yaw_deg=a)), Camera(yaw_deg=a))
        spots[name] = ((x, y), vc)
    atlas = CompassAtlas(spots, home="home", home_position=(0.0, 0.0))
    home = [render_room_view(room, 0.0, 0.0, Camera(yaw_deg=a)) for a in range(0, 360, 30)]
    atlas.normalize(home, [Camera()] * len(home))
    return atlas


def _walk(room, rng: np.random.Generator, frames: int):
    """A wandering walk from 1.5 m out towards home: (image, odometry, true pose)."""
    pose = (1.5, -0.8, float(rng.uniform(0, 360)))
    out = []
    for _ in range(frames):
        bearing = math.degrees(math.atan2(-pose[1], -pose[0]))
        turn = float(np.clip(wrap180(bearing - pose[2]), -15, 15) + rng.normal(0, 3))
        fwd = 0.03 if math.hypot(*pose[:2]) > 0.2 else 0.0
        pose = compose(pose, (fwd, 0.0, turn))
        img = render_room_view(room, pose[0], pose[1], Camera(yaw_deg=pose[2]))
        out.append((img, (fwd, 0.0, turn), pose))
    return out


def bench_trackers(
    frames: int = 60, repeats: int = 5, seed: int = 0, progress: bool = False
) -> dict[str, object]:
    """Median cost of one update of every registered tracker, measured side by side.

    Parameters
    ----------
    frames : int
        Frames of the walk (each round runs every tracker over all of them; 1 to
        :data:`MAX_FRAMES`).
    repeats : int
        Rounds (medians over rounds x frames; 1 to :data:`MAX_REPEATS`).
    seed : int
        Seed of the room and the walk.
    progress : bool
        Show a progress bar.

    Returns
    -------
    dict
        ``{"atlas_ms": ..., "trackers": {name: {"update_ms", "overhead_ms",
        "final_heading_error_deg", "final_position_error_m"}}, ...}``.
    """
    int_in_range("frames", frames, 1, MAX_FRAMES)
    int_in_range("repeats", repeats, 1, MAX_REPEATS)
    check_seed("seed", seed)
    rng = np.random.default_rng(seed)
    room = make_room(rng)
    atlas = _atlas(room)
    walk = _walk(room, rng, frames)
    names = sorted(TRACKERS)
    times: dict[str, list[float]] = {n: [] for n in ["atlas", *names]}
    final: dict[str, tuple[float, float]] = {}
    for _ in tqdm(range(repeats), desc="rounds", disable=not progress):
        for img, _, _ in walk:
            t0 = time.perf_counter()
            atlas.estimate_position(img, Camera())
            times["atlas"].append(time.perf_counter() - t0)
        for name in names:
            tracker = make_tracker(name)
            tracker.reset(atlas, Camera(), 0.1)
            for img, odo, _ in walk:
                t0 = time.perf_counter()
                state = tracker.update(img, 0.0, odo)
                times[name].append(time.perf_counter() - t0)
            true = walk[-1][2]
            final[name] = (
                abs(float(wrap180(state.heading_deg - true[2]))),
                math.hypot(state.position[0] - true[0], state.position[1] - true[1]),
            )
    atlas_ms = float(np.median(times["atlas"]) * 1e3)
    result = {
        "frame": "208x160",
        "spots": len(SPOTS),
        "frames": frames,
        "repeats": repeats,
        "atlas_ms": round(atlas_ms, 3),
        "trackers": {
            n: {
                "update_ms": round(float(np.median(times[n]) * 1e3), 3),
                "overhead_ms": round(float(np.median(times[n]) * 1e3) - atlas_ms, 3),
                "final_heading_error_deg": round(final[n][0], 2),
                "final_position_error_m": round(final[n][1], 3),
            }
            for n in names
        },
    }
    return result
