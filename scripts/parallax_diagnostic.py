"""Diagnostic (not part of the package): how much of the improved mode's heading error
near a spot is parallax, and how much a map re-drawn for the robot's position removes.

For every view of the orientation experiment's paper-size grid (10 frames standing at a
pose, head scanning) the heading is read from likelihoods summed over its frames:

* ``nearest``: the map of the nearest spot of the improved mode's 1.0 m grid, learned as
  the improved mode learns it (the spot's turn and four turns 0.5 m around it merged);
* ``warped, ray-cast depth``: the spot's own map (no turns around it) with every sector
  moved to the direction its wall point has from the robot's position, the wall point
  at the distance a ray from the spot hits (the simulator's geometry, an oracle);
* ``warped, learned depth``: the same with each sector's distance learned from the turns
  around the spot: the distance at which the sector's colour transitions, seen from the
  four turns 0.5 m away, fit the spot's histograms best;
* ``each turn warped``: the spot's turn and each turn around it warped from where it was
  taken, with the learned distances, and added up.

The robot's position is the true one plus Gaussian noise of ``--noise`` metres per axis.

The scene ``ray-cast-room`` runs the ``--joint`` search in the tests' ray-cast room
instead (exact walls, no furniture; the spot's map alone for comparison).

``--joint K`` instead asks whether the views themselves tell the position: the pose
likelihood (:meth:`~vc_gym.compass.parallax.ParallaxMap.pose_log_likelihood`, each
spot's map centred with its turns around) of the K spots nearest the view, summed over
the view's frames and over the spots, on positions 0.1 m apart within 0.6 m of the
nearest spot; the heading and position of its maximum, and for comparison the heading at
the true position; ``--ray-depths`` uses the ray-cast distances instead of the learned.

    python scripts/parallax_diagnostic.py office --noise 0 0.2 0.4
    python scripts/parallax_diagnostic.py office --joint 1 2 4
    python scripts/parallax_diagnostic.py ray-cast-room --exposure mean
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from vc_gym.angles import interp_circular, wrap180
from vc_gym.compass import Camera, CompassAtlas, CompassConfig, VisualCompass
from vc_gym.compass.parallax import ParallaxMap, learn_depths
from vc_gym.experiments.atlases import atlas_spec, learn_atlas_job
from vc_gym.experiments.studies.common import scene_field_bounds
from vc_gym.experiments.studies.orientation_grid import GRID_AROUND_M, training_spots
from vc_gym.experiments.views import field_grid, frames_at_pose, learning_turn, view_poses
from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.worlds.room import make_room, render_room_view

EYE_HEIGHT_M = 0.30


def atlas(
    scene: str, around_m: float, cache: Path, seed: int, exposure: str = "mean"
) -> CompassAtlas:
    """The improved mode's atlas (exposure="mean"), with or without the turns around."""
    spots = training_spots(scene_field_bounds(scene), "improved")
    spec = atlas_spec(
        scene, seed, "grid", 5.0, {"exposure": exposure}, spots=spots, around_m=around_m
    )
    tag = "" if exposure == "mean" else f"-{exposure}"
    path = cache / f"{scene}-seed{seed}-around{around_m}{tag}.npz"
    if not path.exists():
        learn_atlas_job(spec, str(path))
    return CompassAtlas.load(path)


