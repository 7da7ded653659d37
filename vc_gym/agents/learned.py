"""Learned homing agents: stable-baselines3 on the compass' outputs (paper 5.2 task).

A learned agent sees what :class:`~vc_gym.envs.CompassObservation` adds (the filters'
heading and position estimates, the spots' goodness), never the camera frame or the
true pose, through two small adapters:

* :class:`HomingFeatures` turns that ``Dict`` into one scaled feature vector (an MLP
  policy trains in minutes on a CPU);
* :class:`StopAction` gives the agent a continuous ``Box(3)`` action: walk, turn, and
  *stop*. Stopping is a commitment: the robot stands still (head scanning) until the
  task ends the episode after ``stop_time_s``. Holding a Gaussian policy's three
  motion outputs near zero for 50 steps in a row is all but impossible to learn by
  chance; one stop decision is easy. The task's own rule (still for 5 s) is unchanged.

``train`` fits PPO (default) or SAC on ``vc_gym/LearnThenHome-v0`` in parallel worker
processes (``SubprocVecEnv``) and writes ``model.zip``, ``config.json``,
``train_log.json`` and ``learning_curve.png``; :class:`LearnedHomingAgent` loads them.
"""

from __future__ import annotations

import os
import tempfile
import time
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from vc_gym.agents.scripted import LearnThenHomeConfig
from vc_gym.validation import positive_float

__all__ = [
    "ALGORITHMS",
    "PRETRAINED_MODEL",
    "HomingFeatures",
    "LearnedHomingAgent",
    "StopAction",
    "TrainConfig",
    "make_homing_env",
    "train",
]

ALGORITHMS = ("ppo", "sac")
CONFIG_SCHEMA = 1
STOP_THRESHOLD = 0.5

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

    def __post_init__(self) -> None:
        if self.algo not in ALGORITHMS:
            raise ValueError(f"algo must be one of {ALGORITHMS}, got {self.algo!r}")
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
        return {"schema": CONFIG_SCHEMA, **asdict(self), "net_arch": list(self.net_arch)}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrainConfig:
        """Inverse of :meth:`to_dict`; unknown keys or another schema are errors."""
        data = dict(data)
        schema = data.pop("schema", None)
        if schema != CONFIG_SCHEMA:
            raise ValueError(f"config schema {schema!r} is not {CONFIG_SCHEMA}")
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise ValueError(f"unknown config keys {sorted(unknown)}")
        if "net_arch" in data:
            data["net_arch"] = tuple(data["net_arch"])
        return cls(**data)


