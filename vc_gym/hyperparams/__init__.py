"""Hyperparameters for RL Baselines3 Zoo, one module per algorithm.

``python -m rl_zoo3.train --algo ppo --env vc_gym/Homing-v0 --gym-packages vc_gym -conf
vc_gym.hyperparams.ppo`` reads ``hyperparams`` from :mod:`vc_gym.hyperparams.ppo`, which
is ``ppo.yml`` beside it (read as plain data; copy the file and pass its path to ``-conf``
to change it).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vc_gym.config_files import read_settings

__all__ = ["zoo_hyperparams"]


def zoo_hyperparams(algo: str) -> dict[str, Any]:
    """The Zoo hyperparameters of ``algo`` (``"ppo"`` or ``"sac"``) by env id."""
    path = Path(__file__).with_name(f"{algo}.yml")
    if not path.is_file():
        raise ValueError(f"no Zoo hyperparameters for {algo!r}; there are ppo and sac")
    return read_settings(path)
