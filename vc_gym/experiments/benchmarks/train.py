"""Speed of training: agent decisions per second against the env's own step rate.

``env_decisions_per_s`` is one ``vc_gym/Homing-v0`` (the env a learned agent trains on:
the task, the compass and tracker, the feature and stop wrappers) stepping with random
actions in this process, resets included, after its learning phase. ``train`` runs
:func:`~vc_gym.training.train.train` (PPO, ``n_envs`` worker processes, the place
learned once and shared) and reports its decisions per second while the policy trains.
Training runs once with each collector (``TrainConfig.collector``): SB3's lockstep, where
every step waits for the slowest worker, and the asynchronous one
(:mod:`vc_gym.training.async_rollouts`), where each worker runs its rollout on its own.

The env is timed in a round before the first training and after each one, every round
with the same actions, so rounds differ only by what the machine is doing; each
collector is compared with the mean of the two rounds either side of it (a machine that
slows down or speeds up during the run moves both). ``efficiency`` = training
decisions/s ÷ (``n_envs`` × env decisions/s): 1 would mean the workers never wait for
each other or for the policy.

A decision is not a fixed amount of work: a stop that stands holds its decision for up
to the whole stand (50 steps of the task env), and the policy stops more or less often
as it learns. So the same is measured in steps of the task env
(``StopAction``'s ``info["task_steps"]``): ``task_step_efficiency`` = training task
steps/s ÷ (``n_envs`` × the env's task steps/s), with ``*_task_steps_per_decision``
showing how much work a decision was in each. ``decisions_over_task_steps`` divides
training decisions/s by ``n_envs`` × the env's task steps/s, the strictest reading: a
decision that stands for many task steps still counts as one.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.jobs.workers import check_workers
from vc_gym.training.config import COLLECTORS, TrainConfig
from vc_gym.training.environments import learn_places, training_env
from vc_gym.training.train import train
from vc_gym.validation import check_seed, int_in_range

__all__ = ["MAX_ENV_STEPS", "MAX_TIMESTEPS", "bench_train"]

#: Most decisions per training run of the benchmark (the default is 2,048).
MAX_TIMESTEPS = 1_000_000
#: Most decisions per single-env round.
MAX_ENV_STEPS = 100_000


def _env_rate(config: TrainConfig, run_dir: Path, steps: int, seed: int) -> tuple[float, float]:
    """Decisions and task-env steps per second of one env with random actions (the same
    actions for the same ``seed``)."""
    env = training_env(config, run_dir)
    rng = np.random.default_rng(seed)
    task_steps = 0
    try:
        env.reset(seed=seed)
        actions = rng.normal(0.0, 0.6, (steps, 3)).clip(-1, 1).astype(np.float32)
        t0 = time.perf_counter()
        for a in actions:  # like an untrained Gaussian policy (log_std_init -0.5)
            _, _, terminated, truncated, info = env.step(a)
            task_steps += int(info["task_steps"])
            if terminated or truncated:
                env.reset()
        seconds = time.perf_counter() - t0
        return steps / seconds, task_steps / seconds
    finally:
        env.close()


def bench_train(
    timesteps: int = 2048,
    n_envs: int = 2,
    env_steps: int = 600,
    learn_time_s: float = 0.5,
    seed: int = 0,
    progress: bool = True,
    collectors: tuple[str, ...] = COLLECTORS,
) -> dict[str, Any]:
    """Measure training decisions/s next to ``n_envs`` × one env's decisions/s.

    Parameters
    ----------
    timesteps : int
        Decisions to train for with each collector (PPO, the default hyperparameters
        otherwise; 1 to :data:`MAX_TIMESTEPS`).
    n_envs : int
        Worker processes of the training runs (1 to
        :func:`~vc_gym.jobs.workers.max_workers`).
    env_steps : int
        Decisions of each single-env round (one before the first training and one after
        each; every round takes the same actions; 1 to :data:`MAX_ENV_STEPS`).
    learn_time_s : float
        Learning time per direction of the (untimed) learning phase.
    seed : int
        Seed of the learning phase, the env rounds' actions and the training runs.
    collectors : tuple of str
        ``TrainConfig.collector`` values to train with, one after the other in this run
        (default: SB3's lockstep and the asynchronous one).

    Returns
    -------
    dict
        One env alone: ``env_rounds_decisions_per_s`` and ``env_rounds_task_steps_per_s``
        (every round, in order), their medians ``env_decisions_per_s`` and
        ``env_task_steps_per_s``, and ``env_task_steps_per_decision``. Per collector
        (``collectors``): the env's rates around its training (the mean of the rounds
        either side), ``train_decisions_per_s``, ``efficiency``, the same in task-env
        steps (``train_task_steps_per_s``, ``task_step_efficiency``,
        ``train_task_steps_per_decision``) and ``decisions_over_task_steps``. With both
        collectors ``async_over_lockstep``, the ratio of their decision rates; and the
        settings.
    """
    int_in_range("timesteps", timesteps, 1, MAX_TIMESTEPS)
    check_workers(n_envs, "n_envs")
    int_in_range("env_steps", env_steps, 1, MAX_ENV_STEPS)
    check_seed("seed", seed)
    collectors = tuple(collectors)
    if not collectors or any(c not in COLLECTORS for c in collectors):
        raise ValueError(f"collectors must be a non-empty subset of {COLLECTORS}, got {collectors}")
    config = TrainConfig(  # no warm start: only the training's own speed is measured
        timesteps=timesteps,
        n_envs=n_envs,
        seed=seed,
        learn_time_s=learn_time_s,
        demo_episodes=0,
        home_offset_episodes=0,
        home_offset_centre=False,
    )
    runs, rounds = {}, []
    with tempfile.TemporaryDirectory(prefix="vc_gym_bench_train_") as tmp:
        # the place is learned once into the run folder, where train() finds it
        learn_places(config, tmp)
        rounds.append(_env_rate(config, Path(tmp), env_steps, seed))
        for name in collectors:
            # each collector's run in a folder of its own (a run refuses another's
            # folder), with the place learned above copied in
            run_dir = Path(tmp) / name
            run_dir.mkdir()
            for atlas in config.atlas_files(tmp):
                shutil.copy2(atlas, run_dir / atlas.name)
            runs[name] = train(replace(config, collector=name), run_dir, progress=progress)
            rounds.append(_env_rate(config, Path(tmp), env_steps, seed))
    per_collector = {}
    for k, (name, run) in enumerate(runs.items()):
        # the env as fast as it was around this training: the rounds either side of it
        env_rate = float(np.mean([rounds[k][0], rounds[k + 1][0]]))
        env_task_rate = float(np.mean([rounds[k][1], rounds[k + 1][1]]))
        rate, task_rate = float(run["decisions_per_s"]), float(run["task_steps_per_s"])
        per_collector[name] = {
            "env_decisions_per_s": round(env_rate, 2),
            "train_decisions_per_s": round(rate, 2),
            "efficiency": round(rate / (n_envs * env_rate), 3),
            "env_task_steps_per_s": round(env_task_rate, 2),
            "train_task_steps_per_s": round(task_rate, 2),
            "task_step_efficiency": round(task_rate / (n_envs * env_task_rate), 3),
            "train_task_steps_per_decision": round(task_rate / rate, 3),
            "decisions_over_task_steps": round(rate / (n_envs * env_task_rate), 3),
        }
    decision_rates = [r[0] for r in rounds]
    task_rates = [r[1] for r in rounds]
    result: dict[str, Any] = {
        "timesteps": timesteps,
        "n_envs": n_envs,
        "env_decisions_per_s": round(float(np.median(decision_rates)), 2),
        "env_rounds_decisions_per_s": [round(r, 2) for r in decision_rates],
        "env_task_steps_per_s": round(float(np.median(task_rates)), 2),
        "env_rounds_task_steps_per_s": [round(r, 2) for r in task_rates],
        "env_task_steps_per_decision": round(float(np.sum(task_rates) / np.sum(decision_rates)), 3),
        "target_efficiency": 0.7,
        "collectors": per_collector,
    }
    if {"lockstep", "async"} <= set(per_collector):
        result["async_over_lockstep"] = round(
            per_collector["async"]["train_decisions_per_s"]
            / per_collector["lockstep"]["train_decisions_per_s"],
            3,
        )
    return result
