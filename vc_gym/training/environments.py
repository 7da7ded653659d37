"""The envs a training run trains on: one ``vc_gym/Homing-v0`` per place.

Every place of a run (:attr:`~vc_gym.training.config.TrainConfig.place_seeds`) is a
``vc_gym/Homing-v0`` whose learning phase runs once, into the place's atlas file in the
run folder, and is loaded by every other env of that place (:func:`learn_places` runs it
in the parent before any worker starts). :func:`training_env` is the env a policy trains
on; :class:`EnvFactory` builds it, seeded and logged, in a worker process.
"""

from __future__ import annotations

import os
from pathlib import Path

import gymnasium as gym

from vc_gym.envs.learn_then_home import make_task
from vc_gym.envs.place_pool import PlacePool
from vc_gym.training.config import TrainConfig

__all__ = ["EnvFactory", "learn_places", "place_env", "run_places", "training_env"]


def place_env(config: TrainConfig, seed: int, atlas_file: Path) -> gym.Env:
    """``vc_gym/Homing-v0`` of one place: learning seed ``seed``, its atlas learned once
    into ``atlas_file`` by the first env that needs it and loaded by every other."""
    # the task ends its episodes itself (max_homing_s may exceed the registered 60 s)
    return make_task(
        "vc_gym/Homing-v0", **config.env_kwargs(), atlas_file=str(atlas_file), learning_seed=seed
    )


def run_places(config: TrainConfig, out_dir: str | os.PathLike) -> list[tuple[int, Path]]:
    """``(learning seed, atlas file)`` of every place of the run in ``out_dir``."""
    return list(zip(config.place_seeds, config.atlas_files(out_dir), strict=True))


def training_env(config: TrainConfig, out_dir: str | os.PathLike) -> gym.Env:
    """``vc_gym/Homing-v0`` as ``config`` trains on it in the run folder ``out_dir``: one
    env per place (:attr:`TrainConfig.place_seeds`, atlases in
    :meth:`TrainConfig.atlas_files`); several places make a
    :class:`~vc_gym.envs.PlacePool`."""
    envs = [place_env(config, seed, f) for seed, f in run_places(config, out_dir)]
    return envs[0] if len(envs) == 1 else PlacePool(envs)


def learn_places(config: TrainConfig, out_dir: str | os.PathLike) -> int:
    """Run the learning phase of each of ``config``'s places once, into its atlas file in
    the run folder ``out_dir`` (kept if it is there already and was learned the same
    way; a place in the place cache is copied from there). Returns how many atlas files
    were written now."""
    learned = 0
    for seed, f in run_places(config, out_dir):
        env = place_env(config, seed, f)
        try:
            env.reset(seed=seed)
            learned += bool(env.unwrapped.learner.learned)
        finally:
            env.close()
    return learned


class EnvFactory:
    """Picklable constructor of worker ``rank``'s :func:`training_env`, wrapped in SB3's
    ``Monitor`` (episode log ``monitor``, appended to with ``append``) and reset with
    seed ``config.seed + rank``."""

    def __init__(
        self,
        config: TrainConfig,
        rank: int,
        out_dir: Path,
        monitor: str | os.PathLike | None = None,
        append: bool = False,
    ):
        self.config, self.rank, self.out_dir = config, rank, out_dir
        self.monitor, self.append = monitor, append

    def __call__(self) -> gym.Env:
        from stable_baselines3.common.monitor import Monitor

        env = Monitor(
            training_env(self.config, self.out_dir),
            filename=None if self.monitor is None else str(self.monitor),
            info_keywords=("stop_error_m", "success"),
            override_existing=not self.append,
        )
        env.reset(seed=self.config.seed + self.rank)
        return env
