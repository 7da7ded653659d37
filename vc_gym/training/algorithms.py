"""The stable-baselines3 algorithms a homing agent is trained with, by name."""

from __future__ import annotations

__all__ = ["ALGORITHMS", "algorithm_class"]

ALGORITHMS = ("ppo", "sac")


def algorithm_class(name: str):
    """The stable-baselines3 class of ``"ppo"`` or ``"sac"``.

    Raises
    ------
    ValueError
        For another name, or when stable-baselines3 is not installed.
    """
    if name not in ALGORITHMS:
        raise ValueError(f"algo must be one of {ALGORITHMS}, got {name!r}")
    try:
        from stable_baselines3 import PPO, SAC
    except ImportError as exc:
        raise ValueError("learned agents need stable-baselines3: pip install 'vc_gym[rl]'") from exc

    return {"ppo": PPO, "sac": SAC}[name]
