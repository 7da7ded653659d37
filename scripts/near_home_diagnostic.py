"""How the tracker's position near home relates to the true one, for a learned agent's env.

For a few learning seeds, puts the robot of ``vc_gym/Homing-v0`` (as ``vc-gym train``
builds it, its default mode or ``--mode``) at known offsets from home (every radius of
``--radii`` in 8 directions, a heading drawn from the seed), lets it stand with the head
scanning for ``--stand`` seconds, and compares the tracker's position with the truth.
Prints the least-squares gain ``estimate ≈ G · truth + b`` and the residual spread: a gain
well below 1 is a scale error a calibration could undo; a residual as large as the offsets
is noise that only a better measurement removes. It is a diagnostic, not a command; its
numbers are not results.

    python scripts/near_home_diagnostic.py --seeds 100,200
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import gymnasium as gym
import numpy as np

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.envs.homing import HomingFeatures
from vc_gym.envs.learning import HOME
from vc_gym.training.config import TrainConfig


def run(seeds: list[int], radii: list[float], stand_s: float, mode: str, cache: str) -> list:
    config = TrainConfig(mode=mode)
    rows = []
    for seed in seeds:
        env = gym.make(
            "vc_gym/Homing-v0", **config.env_kwargs(), learning_seed=seed, place_cache=cache
        )
        rng = np.random.default_rng(seed)
        steps = int(round(stand_s / env.unwrapped.control_dt))
        for r in radii:
            for k in range(8):
                a = 2 * math.pi * k / 8
                truth = (HOME[0] + r * math.cos(a), HOME[1] + r * math.sin(a))
                yaw = float(rng.uniform(-180, 180))
                obs, info = env.reset(seed=seed * 1000 + k, options={"pose": (*truth, yaw)})
                # a walk decision too small to move: the slowest turn, the head scanning
                for _ in range(steps):
                    obs, _, term, trunc, info = env.step(np.zeros(3, np.float32))
                    if term or trunc:
                        break
                est = obs[HomingFeatures.POSITION] * HomingFeatures.METRES_SCALE
                pose = info["pose"]
                rows.append(
                    {
                        "seed": seed,
                        "radius_m": r,
                        "true": [float(pose[0] - HOME[0]), float(pose[1] - HOME[1])],
                        "estimate": [float(est[0]), float(est[1])],
                    }
                )
        env.close()
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", default="100,200")
    p.add_argument("--radii", default="0.1,0.2,0.3")
    p.add_argument("--stand", type=float, default=3.0, help="seconds standing before reading")
    p.add_argument("--mode", default="pose-home")
    p.add_argument("--cache", default="expert_places")
    p.add_argument("--out", default="near_home_diagnostic.json")
    args = p.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    radii = [float(s) for s in args.radii.split(",")]
    rows = run(seeds, radii, args.stand, args.mode, args.cache)
    t = np.array([row["true"] for row in rows])
    e = np.array([row["estimate"] for row in rows])
    design = np.hstack([t, np.ones((len(t), 1))])
    coef, *_ = np.linalg.lstsq(design, e, rcond=None)
    residual = e - design @ coef
    print(f"gain G (rows: estimate x, y) =\n{np.round(coef[:2].T, 2)}\noffset b = "
          f"{np.round(coef[2], 3)} m; residual std per axis {np.round(residual.std(axis=0), 3)} m")
    for r in radii:
        m = np.array([row["radius_m"] == r for row in rows])
        err = np.linalg.norm(e[m] - t[m], axis=1)
        along = np.sum(e[m] * t[m], axis=1) / r  # the estimate along the true direction
        print(f"radius {r:.2f} m: mean |estimate - truth| {err.mean():.3f} m, estimate along "
              f"the true direction {along.mean():.3f} m (ratio {along.mean() / r:.2f})")
    Path(args.out).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