def ray_depths(env: AiboRoomEnv, spot, sector_deg: float) -> np.ndarray:
    """Per sector, the median horizontal distance of the first hit over 2-25° of
    elevation from the spot (the simulator's geometry: an oracle)."""
    bc, robot = env.client, env.robot.body_id
    n = int(round(360.0 / sector_deg))
    out = np.full(n, 8.0)
    for s, th in enumerate(np.radians((np.arange(n) + 0.5) * sector_deg)):
        found = []
        for el in np.radians([2.0, 8.0, 15.0, 25.0]):
            a = np.array([spot[0], spot[1], EYE_HEIGHT_M])
            b = a + 20.0 * np.array(
                [math.cos(th) * math.cos(el), math.sin(th) * math.cos(el), math.sin(el)]
            )
            hit = bc.rayTestBatch([a.tolist()], [b.tolist()])[0]
            if hit[0] >= 0 and hit[0] != robot:
                found.append(20.0 * hit[2] * math.cos(el))
        if found:
            out[s] = float(np.median(found))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--noise", type=float, nargs="+", default=[0.0, 0.2, 0.4])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--cache", type=Path, default=Path("parallax_cache"))
    ap.add_argument("--joint", type=int, nargs="+", default=[], metavar="K")
    ap.add_argument("--ray-depths", action="store_true", help="--joint with the ray-cast distances")
    ap.add_argument(
        "--exposure", default="mean", help='the maps\' exposure mode (the improved mode: "mean")'
    )
    args = ap.parse_args()
    if args.scene == "ray-cast-room":
        ray_cast_room(args.exposure)
        return
    args.cache.mkdir(parents=True, exist_ok=True)
    merged = atlas(args.scene, GRID_AROUND_M, args.cache, args.seed, args.exposure)
    alone = atlas(args.scene, 0.0, args.cache, args.seed, args.exposure)
    env = AiboRoomEnv(scene=args.scene)
    env.reset(seed=args.seed)
    cam = Camera(hfov_deg=env.camera.hfov_deg)
    spots, ray, learned, each = alone.positions, [], [], []
    sector_deg = alone.compasses[0].config.sector_deg
    for k, (spot, vc) in enumerate(zip(spots, alone.compasses, strict=True)):
        around = []
        for j, (ox, oy) in enumerate(
            [(GRID_AROUND_M, 0), (-GRID_AROUND_M, 0), (0, GRID_AROUND_M), (0, -GRID_AROUND_M)]
        ):
            m = VisualCompass(vc.config, vc.colors)
            for img, c in learning_turn(env, (spot[0] + ox, spot[1] + oy), 12, 5000 + 10 * k + j):
                m.learn(img, c)
            around.append(((ox, oy), m))
        ray.append(ParallaxMap(spot, ray_depths(env, spot, sector_deg), [(spot, vc)]))
        learned.append(ParallaxMap(spot, learn_depths(vc, around), [(spot, vc)]))
        each.append(ParallaxMap.learn(spot, vc, around))
    ratio = np.abs(
        np.log(
            np.concatenate([p.depths_m for p in learned])
            / np.concatenate([p.depths_m for p in ray])
        )
    )
    print(
        f"{args.scene}: learned depth against ray-cast, median |log ratio| "
        f"{np.median(ratio):.2f}, within 30 %: {np.mean(ratio < np.log(1.3)):.0%}"
    )
    grid = field_grid(tuple(env.scene.field_bounds), 0.5)
    poses = view_poses(grid, 2, np.random.default_rng([args.seed, 51]))
    views = [frames_at_pose(env, tuple(p), 10, seed=1000 + k) for k, p in enumerate(poses)]
    headings = np.arange(360.0)
    if args.joint:
        if args.ray_depths:
            each = [
                ParallaxMap(e.spot, r.depths_m, e.parts) for e, r in zip(each, ray, strict=True)
            ]
        joint(args.scene, poses, views, spots, each, merged, cam, args.joint)
        return
    for noise in args.noise:
        rng = np.random.default_rng(99)
        errors: dict[str, list[float]] = {}
        for pose, seen in zip(poses, views, strict=True):
            i = int(np.argmin(np.hypot(spots[:, 0] - pose[0], spots[:, 1] - pose[1])))
            guess = pose[:2] + rng.normal(0.0, noise, 2)
            maps = {
                "nearest": merged.compasses[i],
                "warped, ray-cast depth": ray[i].at(guess),
                "warped, learned depth": learned[i].at(guess),
                "each turn warped": each[i].at(guess),
            }
            for name, m in maps.items():
                total = np.zeros(360)
                for img, pan, _ in seen:
                    total += interp_circular(m.log_likelihood(img, cam), 1.0, headings + pan)
                errors.setdefault(name, []).append(abs(wrap180(np.argmax(total) - pose[2])))
        for name, e in errors.items():
            print(
                f"  noise {noise:.1f} m  {name:24s} mean {np.mean(e):5.2f}°, "
                f"median {np.median(e):5.2f}° ({len(e)} views)"
            )


