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

    python scripts/parallax_diagnostic.py office --noise 0 0.2 0.4
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from vc_gym.angles import interp_circular, wrap180
from vc_gym.compass import Camera, CompassAtlas, VisualCompass
from vc_gym.envs.aibo_room import AiboRoomEnv
from vc_gym.experiments.atlases import atlas_spec, learn_atlas_job
from vc_gym.experiments.studies.common import scene_field_bounds
from vc_gym.experiments.studies.orientation import GRID_AROUND_M, training_spots
from vc_gym.experiments.views import field_grid, learning_turn, look, view_poses

EYE_HEIGHT_M = 0.30
DEPTHS_M = np.geomspace(0.4, 8.0, 40)


def atlas(scene: str, around_m: float, cache: Path, seed: int) -> CompassAtlas:
    """The improved mode's atlas (exposure="mean"), with or without the turns around."""
    spots = training_spots(scene_field_bounds(scene), "improved")
    spec = atlas_spec(
        scene, seed, "grid", 5.0, {"exposure": "mean"}, spots=spots, around_m=around_m
    )
    path = cache / f"{scene}-seed{seed}-around{around_m}.npz"
    if not path.exists():
        learn_atlas_job(spec, str(path))
    return CompassAtlas.load(path)


class Parallax:
    """Sector geometry of one atlas' maps (sector centres, re-indexing by position)."""

    def __init__(self, env: AiboRoomEnv, vc: VisualCompass):
        self.env, self.cfg = env, vc.config
        self.n = vc.config.n_sectors
        self.theta = np.radians((np.arange(self.n) + 0.5) * vc.config.sector_deg)

    def sector_of(self, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
        deg = np.degrees(np.arctan2(dy, dx)) % 360.0
        return np.floor(deg / self.cfg.sector_deg).astype(int) % self.n

    def ray_depth(self, x: float, y: float) -> np.ndarray:
        """Median horizontal distance of the first hit over 2-25° of elevation."""
        bc, robot = self.env.client, self.env.robot.body_id
        out = np.full(self.n, 8.0)
        for s, th in enumerate(self.theta):
            found = []
            for el in np.radians([2.0, 8.0, 15.0, 25.0]):
                a = np.array([x, y, EYE_HEIGHT_M])
                b = a + 20.0 * np.array(
                    [math.cos(th) * math.cos(el), math.sin(th) * math.cos(el), math.sin(el)]
                )
                hit = bc.rayTestBatch([a.tolist()], [b.tolist()])[0]
                if hit[0] >= 0 and hit[0] != robot:
                    found.append(20.0 * hit[2] * math.cos(el))
            if found:
                out[s] = float(np.median(found))
        return out

    def learned_depth(self, vc: VisualCompass, turns: list) -> np.ndarray:
        """Per sector, the distance whose predicted view from every turn around fits best."""
        log_p = vc._log_tables()[2]  # (S, pairs, bins) of the spot's map
        score = np.zeros((self.n, DEPTHS_M.size))
        for (ox, oy), m in turns:
            wx = DEPTHS_M[None, :] * np.cos(self.theta)[:, None] - ox
            wy = DEPTHS_M[None, :] * np.sin(self.theta)[:, None] - oy
            s2 = self.sector_of(wx, wy)
            fit = np.einsum("sqb,tqb->st", log_p, m._counts) / np.maximum(m._n_obs, 1.0)
            rows = np.arange(self.n)[:, None]
            score += np.where(m._n_obs[s2] > 0, fit[rows, s2], 0.0)
        return DEPTHS_M[np.argmax(score, axis=1)]

    def spot_part(self, vc: VisualCompass, spot, depth: np.ndarray) -> tuple:
        """The spot's map and the wall points its sectors look at."""
        th = self.theta
        return vc, spot[0] + depth * np.cos(th), spot[1] + depth * np.sin(th)

    def wall_points(self, spot, depth, origin) -> tuple[np.ndarray, np.ndarray]:
        """What each sector of a turn at ``origin`` looks at, on the spot's depth field."""
        ox, oy = origin[0] - spot[0], origin[1] - spot[1]
        r = depth.copy()
        for _ in range(6):  # fixed point: the spot's distance towards the point hit
            s = self.sector_of(ox + r * np.cos(self.theta), oy + r * np.sin(self.theta))
            hx, hy = depth[s] * np.cos(self.theta[s]), depth[s] * np.sin(self.theta[s])
            r = np.maximum(np.hypot(hx - ox, hy - oy), 0.1)
        return origin[0] + r * np.cos(self.theta), origin[1] + r * np.sin(self.theta)

    def warped(self, parts, like: VisualCompass, position) -> VisualCompass:
        """The maps ``[(map, wall x, wall y)]`` re-indexed for ``position``, added up."""
        w = VisualCompass(self.cfg, like.colors)
        for m, wx, wy in parts:
            s2 = self.sector_of(wx - position[0], wy - position[1])
            np.add.at(w._counts, s2, m._counts)
            np.add.at(w._n_obs, s2, m._n_obs)
        w._frames, w._sizes, w._tables = like._frames, set(like._sizes), None
        return w


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--noise", type=float, nargs="+", default=[0.0, 0.2, 0.4])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--cache", type=Path, default=Path("parallax_cache"))
    args = ap.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)
    merged = atlas(args.scene, GRID_AROUND_M, args.cache, args.seed)
    alone = atlas(args.scene, 0.0, args.cache, args.seed)
    env = AiboRoomEnv(scene=args.scene)
    env.reset(seed=args.seed)
    geo = Parallax(env, alone.compasses[0])
    cam = Camera(hfov_deg=env.camera.hfov_deg)
    spots, ray, learned, turns = alone.positions, [], [], []
    for k, (spot, vc) in enumerate(zip(spots, alone.compasses, strict=True)):
        mine = []
        for j, (ox, oy) in enumerate(
            [(GRID_AROUND_M, 0), (-GRID_AROUND_M, 0), (0, GRID_AROUND_M), (0, -GRID_AROUND_M)]
        ):
            m = VisualCompass(vc.config, vc.colors)
            for img, c in learning_turn(env, (spot[0] + ox, spot[1] + oy), 12, 5000 + 10 * k + j):
                m.learn(img, c)
            mine.append(((ox, oy), m))
        turns.append(mine)
        ray.append(geo.ray_depth(*spot))
        learned.append(geo.learned_depth(vc, mine))
    ratio = np.abs(np.log(np.concatenate(learned) / np.concatenate(ray)))
    print(
        f"{args.scene}: learned depth against ray-cast, median |log ratio| "
        f"{np.median(ratio):.2f}, within 30 %: {np.mean(ratio < np.log(1.3)):.0%}"
    )
    grid = field_grid(tuple(env.scene.field_bounds), 0.5)
    poses = view_poses(grid, 2, np.random.default_rng([args.seed, 51]))
    views = [look(env, tuple(p), 10, seed=1000 + k) for k, p in enumerate(poses)]
    headings = np.arange(360.0)
    for noise in args.noise:
        rng = np.random.default_rng(99)
        errors: dict[str, list[float]] = {}
        for pose, seen in zip(poses, views, strict=True):
            i = int(np.argmin(np.hypot(spots[:, 0] - pose[0], spots[:, 1] - pose[1])))
            spot, vc = spots[i], alone.compasses[i]
            guess = pose[:2] + rng.normal(0.0, noise, 2)
            each = [geo.spot_part(vc, spot, learned[i])] + [
                (m, *geo.wall_points(spot, learned[i], (spot[0] + ox, spot[1] + oy)))
                for (ox, oy), m in turns[i]
            ]
            maps = {
                "nearest": merged.compasses[i],
                "warped, ray-cast depth": geo.warped([geo.spot_part(vc, spot, ray[i])], vc, guess),
                "warped, learned depth": geo.warped(
                    [geo.spot_part(vc, spot, learned[i])], vc, guess
                ),
                "each turn warped": geo.warped(each, vc, guess),
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


if __name__ == "__main__":
    main()
