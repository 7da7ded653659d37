"""Diagnostic (not part of the package): how well does the pose likelihood of maps
re-drawn for a position (:class:`~vc_gym.compass.pose_maps.PoseMaps`) tell the position
of a walking robot?

The robot walks between random waypoints on the field (head scanning, as the tracking
experiment's robot), and at every frame the frame's log-likelihood is evaluated on poses
around the true one: positions on a 5 cm grid within ``--reach`` metres, camera headings
within ±6°. For each window of ``W`` frames the likelihoods are summed with every frame's
grid placed around that frame's own true pose (the robot's relative motion known
exactly: the best any filter with perfect odometry could do), and the distance of the
maximum from the truth is recorded. If the likelihood told the position, that distance
would shrink towards zero as the window grows.

Maps (``--maps``):

* ``centred``: what the pose tracker uses, each spot's map with its four turns around
  merged in (:meth:`PoseMaps.from_atlas`);
* ``spot``: each spot's own map only, re-drawn with the distances learned from its turns;
* ``dense``: ``spot`` plus each turn around a spot as a map of its own (0.5 m apart).

``--sensor bearings`` scores the same grid with the landmarks' bearings instead
(:class:`~vc_gym.localization.bearing_sensor.BearingSensor`): the colour changes of the
atlas' learning turns (re-rendered at the atlas' spots and turns, every 15°, with the
atlas' colour classes) triangulated into landmarks; ``--sensor both`` prints the two
side by side on the same walk.

``--spots`` chooses the map each candidate is scored with: ``nearest`` (the pose
tracker's rule: the spot nearest the candidate), ``fixed`` (the spot nearest the truth,
for every candidate: no switching between maps inside the grid), ``offset`` (nearest,
with each spot's best candidate of the frame set to zero: only the shape of each map's
likelihood counts, not its level) or ``best2`` (the better of the two nearest spots).

    python scripts/pose_likelihood_diagnostic.py robolab --seed 100 --windows 1 20 60 150
    python scripts/pose_likelihood_diagnostic.py robolab --seed 100 --maps dense
    python scripts/pose_likelihood_diagnostic.py robolab --seed 100 --spots fixed
    python scripts/pose_likelihood_diagnostic.py plain_house --seed 100 --sensor both --grid 0.02
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.compass import Camera, CompassAtlas
from vc_gym.compass.bearings import bands_bearings
from vc_gym.compass.landmarks import LearnedView, learn_landmarks
from vc_gym.compass.parallax import ParallaxMap
from vc_gym.compass.pose_maps import PoseMaps, around_groups
from vc_gym.envs.learning import HEAD_SCAN_DEG
from vc_gym.experiments.atlases import atlas_spec, learn_atlas_job
from vc_gym.experiments.benchmarks.bearings import frame_at_pose
from vc_gym.experiments.studies.common import scene_field_bounds
from vc_gym.experiments.studies.orientation_grid import GRID_AROUND_M, training_spots
from vc_gym.exposure import SessionLight
from vc_gym.localization.bearing_sensor import BearingSensor
from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.sim.robot import EYE_OFFSET_M

HEADING_OFFSETS_DEG = np.arange(-6.0, 6.5, 2.0)
GRID_STEP_M = 0.05


def load_atlas(scene: str, seed: int, exposure: str, cache: Path) -> CompassAtlas:
    """The tracking experiment's atlas (spots 1.0 m apart, turns 0.5 m around each kept)."""
    path = cache / f"{scene}-{seed}-{exposure}.npz"
    if not path.exists():
        cache.mkdir(parents=True, exist_ok=True)
        spots = training_spots(scene_field_bounds(scene), "spot-grid")
        spec = atlas_spec(
            scene, seed, "grid", 5.0, {"exposure": exposure}, spots=spots,
            around_m=GRID_AROUND_M, keep_around=True,
        )
        learn_atlas_job(spec, str(path))
    return CompassAtlas.load(path)


