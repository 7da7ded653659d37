"""Train PPO on ``vc_gym/Homing-v0`` with plain stable-baselines3, then evaluate it.

    python examples/train_ppo.py --timesteps 20000 --out ppo_homing.zip

The env learns the place on its first reset (cached: later runs and the other envs of a
vector env load it) and kidnaps the robot on every reset. ``vc-gym train`` adds a warm
start from the scripted agent, held-out evaluations, checkpoints and sweeps; ``vc-gym
evaluate --agent ppo_homing.zip`` evaluates the saved model like any other agent.
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env

import vc_gym  # noqa: F401  (registers the envs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timesteps", type=int, default=20_000, help="agent decisions")
    parser.add_argument("--n-envs", type=int, default=2, help="parallel envs")
    parser.add_argument("--episodes", type=int, default=5, help="evaluation kidnappings")
    parser.add_argument("--learn-time", type=float, default=5.0, help="s per direction")
    parser.add_argument("--max-homing", type=float, default=60.0, help="s of homing")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="ppo_homing.zip", help="the saved model")
    args = parser.parse_args()

    # one place (learning seed) for every env: learned once, then loaded from the cache
    env_kwargs = {
        "learn_time_s": args.learn_time,
        "max_homing_s": args.max_homing,
        "learning_seed": args.seed,
    }
    envs = make_vec_env("vc_gym/Homing-v0", n_envs=args.n_envs, seed=args.seed,
                        env_kwargs=env_kwargs)
    model = PPO("MlpPolicy", envs, n_steps=64, batch_size=64, seed=args.seed)
    model.learn(total_timesteps=args.timesteps, progress_bar=True)
    model.save(args.out)
    envs.close()

    env = gym.make("vc_gym/Homing-v0", **env_kwargs)
    stops, successes = [], []
    for episode in range(args.episodes):
        obs, info = env.reset(seed=10_000 + episode)  # kidnappings training never saw
        done = False
        while not done:
            action, _ = model.predict(obs, deterministic=True)
            obs, reward, terminated, truncated, info = env.step(action)
            done = terminated or truncated
        stops.append(info["stop_error_m"])
        successes.append(info["success"])
    env.close()
    print(f"{args.episodes} kidnappings: {np.mean(successes):.0%} within 30 cm, "
          f"mean stop {np.mean(stops) * 100:.1f} cm from home; model saved to {args.out}")


if __name__ == "__main__":
    main()
