"""Training learned homing agents with stable-baselines3 (``vc-gym train``).

:func:`train` fits PPO (default) or SAC on ``vc_gym/Homing-v0`` (the task env seen
through the compass and a tracker, :mod:`vc_gym.envs.homing`) in parallel worker
processes (``SubprocVecEnv``) and writes ``model.zip``, ``config.json``,
``train_log.json`` and ``learning_curve.png``;
:class:`~vc_gym.agents.learned.LearnedHomingAgent` loads them.
"""

from __future__ import annotations

import os
import time
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from vc_gym.agents.learned import ALGORITHMS, algorithm_class
from vc_gym.experiments.output import new_figure, save_figure, write_json
from vc_gym.persistence import write_atomic
from vc_gym.validation import positive_float

__all__ = ["TrainConfig", "train"]

CONFIG_SCHEMA = 2

#: The PPO policy shipped with the package (trained by ``vc-gym train``, see README);
#: ``vc-gym evaluate --agent pretrained`` evaluates it.
PRETRAINED_MODEL = Path(__file__).parent / "pretrained" / "ppo_robolab" / "model.zip"


@dataclass(frozen=True)
class TrainConfig:
    """Everything that defines a training run (saved next to the model as JSON).

    Parameters
    ----------
    algo : str
        ``"ppo"`` (default) or ``"sac"``.
    timesteps : int
        Agent decisions to train for (a stop decision counts once).
    n_envs : int
        Parallel environments (one worker process each with ``vec_env="subproc"``).
    seed : int
        Seed of the model and of the environments (env ``i`` gets ``seed + i``).
    scene : str
        Scene of ``vc_gym/LearnThenHome-v0``.
    learn_time_s, success_radius_m, max_homing_s : float
        Task parameters (see ``LearnThenHomeEnv``).
    stop_time_s : float
        How long the robot must stand still to end an episode *in training* (one step).
        The robot does not move while it stands, so the outcome (where it stopped) and
        the rewards are those of the paper's 5 s; training just wastes fewer
        simulated seconds. Evaluation uses the task's 5 s.
    vec_env : str
        ``"subproc"`` (``SubprocVecEnv``, forkserver) or ``"dummy"`` (in-process).
    net_arch : tuple of int
        Hidden layers of the policy and value MLPs.
    learning_rate, gamma : float
        Optimiser step and discount.
    n_steps : int
        PPO rollout length per env (SAC: ignored).
    batch_size : int
        Minibatch size.
    log_std_init : float
        Initial log standard deviation of the Gaussian policy (-0.5: σ ≈ 0.6).
    max_forward : float
        Walking speed (m/s) of a full forward action.
    max_turn_deg_s : float
        Turn rate (deg/s) of a full turn action.
    tracker : str
        Tracker of the agent's env (``"grid"``, ``"particle"``, ``"kalman"``).
    """

    algo: str = "ppo"
    timesteps: int = 60_000
    n_envs: int = 2
    seed: int = 0
    scene: str = "robolab"
    learn_time_s: float = 5.0
    stop_time_s: float = 0.1
    success_radius_m: float = 0.3
    max_homing_s: float = 60.0
    vec_env: str = "subproc"
    net_arch: tuple[int, ...] = (64, 64)
    learning_rate: float = 3e-4
    gamma: float = 0.99
    n_steps: int = 256
    batch_size: int = 64
    log_std_init: float = -0.5
    max_forward: float = 0.4
    max_turn_deg_s: float = 60.0
    tracker: str = "grid"

    def __post_init__(self) -> None:
        if self.algo not in ALGORITHMS:
            raise ValueError(f"algo must be one of {ALGORITHMS}, got {self.algo!r}")
        if not isinstance(self.tracker, str):
            raise ValueError(f"tracker must be a tracker name, got {self.tracker!r}")
        if self.vec_env not in ("subproc", "dummy"):
            raise ValueError(f"vec_env must be 'subproc' or 'dummy', got {self.vec_env!r}")
        for name in ("timesteps", "n_envs", "n_steps", "batch_size"):
            v = getattr(self, name)
            if not (isinstance(v, int) and not isinstance(v, bool) and v >= 1):
                raise ValueError(f"{name} must be an int >= 1, got {v!r}")
        for name in (
            "learn_time_s",
            "stop_time_s",
            "success_radius_m",
            "max_homing_s",
            "learning_rate",
            "max_forward",
            "max_turn_deg_s",
        ):
            v = getattr(self, name)
            positive_float(name, v)
        if not (0 < self.gamma <= 1):
            raise ValueError(f"gamma must be in (0, 1], got {self.gamma!r}")
        if not self.net_arch or any(int(n) < 1 for n in self.net_arch):
            raise ValueError(f"net_arch must be positive layer sizes, got {self.net_arch!r}")
        object.__setattr__(self, "net_arch", tuple(int(n) for n in self.net_arch))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (with the schema version)."""
        return {
            "schema": CONFIG_SCHEMA,
            **asdict(self),
            "net_arch": list(self.net_arch),
            "env": self.env_kwargs(),
        }

    def env_kwargs(self) -> dict[str, Any]:
        """The ``vc_gym/Homing-v0`` arguments of this run (the agent's env)."""
        return {
            "scene": self.scene,
            "learn_time_s": self.learn_time_s,
            "stop_time_s": self.stop_time_s,
            "success_radius_m": self.success_radius_m,
            "max_homing_s": self.max_homing_s,
            "max_forward": self.max_forward,
            "max_turn_deg_s": self.max_turn_deg_s,
            "tracker": self.tracker,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrainConfig:
        """Inverse of :meth:`to_dict`; unknown keys or another schema are errors."""
        data = dict(data)
        schema = data.pop("schema", None)
        if schema not in (1, CONFIG_SCHEMA):  # schema 1 had no "env" (derived from the rest)
            raise ValueError(f"config schema {schema!r} is not {CONFIG_SCHEMA}")
        env = data.pop("env", None)
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise ValueError(f"unknown config keys {sorted(unknown)}")
        if "net_arch" in data:
            data["net_arch"] = tuple(data["net_arch"])
        config = cls(**data)
        if env is not None and env != config.env_kwargs():
            raise ValueError("the config's 'env' does not match its own fields")
        return config


class _EnvFactory:
    """Picklable env constructor for worker processes."""

    def __init__(self, config: TrainConfig, rank: int):
        self.config, self.rank = config, rank

    def __call__(self) -> gym.Env:
        from stable_baselines3.common.monitor import Monitor

        env = gym.make("vc_gym/Homing-v0", **self.config.env_kwargs())
        env = Monitor(env, info_keywords=("stop_error_m", "success"))
        env.reset(seed=self.config.seed + self.rank)
        return env


def train(config: TrainConfig, out_dir: str | os.PathLike, progress: bool = True) -> dict[str, Any]:
    """Train a homing agent and write ``model.zip``, ``config.json``, ``train_log.json``
    and ``learning_curve.png`` to ``out_dir``.

    Returns
    -------
    dict
        Paths, duration, episodes seen, and the success rate and mean stop error of the
        last 50 training episodes.
    """
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv
    from tqdm import tqdm

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    factories = [_EnvFactory(config, i) for i in range(config.n_envs)]
    if config.vec_env == "subproc":
        venv = SubprocVecEnv(factories, start_method="forkserver")
    else:
        venv = DummyVecEnv(factories)
    episodes: list[dict[str, Any]] = []

    class _Progress(BaseCallback):
        def _on_training_start(self) -> None:
            self.bar = tqdm(
                total=config.timesteps, desc=f"train {config.algo}", disable=not progress
            )

        def _on_step(self) -> bool:
            self.bar.update(self.training_env.num_envs)
            for info in self.locals["infos"]:
                ep = info.get("episode")
                if ep is not None:
                    episodes.append(
                        {
                            "timestep": int(self.num_timesteps),
                            "return": float(ep["r"]),
                            "decisions": int(ep["l"]),
                            "stop_error_m": float(info.get("stop_error_m", float("nan"))),
                            "success": bool(info.get("success", False)),
                        }
                    )
                    if len(episodes) % 100 == 0:  # a log to watch while it runs
                        write_json(
                            out / "train_log.json", {"running": True, "per_episode": episodes}
                        )
                    recent = episodes[-50:]
                    self.bar.set_postfix(
                        success=f"{np.mean([e['success'] for e in recent]):.0%}",
                        err=f"{np.nanmean([e['stop_error_m'] for e in recent]):.2f}m",
                    )
            return True

        def _on_training_end(self) -> None:
            self.bar.close()

    algo = algorithm_class(config.algo)
    kwargs: dict[str, Any] = {
        "learning_rate": config.learning_rate,
        "gamma": config.gamma,
        "batch_size": config.batch_size,
        "policy_kwargs": {"net_arch": list(config.net_arch), "log_std_init": config.log_std_init},
        "seed": config.seed,
        "verbose": 0,
        "device": "cpu",
    }
    if config.algo == "ppo":
        kwargs["n_steps"] = config.n_steps
    try:
        model = algo("MlpPolicy", venv, **kwargs)
        model.learn(total_timesteps=config.timesteps, callback=_Progress())
    finally:
        venv.close()
    model_path = out / "model.zip"
    write_atomic(model_path, model.save)
    write_json(out / "config.json", config.to_dict())
    recent = episodes[-50:]
    summary = {
        "model": str(model_path),
        "config": config.to_dict(),
        "duration_s": round(time.perf_counter() - t0, 1),
        "episodes": len(episodes),
        "recent_success_rate": float(np.mean([e["success"] for e in recent])) if recent else None,
        "recent_mean_stop_error_m": float(np.nanmean([e["stop_error_m"] for e in recent]))
        if recent
        else None,
    }
    write_json(out / "train_log.json", {**summary, "per_episode": episodes})
    if episodes:
        _plot_curve(out / "learning_curve.png", episodes, config)
    return summary


def _plot_curve(path: Path, episodes: list[dict[str, Any]], config: TrainConfig) -> None:
    t = np.array([e["timestep"] for e in episodes])
    ret = np.array([e["return"] for e in episodes])
    succ = np.array([e["success"] for e in episodes], float)
    err = np.array([e["stop_error_m"] for e in episodes])
    k = max(1, min(50, len(episodes) // 5))
    kernel = np.ones(k) / k

    def smooth(v):
        return np.convolve(v, kernel, mode="valid") if len(v) >= k else v

    ts = t[k - 1 :] if len(t) >= k else t
    fig = new_figure(figsize=(12, 3.5), layout="constrained")
    axes = fig.subplots(1, 3)
    axes[0].plot(t, ret, ".", ms=2, color="0.7")
    axes[0].plot(ts, smooth(ret), color="tab:blue")
    axes[0].set_ylabel("episode return")
    axes[1].plot(ts, smooth(succ), color="tab:green")
    axes[1].set_ylabel(f"success rate (≤ {config.success_radius_m} m, mean of {k})")
    axes[1].set_ylim(0, 1)
    axes[2].plot(t, err * 100, ".", ms=2, color="0.7")
    axes[2].plot(ts, smooth(np.nan_to_num(err, nan=np.nanmax(err))) * 100, color="tab:red")
    axes[2].set_ylabel("stop distance from home (cm)")
    for ax in axes:
        ax.set_xlabel("agent decisions")
    fig.suptitle(f"{config.algo.upper()} on vc_gym/LearnThenHome-v0 ({config.scene})")
    save_figure(fig, path, dpi=100)
