"""What the feature expert's stops look like on a learned agent's env, by expert setting.

For a few learning seeds, lets :class:`~vc_gym.training.HomingFeatureExpert` variants home
on ``vc_gym/Homing-v0`` as ``vc-gym train`` builds it (its default mode, or ``--mode``) and
prints, per variant, success within 30 cm, mean stop distance, mean homing time and, with
the ``pose-grid`` tracker, the pose belief's own position spread and error at the stops
that succeeded and that did not. It is a diagnostic for choosing an expert to clone, not a
command; its numbers are not results.

    python scripts/expert_diagnostic.py --seeds 100,200 --episodes 12
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
from vc_gym.training.config import TrainConfig
from vc_gym.training.feature_expert import HomingFeatureExpert


def run(seeds: list[int], episodes: int, mode: str, variants: dict, cache: str) -> dict:
    config = TrainConfig(mode=mode)
    out: dict = {}
    for seed in seeds:
        env = gym.make(
            "vc_gym/Homing-v0",
            **config.env_kwargs(),
            learning_seed=seed,
            place_cache=cache,
        )
        u = env.unwrapped
        where = HomingFeatures.position_std_slice(u.n_spots)
        far_states: list = []
        if hasattr(u.tracker, "far"):  # pose-grid: also record the pose belief's own state
            update = u.tracker.far.update

            def recorded(*args, _update=update, _states=far_states):
                _states.append(_update(*args))
                return _states[-1]

            u.tracker.far.update = recorded
        for name, kwargs in variants.items():
            expert = HomingFeatureExpert(previous_action=True, **kwargs)
            rows = out.setdefault(name, [])
            for k in range(episodes):
                obs, info = env.reset(seed=10_000 * seed + k)
                stds = []
                while True:
                    obs, r, term, trunc, info = env.step(expert.predict(obs))
                    stds.append(float(np.mean(obs[where])) * HomingFeatures.POSITION_STD_SCALE_M)
                    if term or trunc:
                        break
                far = far_states[-1] if far_states else None
                stop = info.get("stop_position", info["pose"][:2])
                rows.append(
                    {
                        "far_std_m": float(np.mean(far.position_std_m)) if far else math.nan,
                        "far_error_m": float(math.dist(far.position, stop)) if far else math.nan,
                        "seed": seed,
                        "error_m": float(info.get("stop_error_m", math.nan)),
                        "success": bool(info.get("success", False)),
                        "time_s": float(info.get("sim_time", 0.0)),
                        "timed_out": bool(trunc),
                        "std_at_stop_m": stds[-1],
                    }
                )
        env.close()
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", default="100,200")
    p.add_argument("--episodes", type=int, default=12)
    p.add_argument("--mode", default="pose-home")
    p.add_argument("--cache", default="expert_places")
    p.add_argument("--out", default="expert_diagnostic.json")
    args = p.parse_args()
    variants = {
        "fast": {"max_speed_m_s": 0.4},
        "fast, 5 cm": {"max_speed_m_s": 0.4, "home_tolerance_m": 0.05},
    }
    seeds = [int(s) for s in args.seeds.split(",")]
    out = run(seeds, args.episodes, args.mode, variants, args.cache)
    for name, rows in out.items():
        err = np.array([r["error_m"] for r in rows])
        ok = np.array([r["success"] for r in rows])
        t = np.array([r["time_s"] for r in rows])
        std = np.array([r["far_std_m"] for r in rows])
        far_err = np.array([r["far_error_m"] for r in rows])
        print(f"  far error {np.nanmean(far_err):.2f} m; corr(far std, stop error) "
              f"{np.corrcoef(std, err)[0, 1]:.2f}")
        print(
            f"{name:>12}: success {ok.mean():.0%}, mean stop {100 * np.nanmean(err):.1f} cm, "
            f"time {t.mean():.1f} s, timeouts {sum(r['timed_out'] for r in rows)}, "
            f"far std at stop: good {np.mean(std[ok]) if ok.any() else math.nan:.2f} m, "
            f"bad {np.mean(std[~ok]) if (~ok).any() else math.nan:.2f} m"
        )
    Path(args.out).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