class HomingFeatures(gym.ObservationWrapper):
    """The compass outputs of :class:`~vc_gym.envs.CompassObservation` as one vector.

    ``[home_vector / 2 m (2), cos θ̂, sin θ̂, heading spread / 180°, position / 2 m (2),
    log goodness / 5 (one per spot, clipped to ±5), head pan / 90°]``: all of order 1.
    """

    def __init__(self, env: gym.Env):
        super().__init__(env)
        space = env.observation_space
        needed = {"home_vector", "heading", "heading_spread", "position", "goodness", "head"}
        if not isinstance(space, spaces.Dict) or not needed <= set(space.spaces):
            raise ValueError(f"HomingFeatures needs a CompassObservation env, got {space}")
        self.n_spots = space["goodness"].shape[0]
        n = 8 + self.n_spots
        self.observation_space = spaces.Box(-10.0, 10.0, (n,), np.float32)

    def observation(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        g = np.log(np.maximum(obs["goodness"].astype(np.float64), 1e-12)) / 5.0
        f = np.concatenate(
            [
                obs["home_vector"] / 2.0,
                obs["heading"],
                obs["heading_spread"] / 180.0,
                obs["position"] / 2.0,
                np.clip(g, -5.0, 5.0),
                obs["head"][:1] / 90.0,
            ]
        )
        return np.clip(f, -10.0, 10.0).astype(np.float32)


class StopAction(gym.Wrapper):
    """``Box(-1, 1, (3,))`` actions: walk (> 0 forward), turn, stop (> 0.5).

    Walking maps ``max(a[0], 0)`` to ``max_forward`` m/s, turning ``a[1]`` to
    ``max_turn_deg_s`` (left positive). ``a[2] > 0.5`` makes the robot stand still,
    scanning with its head, until the wrapped task ends the episode (it stops after
    ``stop_time_s``); the rewards of those steps are summed into one. Stop requests in
    the first ``min_walk_s`` of an episode are ignored (the filters are still settling,
    and an untrained policy would otherwise end most episodes within a step or two).
    """

    def __init__(
        self,
        env: gym.Env,
        max_forward: float = 0.4,
        max_turn_deg_s: float = 60.0,
        min_walk_s: float = 2.0,
    ):
        super().__init__(env)
        inner = env.action_space
        if not isinstance(inner, spaces.Box) or inner.shape[0] < 5:
            raise ValueError(f"StopAction needs the task's Box(5) actions, got {inner}")
        if not hasattr(env.unwrapped, "room"):
            raise ValueError("StopAction wraps vc_gym/LearnThenHome-v0 (its robot's speeds)")
        self.max_forward = float(max_forward)
        self.max_turn_deg_s = float(max_turn_deg_s)
        self._pans = LearnThenHomeConfig().head_scan_deg
        self._n = inner.shape[0]
        self.action_space = spaces.Box(-1.0, 1.0, (3,), np.float32)
        self._max_hold = 10**5
        self.min_walk_steps = int(round(min_walk_s / env.unwrapped.control_dt))
        self._t = 0

    def reset(self, **kwargs):
        self._t = 0
        return self.env.reset(**kwargs)

    def _inner_action(self, forward: float, turn: float, pan_deg: float = 0.0) -> np.ndarray:
        robot = self.env.unwrapped.room.robot
        a = np.zeros(self._n, np.float32)
        a[0] = np.clip(forward * self.max_forward / robot.max_forward, 0.0, 1.0)
        a[2] = np.clip(turn * self.max_turn_deg_s / robot.max_turn_deg_s, -1.0, 1.0)
        a[3] = pan_deg / 90.0
        return a

    def step(self, action):
        a = np.asarray(action, dtype=np.float64)
        if a.shape != (3,) or not np.all(np.isfinite(a)):
            raise ValueError(f"action must be 3 finite numbers, got {action!r}")
        a = np.clip(a, -1.0, 1.0)
        self._t += 1
        if a[2] <= STOP_THRESHOLD or self._t <= self.min_walk_steps:
            return self.env.step(self._inner_action(max(a[0], 0.0), a[1]))
        total = 0.0
        for i in range(self._max_hold):
            pan = self._pans[i % len(self._pans)]
            obs, r, terminated, truncated, info = self.env.step(self._inner_action(0.0, 0.0, pan))
            total += float(r)
            if terminated or truncated:
                break
        return obs, total, terminated, truncated, info


def make_homing_env(
    config: TrainConfig | None = None, relearn: str = "scene", **task_kwargs: Any
) -> gym.Env:
    """``vc_gym/LearnThenHome-v0`` as a learned agent sees it (no image, no true pose).

    Task → :class:`~vc_gym.envs.CompassObservation` (image dropped) →
    :class:`HomingFeatures` → :class:`StopAction`.
    """
    import vc_gym  # noqa: F401  (registers the envs in worker processes)
    from vc_gym.envs.compass_observation import CompassObservation

    cfg = config if config is not None else TrainConfig()
    kwargs = {
        "scene": cfg.scene,
        "relearn": relearn,
        "learn_time_s": cfg.learn_time_s,
        "stop_time_s": cfg.stop_time_s,
        "success_radius_m": cfg.success_radius_m,
        "max_homing_s": cfg.max_homing_s,
        **task_kwargs,  # overrides, e.g. a shorter learning time in tests
    }
    env = gym.make("vc_gym/LearnThenHome-v0", **kwargs)
    env = CompassObservation(env, keep_image=False)
    env = HomingFeatures(env)
    return StopAction(env, cfg.max_forward, cfg.max_turn_deg_s)


class _EnvFactory:
    """Picklable env constructor for worker processes."""

    def __init__(self, config: TrainConfig, rank: int):
        self.config, self.rank = config, rank

    def __call__(self) -> gym.Env:
        from stable_baselines3.common.monitor import Monitor

        env = Monitor(make_homing_env(self.config), info_keywords=("stop_error_m", "success"))
        env.reset(seed=self.config.seed + self.rank)
        return env


def _algorithm(name: str):
    try:
        from stable_baselines3 import PPO, SAC
    except ImportError as exc:
        raise ValueError("learned agents need stable-baselines3: pip install 'vc_gym[rl]'") from exc

    return {"ppo": PPO, "sac": SAC}[name]


def _write_atomic(path: Path, write) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.stem + ".", suffix=path.suffix)
    os.close(fd)
    try:
        write(tmp)
        os.chmod(tmp, 0o644)  # mkstemp makes it private; a model is meant to be shared
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


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

    from vc_gym.experiments.output import write_json

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

    algo = _algorithm(config.algo)
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
    _write_atomic(model_path, model.save)
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
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from vc_gym.experiments.output import save_figure

    t = np.array([e["timestep"] for e in episodes])
    ret = np.array([e["return"] for e in episodes])
    succ = np.array([e["success"] for e in episodes], float)
    err = np.array([e["stop_error_m"] for e in episodes])
    k = max(1, min(50, len(episodes) // 5))
    kernel = np.ones(k) / k

    def smooth(v):
        return np.convolve(v, kernel, mode="valid") if len(v) >= k else v

    ts = t[k - 1 :] if len(t) >= k else t
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.5), constrained_layout=True)
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


class LearnedHomingAgent:
    """A trained homing agent, loaded from ``DIR/model.zip`` and ``DIR/config.json``.

    Parameters
    ----------
    model_path : path
        The ``model.zip`` written by :func:`train`.
    """

    def __init__(self, model_path: str | os.PathLike):
        path = Path(model_path)
        if path.suffix != ".zip" or not path.is_file():
            raise ValueError(f"{path}: not a model file (expected DIR/model.zip from train)")
        cfg_path = path.with_name("config.json")
        if not cfg_path.is_file():
            raise ValueError(f"{cfg_path}: missing (train writes it next to the model)")
        import json

        try:
            self.config = TrainConfig.from_dict(json.loads(cfg_path.read_text()))
        except (ValueError, TypeError) as exc:
            raise ValueError(f"{cfg_path}: not a valid training config: {exc}") from exc
        try:
            self.model = _algorithm(self.config.algo).load(path, device="cpu")
        except Exception as exc:  # SB3 raises many kinds on a corrupt zip
            raise ValueError(f"{path}: cannot load the {self.config.algo} model: {exc}") from exc
        self.path = path

    def make_env(self, relearn: str = "scene", **task_kwargs: Any) -> gym.Env:
        """The env the agent was trained on (features and stop action)."""
        return make_homing_env(self.config, relearn=relearn, **task_kwargs)

    def predict(self, obs: np.ndarray) -> np.ndarray:
        """Deterministic action for one feature vector."""
        action, _ = self.model.predict(obs, deterministic=True)
        return action