def pose_maps(atlas: CompassAtlas, kind: str) -> PoseMaps:
    """The maps the likelihood is read from (see the module docstring)."""
    if kind == "centred":
        return PoseMaps.from_atlas(atlas)
    index = {n: k for k, n in enumerate(atlas.names)}
    maps = []
    for name, members in around_groups(atlas.names).items():
        k = index[name]
        spot, spot_map = atlas.positions[k], atlas.compasses[k]
        around = [
            (atlas.positions[index[m]] - spot, atlas.compasses[index[m]]) for m in members[1:]
        ]
        learned = ParallaxMap.learn(spot, spot_map, around)
        maps.append(ParallaxMap(spot, learned.depths_m, [(spot, spot_map)]))
        if kind == "dense":
            for m in members[1:]:
                o = atlas.positions[index[m]]
                depth = np.maximum(np.linalg.norm(learned.wall_points(o) - o, axis=1), 0.1)
                maps.append(ParallaxMap(o, depth, [(o, atlas.compasses[index[m]])]))
    return PoseMaps(maps)


def bearing_sensor(room: AiboRoomEnv, atlas: CompassAtlas, camera: Camera) -> BearingSensor:
    """Landmarks from turns at every position of the atlas (its spots and the turns around
    them), seen with the atlas' colour classes, as a sensor."""
    colors = atlas.compasses[0].colors
    views = []
    for x, y in atlas.positions:
        for yaw in range(0, 360, 15):
            image, cam, (ex, ey, eye_yaw), _ = frame_at_pose(
                room, camera, float(x), float(y), float(yaw)
            )
            views.append(LearnedView(bands_bearings(image, cam, colors), eye_yaw, ex, ey))
    landmarks = learn_landmarks(views)
    print(f"{len(landmarks)} landmarks from {len(views)} learning frames "
          f"(median uncertainty {np.median(landmarks.std_m):.3f} m)")
    return BearingSensor(landmarks, colors, camera, eye_forward_m=EYE_OFFSET_M[0])


def bearing_scores(sensor, image, camera, pitch, xy, body_heading, pan) -> np.ndarray:
    """``(cells, headings)`` log-likelihoods of the grid from the frame's bearings."""
    found = bands_bearings(image, camera.replace(pitch_deg=pitch), sensor.colors)
    poses = np.column_stack([np.repeat(xy, len(body_heading), axis=0),
                             np.tile(body_heading, len(xy))])
    return sensor.pose_log_likelihood(found, poses, pan).reshape(len(xy), len(body_heading))


def summary(name: str, frames: list[np.ndarray], windows, offsets) -> None:
    """The table of one sensor: distance of the summed likelihood's maximum from the truth."""
    print(f"{name}: {len(frames)} frames")
    print("window (frames) | median m off | mean m off | within 0.15 m | within 0.05 m"
          " | mean |heading off|")
    for w in windows:
        off, head = [], []
        for end in range(w, len(frames) + 1):
            total = np.sum(frames[end - w:end], axis=0)
            cell, h = np.unravel_index(np.argmax(total), total.shape)
            off.append(math.hypot(*offsets[cell]))
            head.append(abs(HEADING_OFFSETS_DEG[h]))
        off = np.asarray(off)
        print(f"{w:15d} | {np.median(off):12.3f} | {off.mean():10.3f} | "
              f"{np.mean(off <= 0.15):13.0%} | {np.mean(off <= 0.05):13.0%} | {np.mean(head):.1f}°")


