"""Speed of training: agent decisions per second against the env's own step rate.

``env_decisions_per_s`` is one ``vc_gym/Homing-v0`` (the env a learned agent trains on:
the task, the compass and tracker, the feature and stop wrappers) stepping with random
actions in this process, resets included, after its learning phase. ``train`` runs
:func:`~vc_gym.experiments.training.train` (PPO, ``n_envs`` worker processes, the place
learned once and shared) and reports its decisions per second while the policy trains.
The env is measured before and after training (median of the rounds), in the same run.
``efficiency`` = training decisions/s ÷ (``n_envs`` × env decisions/s): 1 would mean the
workers never wait for each other or for the policy.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.experiments.training import TrainConfig, learn_places, train, training_env
from vc_gym.validation import int_at_least

__all__ = ["bench_train"]


def _env_rate(config: TrainConfig, run_dir: Path, steps: int, seed: int) -> float:
    env = training_env(config, run_dir)
    rng = np.random.default_rng(seed)
    try:
        env.reset(seed=seed)
        actions = rng.normal(0.0, 0.6, (steps, 3)).clip(-1, 1).astype(np.float32)
        t0 = time.perf_counter()
        for a in actions:  # like an untrained Gaussian policy (log_std_init -0.5)
            _, _, terminated, truncated, _ = env.step(a)
            if terminated or truncated:
                env.reset()
        return steps / (time.perf_counter() - t0)
    finally:
        env.close()


def bench_train(
    timesteps: int = 2048,
    n_envs: int = 2,
    env_steps: int = 600,
    learn_time_s: float = 0.5,
    seed: int = 0,
    progress: bool = True,
) -> dict[str, Any]:
    """Measure training decisions/s next to ``n_envs`` × one env's decisions/s.

    Parameters
    ----------
    timesteps : int
        Decisions to train for (PPO, the default hyperparameters otherwise).
    n_envs : int
        Worker processes of the training run.
    env_steps : int
        Decisions of each single-env round (one round before training, one after).
    learn_time_s : float
        Learning time per direction of the (untimed) learning phase.
    seed : int
        Seed of the learning phase, the env rounds and the training run.

    Returns
    -------
    dict
        ``env_decisions_per_s``, ``train_decisions_per_s``, ``n_envs``, ``efficiency``
        and the settings.
    """
    int_at_least("env_steps", env_steps, 1)
    config = TrainConfig(  # no warm start: only the training's own speed is measured
        timesteps=timesteps, n_envs=n_envs, seed=seed, learn_time_s=learn_time_s, demo_episodes=0
    )
    with tempfile.TemporaryDirectory(prefix="vc_gym_bench_train_") as tmp:
        # the place is learned once into the run folder, where train() finds it
        learn_places(config, tmp)
        before = _env_rate(config, Path(tmp), env_steps, seed)
        run = train(config, tmp, progress=progress)
        after = _env_rate(config, Path(tmp), env_steps, seed + 1)
    env_rate = float(np.median([before, after]))
    train_rate = float(run["decisions_per_s"])
    return {
        "timesteps": timesteps,
        "n_envs": n_envs,
        "env_decisions_per_s": round(env_rate, 2),
        "env_rounds_decisions_per_s": [round(before, 2), round(after, 2)],
        "train_decisions_per_s": round(train_rate, 2),
        "efficiency": round(train_rate / (n_envs * env_rate), 3),
        "target_efficiency": 0.7,
    }
