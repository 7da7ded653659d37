"""The smallest training runs the tests train: a few seconds each, writing every file.

64 decisions with a checkpoint and a held-out evaluation every 32, on a place learned in
0.2 s; no warm start and no goal measurement, so nothing runs before PPO. Stops are
checked over 3 steps (``stop_time_s=0.3``; the default 5 s would make 50).
"""

from __future__ import annotations

from typing import Any

from vc_gym.training.config import TrainConfig

#: The fields every tiny run shares.
TINY_FIELDS: dict[str, Any] = {
    "timesteps": 64,
    "learn_time_s": 0.2,
    "n_steps": 32,
    "batch_size": 32,
    "max_homing_s": 3.0,
    "stop_time_s": 0.3,
    "eval_freq": 32,
    "save_freq": 32,
    "demo_episodes": 0,
    "home_offset_episodes": 0,  # the goal is the tracker's home: no measurement to wait for
    "home_offset_centre": False,
    # four spots learned, not 25 turns: the default mode's learning triples a tiny run
    "mode": "paper",
}


def tiny_config(**changes: Any) -> TrainConfig:
    """A tiny run's :class:`TrainConfig`: :data:`TINY_FIELDS` with ``changes`` on top."""
    return TrainConfig(**{**TINY_FIELDS, **changes})


#: Two worker processes (the async collector), two evaluation episodes.
TINY = tiny_config(n_envs=2, eval_episodes=2)
#: One env in this process: the quickest run that still writes checkpoints (32, 64),
#: evaluations and a best model; the tracker given as a {"type": ...} dict.
TINY_LOCAL = tiny_config(
    n_envs=1, vec_env="dummy", collector="lockstep", eval_episodes=1, tracker={"type": "grid"}
)