def scored(maps, terms, xy, camera_heading, truth, rule: str) -> np.ndarray:
    """``(cells, headings)`` log-likelihoods of the grid under the spot rule ``rule``."""
    def under(spot):
        return np.stack(
            [maps.log_likelihood(terms, xy, np.full(len(xy), h), spot) for h in camera_heading],
            axis=1,
        )

    if rule == "fixed":
        return under(np.full(len(xy), maps.nearest(truth[None, :2])[0]))
    nearest = maps.nearest(xy)
    ll = under(nearest)
    if rule == "offset":
        for s in np.unique(nearest):
            ll[nearest == s] -= ll[nearest == s].max()
    elif rule == "best2":
        d = np.linalg.norm(xy[:, None, :] - maps.positions[None], axis=2)
        second = np.argsort(d, axis=1)[:, 1]
        ll = np.maximum(ll, under(second))
    return ll


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--seed", type=int, default=100, help="learning seed (default 100)")
    ap.add_argument("--exposure", default="session", help="the atlas' exposure (default session)")
    ap.add_argument("--maps", choices=["centred", "spot", "dense"], default="centred")
    ap.add_argument("--spots", choices=["nearest", "fixed", "offset", "best2"], default="nearest")
    ap.add_argument("--frames", type=int, default=400, help="frames walked (0.1 s each)")
    ap.add_argument("--windows", type=int, nargs="+", default=[1, 20, 60, 150])
    ap.add_argument("--reach", type=float, default=0.6, help="half-width of the grid, m")
    ap.add_argument("--cache", type=Path, default=Path("vc_gym_diagnostic_atlases"))
    ap.add_argument("--sensor", choices=["sectors", "bearings", "both"], default="sectors",
                    help="sector histograms (the maps), the landmarks' bearings, or both")
    ap.add_argument("--grid", type=float, default=GRID_STEP_M, help="grid step, m")
    a = ap.parse_args()

    atlas = load_atlas(a.scene, a.seed, a.exposure, a.cache)
    maps = pose_maps(atlas, a.maps)
    x0, x1, y0, y1 = scene_field_bounds(a.scene)
    room = AiboRoomEnv(scene=a.scene)
    camera = Camera(hfov_deg=room.camera.hfov_deg)
    light = SessionLight(100)
    sensors = ["sectors", "bearings"] if a.sensor == "both" else [a.sensor]
    bearings = bearing_sensor(room, atlas, camera) if "bearings" in sensors else None
    axis = np.arange(-a.reach, a.reach + 1e-9, a.grid)
    gx, gy = np.meshgrid(axis, axis, indexing="ij")
    offsets = np.c_[gx.ravel(), gy.ravel()]

    rng = np.random.default_rng(a.seed)
    _, info = room.reset(seed=a.seed, options={"pose": (0.0, 0.0, 30.0)})
    waypoint = rng.uniform([x0, y0], [x1, y1])
    frames: dict[str, list[np.ndarray]] = {name: [] for name in sensors}
    for f in range(a.frames):
        pose = info["pose"]
        d = waypoint - pose[:2]
        if math.hypot(*d) < 0.25:
            waypoint = rng.uniform([x0, y0], [x1, y1])
            d = waypoint - pose[:2]
        err = wrap180(math.degrees(math.atan2(d[1], d[0])) - pose[2])
        turn = float(np.clip(err, -6.0, 6.0)) / room.control_dt
        forward = 0.4 if abs(err) < 25 else 0.0
        pan = HEAD_SCAN_DEG[f % len(HEAD_SCAN_DEG)]
        obs, _, _, _, info = room.step(
            room.velocity_action(forward_m_s=forward, turn_deg_s=turn, pan_deg=pan)
        )
        truth = np.asarray(info["pose"], dtype=np.float64)
        xy = truth[:2] + offsets
        pan = float(obs["head"][0])
        if bearings is not None:
            pitch = room.robot.eye()[2]
            body = truth[2] + HEADING_OFFSETS_DEG
            frames["bearings"].append(
                bearing_scores(bearings, obs["image"], camera, pitch, xy, body, pan)
            )
        if "sectors" not in sensors:
            continue
        gain = None
        if maps.config.exposure == "session":
            gain = light.update(maps.maps[0].frame_gain(obs["image"], camera))
        terms = maps.frame(obs["image"], camera, None, gain)
        camera_heading = (truth[2] + pan + HEADING_OFFSETS_DEG) % 360.0
        if terms.has_evidence:
            frames["sectors"].append(scored(maps, terms, xy, camera_heading, truth, a.spots))
        else:  # no evidence: the same for every pose
            frames["sectors"].append(np.zeros((len(xy), len(camera_heading))))
    room.close()

    print(f"{a.scene}, seed {a.seed}, exposure {a.exposure}, maps {a.maps}, spots {a.spots}, "
          f"grid {a.grid} m; the motion known exactly (0.1 s a frame)")
    for name in sensors:
        summary(name, frames[name], a.windows, offsets)


if __name__ == "__main__":
    main()