def joint(scene, poses, views, spots, each, merged, cam, ks) -> None:
    """Heading and position from the pose likelihood of the K nearest spots' maps (and,
    for comparison, the heading from the nearest spot's map as the improved mode learns
    it)."""
    step = np.arange(-0.6, 0.6 + 1e-9, 0.1)
    offsets = np.stack(np.meshgrid(step, step, indexing="ij"), axis=-1).reshape(-1, 2)
    headings = np.arange(360.0)
    errors: dict[str, list[float]] = {}
    for pose, seen in zip(poses, views, strict=True):
        order = np.argsort(np.hypot(spots[:, 0] - pose[0], spots[:, 1] - pose[1]))
        cand = spots[order[0]] + offsets
        total = np.zeros((len(cand), 360))
        at_true = np.zeros(360)
        nearest = np.zeros(360)
        for img, pan, _ in seen:
            ll = merged.compasses[order[0]].log_likelihood(img, cam)
            nearest += interp_circular(ll, 1.0, headings + pan)
        errors.setdefault("nearest map", []).append(abs(wrap180(np.argmax(nearest) - pose[2])))
        for k in range(max(ks)):
            pm = each[order[k]]
            rows = pm.sector_maps(np.vstack([cand, pose[None, :2]]))
            for img, pan, _ in seen:
                ll = pm.centred().log_likelihood_remapped(img, cam, rows)
                ll = interp_circular(ll, 1.0, headings + pan)
                total += ll[:-1]
                at_true += ll[-1]
            if k + 1 in ks:
                n, h = np.unravel_index(np.argmax(total), total.shape)
                for name, value in [
                    ("heading at the best pose", abs(wrap180(h - pose[2]))),
                    ("position error of it (m)", float(np.hypot(*(cand[n] - pose[:2])))),
                    ("heading at the true position", abs(wrap180(np.argmax(at_true) - pose[2]))),
                ]:
                    errors.setdefault(f"K={k + 1} {name}", []).append(value)
    for name, e in errors.items():
        print(f"  {scene} {name:36s} mean {np.mean(e):5.2f}, median {np.median(e):5.2f}")


def ray_cast_room(exposure: str) -> None:
    """The pose likelihood in the tests' 4 x 3 m ray-cast room (exact walls, no furniture):
    20 views of 10 frames 0.2-0.6 m from the spot, the best of 13 x 13 positions."""
    room = make_room(np.random.default_rng(3), width_m=4.0, depth_m=3.0)
    yaws = [b + p for b in range(0, 360, 45) for p in (-22.5, 0.0, 22.5)]
    config = CompassConfig(exposure=exposure)

    def turn(x: float, y: float, colors=None) -> VisualCompass:
        vc = VisualCompass(config, colors)
        if colors is None:
            vc.fit_colors([render_room_view(room, x, y, Camera(yaw_deg=a)) for a in yaws[1::3]])
        for a in yaws:
            vc.learn(render_room_view(room, x, y, Camera(yaw_deg=a)), Camera(yaw_deg=a))
        return vc

    spot = turn(0.0, 0.0)
    around = [((0.5, 0.0), 0), ((-0.5, 0.0), 0), ((0.0, 0.5), 0), ((0.0, -0.5), 0)]
    pm = ParallaxMap.learn((0, 0), spot, [(o, turn(*o, spot.colors)) for o, _ in around])
    step = np.arange(-0.6, 0.61, 0.1)
    cand = np.stack(np.meshgrid(step, step, indexing="ij"), axis=-1).reshape(-1, 2)
    rows = pm.sector_maps(cand)
    rng = np.random.default_rng(11)
    errors: dict[str, list[float]] = {}
    for _ in range(20):
        r, a = rng.uniform(0.2, 0.6), rng.uniform(0.0, 2 * np.pi)
        pos, yaw = np.array([r * np.cos(a), r * np.sin(a)]), rng.uniform(0.0, 360.0)
        total, plain = np.zeros((len(cand), 360)), np.zeros(360)
        for pan in (-20, 0, 20, 40, 20, 0, -20, 0, 20, 40):
            img = render_room_view(room, *pos, Camera(yaw_deg=yaw + pan))
            total += np.roll(pm.centred().log_likelihood_remapped(img, Camera(), rows), -pan, 1)
            plain += np.roll(spot.log_likelihood(img, Camera()), -pan)
        n, h = np.unravel_index(np.argmax(total), total.shape)
        for name, value in [
            ("position error of the best pose (m)", float(np.hypot(*(cand[n] - pos)))),
            ("heading at the best pose", abs(wrap180(h - yaw))),
            ("heading from the spot's map", abs(wrap180(np.argmax(plain) - yaw))),
        ]:
            errors.setdefault(name, []).append(value)
    for name, e in errors.items():
        print(
            f"  ray-cast room, {exposure}: {name:36s} "
            f"mean {np.mean(e):5.2f}, median {np.median(e):5.2f}"
        )


if __name__ == "__main__":
    main()
