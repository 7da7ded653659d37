"""Training learned homing agents with stable-baselines3 (``vc-gym train``).

:func:`train` fits PPO (default) or SAC on ``vc_gym/Homing-v0`` (the task env seen
through the compass and a tracker, :mod:`vc_gym.envs.homing`) in parallel worker
processes (``SubprocVecEnv``) and writes ``model.zip``, ``config.json``,
``train_log.json`` and ``learning_curve.png``;
:class:`~vc_gym.agents.learned.LearnedHomingAgent` loads them.
"""

from __future__ import annotations

import json
import os
import time
import warnings
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from vc_gym.agents.feature_expert import HomingFeatureExpert
from vc_gym.agents.learned import ALGORITHMS, algorithm_class
from vc_gym.agents.safe_load import load_sb3_model
from vc_gym.config_files import read_settings
from vc_gym.envs.homing import home_offset
from vc_gym.envs.place_pool import PlacePool
from vc_gym.envs.scenes import check_scene_name
from vc_gym.experiments.episode import LEARNED_CONFIRM_STOP_M
from vc_gym.experiments.home_offset import MIN_STOPS, centre_home_offset, measure_home_offset
from vc_gym.experiments.imitation import clone_behaviour, collect_demonstrations
from vc_gym.experiments.output import check_out_dir, new_figure, save_figure, write_json
from vc_gym.localization import make_tracker
from vc_gym.persistence import write_atomic
from vc_gym.validation import flag, int_at_least, nonnegative_float, positive_float

__all__ = ["TrainConfig", "check_names", "read_train_config", "train"]

CONFIG_SCHEMA = 2
#: Warm-start episodes of each algorithm by default (``TrainConfig.demo_episodes``).
DEFAULT_DEMO_EPISODES = {"ppo": 60, "sac": 0}
#: Expert episodes that measure the goal correction by default
#: (``TrainConfig.home_offset_episodes``; centred, ``home_offset_centre``). With the
#: previous action as an input, policies trained towards the centred goal beat the
#: scripted agent on learning seeds 30-32, the rule written before they were trained
#: (README, *Learned agents*).
DEFAULT_HOME_OFFSET_EPISODES = 10
#: Learning and kidnapping seeds of the offset measurement start here: apart from the
#: training envs' (seed + i), the held-out evaluations' (``eval_seed``) and the learning
#: seeds anyone evaluates on.
HOME_OFFSET_SEED = 2_000_000
#: Accepted values of ``TrainConfig.collector``.
COLLECTORS = ("lockstep", "async")
#: At most this many places per training run (each is a PyBullet world in every worker).
MAX_PLACES = 16


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
        Seed of the model and of the environments (env ``i`` gets ``seed + i``) and,
        without ``places``, of the learning phase, which runs once per training run
        (``DIR/atlas.npz``, shared by every worker; see ``atlas_file`` of
        ``vc_gym/LearnThenHome-v0``).
    places : tuple of int
        Train over a pool of places: the learning seeds of the places, each learned once
        (``DIR/atlas-place<s>.npz``); every episode happens in one of them, drawn at
        reset (:class:`~vc_gym.envs.PlacePool`). Empty (default): the one place of
        ``seed``.
    scene : str
        Scene of ``vc_gym/LearnThenHome-v0``.
    learn_time_s, success_radius_m, max_homing_s : float
        Task parameters (see ``LearnThenHomeEnv``).
    stop_time_s : float
        How long the robot must stand still to end an episode in training (default:
        the task's 5 s, as in every evaluation).
    confirm_stop_m : float, optional
        Check every stop while the robot stands (``confirm_stop_m`` of
        ``vc_gym/Homing-v0``): a stop whose estimated home moves farther than this
        within ``stop_time_s`` is called off and the policy decides again. Default
        0.25 m, what every evaluation of a learned agent does
        (``vc_gym.experiments.episode.LEARNED_CONFIRM_STOP_M``), so the policy learns
        with the check it is evaluated with (README: 87 ± 5 % and 25.0 ± 4.6 cm on 99
        held-out kidnappings, against 86 ± 6 % and 27.1 ± 4.4 cm trained with final
        stops of 0.1 s). ``None``: a stop is final.
    closeness_bonus : float
        Reward of a successful stop for its closeness to home (``closeness_bonus`` of
        ``vc_gym/LearnThenHome-v0``: ``closeness_bonus × (1 − d / success_radius_m)`` on
        top of the success bonus). Default 0: the task's rewards, under which a stop
        25 cm from home earns as much as one at home, less the 10 per metre of the
        progress reward. A ``config.json`` saved before the field existed was trained
        with 0.
    min_walk_m : float
        Stop requests are ignored until the robot has walked this far by its own
        forward commands (``min_walk_m`` of ``vc_gym/Homing-v0``). Default 0. A
        ``config.json`` saved before the field existed was trained with 0.
    previous_action : bool
        The policy also sees its last action (``previous_action`` of
        ``vc_gym/Homing-v0``, :class:`~vc_gym.envs.PreviousAction`), and the expert it is
        warm-started from keeps a turn going while home is behind, so that the clone can
        learn to turn through rather than stall with home behind it (README, *Learned
        agents*). Default True; a ``config.json`` saved before the field existed was
        trained without it.
    home_offset_episodes : int
        Before the warm start, the scripted expert homes this many times in each of the
        training place(s) and ``home_offset_places`` more, and the median ``estimate −
        true position`` at its stops becomes the goal of the agent's env
        (``home_offset_m`` of ``vc_gym/Homing-v0``; :mod:`vc_gym.experiments.home_offset`;
        ``DIR/home_offset.json``): the policy learns to stop where that error says the
        true home is, not where the tracker believes home is (README, *Learned
        agents*). Default 10; 0: the atlas' home (then ``home_offset_centre=False``).
    home_offset_places : int
        Places learned only for that measurement (learning seeds
        ``HOME_OFFSET_SEED + 16 × seed + k``, ``DIR/home-offset-place<s>.npz``): part of
        the offset belongs to the place. Default 3.
    home_offset_centre : bool
        Then correct the measured goal so that the expert's median stop lies at the true
        home: the expert homes again on the same kidnappings going to it, and a secant
        step per axis moves the goal
        (:func:`~vc_gym.experiments.home_offset.centre_home_offset`; twice the expert
        episodes; needs ``home_offset_episodes``). Default ``True``. A ``config.json``
        saved before the field existed was not centred.
    home_offset_m : (float, float), optional
        The goal correction itself (metres, world frame). ``None`` (default): measured
        with ``home_offset_episodes``, or ``(0, 0)`` without; a run's ``config.json``
        holds the measured value, so that its evaluation uses it.
    vec_env : str
        ``"subproc"`` (``SubprocVecEnv``, forkserver) or ``"dummy"`` (in-process).
    collector : str, optional
        How PPO collects its rollouts from the ``"subproc"`` workers: ``"async"`` (each
        worker runs its rollout on its own, choosing its actions itself,
        :mod:`vc_gym.experiments.async_rollouts`; the same rollouts as SB3's, faster
        when decisions differ in cost, as a checked stop's stand does) or
        ``"lockstep"`` (SB3's: every step waits for the slowest worker). Default
        (``None``): ``"async"`` with PPO in worker processes, else ``"lockstep"``. A
        ``config.json`` saved before the field existed was trained in lockstep.
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
    eval_freq : int
        Decisions between evaluations on held-out kidnappings (0: none). The model with
        the best mean return is kept as ``best/best_model.zip``.
    eval_episodes : int
        Kidnappings per evaluation (the same ones every time).
    eval_seed : int
        Seed of the held-out kidnappings (training envs use ``seed + i``).
    save_freq : int
        Decisions between checkpoints in ``checkpoints/`` (0: none); ``--resume DIR``
        continues from the latest.
    demo_episodes : int
        Warm start (PPO only): episodes of the scripted expert
        (:class:`~vc_gym.agents.HomingFeatureExpert`) whose decisions the policy is
        cloned from before PPO starts (:mod:`vc_gym.experiments.imitation`); 0: PPO
        from scratch. They are not counted in ``timesteps``. With evaluations on, the
        clone is evaluated before PPO starts, so the best model can be the clone.
        Default (``None``): 60 with PPO (about 6,000 decisions; over 60,000 decisions
        PPO from the clone reached ~80 % success in training, PPO from scratch ~30 %,
        README), 0 with SAC.
    """

    algo: str = "ppo"
    timesteps: int = 60_000
    n_envs: int = 2
    seed: int = 0
    places: tuple[int, ...] = ()
    scene: str = "robolab"
    learn_time_s: float = 5.0
    stop_time_s: float = 5.0
    confirm_stop_m: float | None = LEARNED_CONFIRM_STOP_M
    closeness_bonus: float = 0.0
    min_walk_m: float = 0.0
    previous_action: bool = True
    home_offset_episodes: int = DEFAULT_HOME_OFFSET_EPISODES
    home_offset_places: int = 3
    home_offset_centre: bool = True
    home_offset_m: tuple[float, float] | None = None
    success_radius_m: float = 0.3
    max_homing_s: float = 60.0
    vec_env: str = "subproc"
    collector: str | None = None
    net_arch: tuple[int, ...] = (64, 64)
    learning_rate: float = 3e-4
    gamma: float = 0.99
    n_steps: int = 256
    batch_size: int = 64
    log_std_init: float = -0.5
    max_forward: float = 0.4
    max_turn_deg_s: float = 60.0
    tracker: str = "grid"
    eval_freq: int = 20_000
    eval_episodes: int = 10
    eval_seed: int = 1_000_000
    save_freq: int = 0
    demo_episodes: int | None = None

    def __post_init__(self) -> None:
        if self.algo not in ALGORITHMS:
            raise ValueError(f"algo must be one of {ALGORITHMS}, got {self.algo!r}")
        if self.demo_episodes is None:
            object.__setattr__(self, "demo_episodes", DEFAULT_DEMO_EPISODES[self.algo])
        if not isinstance(self.tracker, str):
            raise ValueError(f"tracker must be a tracker name, got {self.tracker!r}")
        if self.vec_env not in ("subproc", "dummy"):
            raise ValueError(f"vec_env must be 'subproc' or 'dummy', got {self.vec_env!r}")
        if self.collector is None:
            parallel = self.algo == "ppo" and self.vec_env == "subproc"
            object.__setattr__(self, "collector", "async" if parallel else "lockstep")
        if self.collector not in COLLECTORS:
            raise ValueError(f"collector must be one of {COLLECTORS}, got {self.collector!r}")
        if self.collector == "async" and (self.algo != "ppo" or self.vec_env != "subproc"):
            raise ValueError(
                "collector 'async' needs algo 'ppo' and vec_env 'subproc' (worker processes; "
                "vc-gym train --n-envs 1 runs its env in-process)"
            )
        for name in ("timesteps", "n_envs", "n_steps", "batch_size", "eval_episodes"):
            int_at_least(name, getattr(self, name), 1)
        for name in ("eval_freq", "eval_seed", "save_freq", "seed", "demo_episodes"):
            int_at_least(name, getattr(self, name), 0)
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
        if self.confirm_stop_m is not None:
            positive_float("confirm_stop_m", self.confirm_stop_m)
        nonnegative_float("closeness_bonus", self.closeness_bonus)
        nonnegative_float("min_walk_m", self.min_walk_m)
        int_at_least("home_offset_episodes", self.home_offset_episodes, 0)
        int_at_least("home_offset_places", self.home_offset_places, 0)
        if self.home_offset_places > MAX_PLACES:
            raise ValueError(
                f"home_offset_places must be at most {MAX_PLACES}, got {self.home_offset_places}"
            )
        flag("previous_action", self.previous_action)
        flag("home_offset_centre", self.home_offset_centre)
        if self.home_offset_m is not None:
            object.__setattr__(self, "home_offset_m", home_offset(self.home_offset_m))
        elif self.home_offset_centre and not self.home_offset_episodes:
            raise ValueError(
                "home_offset_centre corrects a measured goal: with home_offset_episodes=0 "
                "(the tracker's home) set home_offset_centre=False too "
                "(--home-offset-episodes 0 --no-home-offset-centre)"
            )
        if self.demo_episodes and self.algo != "ppo":
            raise ValueError("demo_episodes (the warm start) needs algo 'ppo'; use 0 with sac")
        if not (0 < self.gamma <= 1):
            raise ValueError(f"gamma must be in (0, 1], got {self.gamma!r}")
        if not self.net_arch or any(int(n) < 1 for n in self.net_arch):
            raise ValueError(f"net_arch must be positive layer sizes, got {self.net_arch!r}")
        object.__setattr__(self, "net_arch", tuple(int(n) for n in self.net_arch))
        places = self.places
        if isinstance(places, (str, bytes)) or not hasattr(places, "__iter__"):
            raise ValueError(f"places must be a sequence of learning seeds, got {places!r}")
        places = tuple(places)
        for s in places:
            int_at_least("places entry", s, 0)
        if len(set(places)) != len(places) or len(places) > MAX_PLACES:
            raise ValueError(
                f"places must be at most {MAX_PLACES} distinct learning seeds, got {places!r}"
            )
        object.__setattr__(self, "places", tuple(int(s) for s in places))
        n_measured = self.home_offset_episodes * len(self.home_offset_seeds)
        if 0 < n_measured < MIN_STOPS:
            raise ValueError(
                f"the home offset needs at least {MIN_STOPS} expert episodes, got "
                f"home_offset_episodes={self.home_offset_episodes} in "
                f"{len(self.home_offset_seeds)} place(s)"
            )

    @property
    def place_seeds(self) -> tuple[int, ...]:
        """The learning seeds of the places trained in (``places``, or ``(seed,)``)."""
        return self.places or (self.seed,)

    @property
    def home_offset_seeds(self) -> tuple[int, ...]:
        """The learning seeds of the places the goal correction is measured in."""
        extra = (
            HOME_OFFSET_SEED + MAX_PLACES * self.seed + k for k in range(self.home_offset_places)
        )
        return self.place_seeds + tuple(extra)

    def atlas_files(self, out_dir: str | os.PathLike) -> list[Path]:
        """Where the run in ``out_dir`` keeps each place's atlas (one per place seed)."""
        out = Path(out_dir)
        if not self.places:
            return [out / "atlas.npz"]
        return [out / f"atlas-place{s}.npz" for s in self.places]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (with the schema version)."""
        return {
            "schema": CONFIG_SCHEMA,
            **asdict(self),
            "net_arch": list(self.net_arch),
            "places": list(self.places),
            "home_offset_m": None if self.home_offset_m is None else list(self.home_offset_m),
            "env": self.env_kwargs(),
        }

    def env_kwargs(self) -> dict[str, Any]:
        """The ``vc_gym/Homing-v0`` arguments of this run (the agent's env)."""
        # confirm_stop_m, closeness_bonus, min_walk_m and home_offset_m only when set, as
        # configs saved before they existed have them
        checked: dict[str, Any] = {}
        if self.confirm_stop_m is not None:
            checked["confirm_stop_m"] = self.confirm_stop_m
        for name in ("closeness_bonus", "min_walk_m"):
            if getattr(self, name):
                checked[name] = getattr(self, name)
        if self.home_offset_m is not None and self.home_offset_m != (0.0, 0.0):
            checked["home_offset_m"] = list(self.home_offset_m)
        if self.previous_action:
            checked["previous_action"] = True
        return {
            "scene": self.scene,
            "learn_time_s": self.learn_time_s,
            "stop_time_s": self.stop_time_s,
            "success_radius_m": self.success_radius_m,
            "max_homing_s": self.max_homing_s,
            "max_forward": self.max_forward,
            "max_turn_deg_s": self.max_turn_deg_s,
            "tracker": self.tracker,
            **checked,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrainConfig:
        """Inverse of :meth:`to_dict`; unknown keys or another schema are errors.

        A field missing from a saved config takes the value it had before the field
        existed (final stops, lockstep rollouts), not today's default.
        """
        data = dict(data)
        schema = data.pop("schema", None)
        if schema not in (1, CONFIG_SCHEMA):  # schema 1 had no "env" (derived from the rest)
            raise ValueError(f"config schema {schema!r} is not {CONFIG_SCHEMA}")
        env = data.pop("env", None)
        data.setdefault("confirm_stop_m", None)
        data.setdefault("closeness_bonus", 0.0)
        data.setdefault("min_walk_m", 0.0)
        data.setdefault("previous_action", False)
        data.setdefault("home_offset_episodes", 0)
        data.setdefault("home_offset_places", 0)
        data.setdefault("home_offset_centre", False)
        data.setdefault("collector", "lockstep")
        config = cls.from_settings(data)
        if env is not None and env != config.env_kwargs():
            raise ValueError("the config's 'env' does not match its own fields")
        return config

    @classmethod
    def from_settings(cls, data: dict[str, Any]) -> TrainConfig:
        """A config from any subset of its fields (a hand-written settings file); the
        rest take their defaults. Unknown keys are errors."""
        data = dict(data)
        unknown = set(data) - {f.name for f in fields(cls)}
        if unknown:
            raise ValueError(f"unknown config keys {sorted(unknown)}")
        for name in ("net_arch", "places"):
            if isinstance(data.get(name), list):
                data[name] = tuple(data[name])
        return cls(**data)


def _place_env(config: TrainConfig, seed: int, atlas_file: Path) -> gym.Env:
    """``vc_gym/Homing-v0`` of one place: learning seed ``seed``, its atlas learned once
    into ``atlas_file`` by the first env that needs it and loaded by every other."""
    return gym.make(
        "vc_gym/Homing-v0", **config.env_kwargs(), atlas_file=str(atlas_file), learning_seed=seed
    )


def _places(config: TrainConfig, out_dir: str | os.PathLike) -> list[tuple[int, Path]]:
    """``(learning seed, atlas file)`` of every place of the run in ``out_dir``."""
    return list(zip(config.place_seeds, config.atlas_files(out_dir), strict=True))


def training_env(config: TrainConfig, out_dir: str | os.PathLike) -> gym.Env:
    """``vc_gym/Homing-v0`` as ``config`` trains on it in the run folder ``out_dir``: one
    env per place (:attr:`TrainConfig.place_seeds`, atlases in
    :meth:`TrainConfig.atlas_files`); several places make a
    :class:`~vc_gym.envs.PlacePool`."""
    envs = [_place_env(config, seed, f) for seed, f in _places(config, out_dir)]
    return envs[0] if len(envs) == 1 else PlacePool(envs)


def check_names(config: TrainConfig) -> None:
    """Refuse an unregistered scene or tracker of ``config`` with a clear ``ValueError``."""
    check_scene_name(config.scene)
    make_tracker(config.tracker)


def learn_places(config: TrainConfig, out_dir: str | os.PathLike) -> int:
    """Run the learning phase of each of ``config``'s places once, into its atlas file in
    the run folder ``out_dir`` (kept if it is there already and was learned the same
    way). Returns how many places were learned now."""
    learned = 0
    for seed, f in _places(config, out_dir):
        env = _place_env(config, seed, f)
        try:
            env.reset(seed=seed)
            learned += bool(env.unwrapped.learner.learned)
        finally:
            env.close()
    return learned


def read_train_config(path: str | os.PathLike, **overrides: Any) -> TrainConfig:
    """A :class:`TrainConfig` from a YAML or JSON file of its fields, with ``overrides``
    on top. Any subset of the fields: the others take their defaults. A ``config.json``
    written by :func:`train` works too (it has a ``schema``; a field it lacks takes the
    value it had when the file was written, :meth:`TrainConfig.from_dict`).

    Raises
    ------
    ValueError
        Naming the file, for a file that cannot be read or an unknown or bad field.
    """
    data = {**read_settings(path), **overrides}
    try:
        if "schema" in data:  # a run's config.json: its missing fields are its era's
            data.pop("env", None)  # derived from the fields (a --config file overrides them)
            return TrainConfig.from_dict(data)
        return TrainConfig.from_settings(data)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}") from None


class _EnvFactory:
    """Picklable env constructor for worker processes."""

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


def _checkpoint_steps(path: Path) -> int | None:
    """Decisions of a ``model_<N>_steps.zip`` checkpoint (None for another name)."""
    steps = path.stem[len("model_") : -len("_steps")]
    return int(steps) if steps.isdigit() else None


def latest_checkpoint(run_dir: str | os.PathLike) -> Path | None:
    """The checkpoint with the most decisions in ``run_dir/checkpoints`` (None if none)."""
    found = [
        (steps, p)
        for p in (Path(run_dir) / "checkpoints").glob("model_*_steps.zip")
        if (steps := _checkpoint_steps(p)) is not None
    ]
    return max(found)[1] if found else None


def train(
    config: TrainConfig,
    out_dir: str | os.PathLike,
    progress: bool = True,
    tensorboard_log: str | os.PathLike | None = None,
    resume: bool = False,
) -> dict[str, Any]:
    """Train a homing agent the way stable-baselines3 users expect.

    Writes to ``out_dir``: ``model.zip`` (the final policy), ``config.json``,
    ``train_log.json`` (every training episode), ``learning_curve.png``, ``atlas.npz``
    (the place, learned once; ``atlas-place<s>.npz`` per place with ``places``),
    ``monitor/<i>.monitor.csv`` (SB3's per-worker episode logs), with ``eval_freq``
    ``eval/evaluations.npz`` and ``best/best_model.zip`` (held-out kidnappings), with
    ``save_freq`` ``checkpoints/model_<N>_steps.zip``.

    Parameters
    ----------
    config : TrainConfig
        The run's settings (saved as ``config.json`` before training starts).
    out_dir : path-like
        The run folder.
    progress : bool
        Show progress.
    tensorboard_log : path-like, optional
        Also write TensorBoard logs there (needs the ``tensorboard`` package).
    resume : bool
        Continue the run in ``out_dir`` from its latest checkpoint up to
        ``config.timesteps`` decisions (its ``config.json`` must match ``config`` except
        for ``timesteps``).

    Returns
    -------
    dict
        Paths, duration, decisions per second while the policy trained, episodes seen,
        and the success rate and mean stop error of the last 50 training episodes.
    """
    import torch
    from stable_baselines3.common.callbacks import CallbackList, CheckpointCallback
    from stable_baselines3.common.logger import Logger
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    from vc_gym.experiments.async_rollouts import AsyncRolloutPPO, AsyncSubprocVecEnv
    from vc_gym.experiments.training_callbacks import EpisodeLog, HeldOutEvaluation

    out = Path(out_dir)
    algo = algorithm_class(config.algo)
    check_names(config)  # before the run folder is made, not in the workers
    if tensorboard_log is not None:
        try:
            import tensorboard  # noqa: F401
        except ImportError:
            raise ValueError(
                "--tensorboard-log needs the tensorboard package: pip install tensorboard"
            ) from None
    episodes: list[dict[str, Any]] = []
    checkpoint = None
    warm_start: dict[str, Any] | None = None
    offset: dict[str, Any] | None = None
    if resume:
        checkpoint, episodes, config = _resume_state(out, config)
    out = check_out_dir(out)
    write_json(out / "config.json", config.to_dict())
    t0 = time.perf_counter()
    if progress:
        seeds = ", ".join(map(str, config.place_seeds))
        print(f"learning each place once ({config.scene}, learning seeds {seeds}) -> {out}")
    learn_places(config, out)
    if config.home_offset_m is None and config.home_offset_episodes:
        if progress:
            print(
                f"measuring the tracker's home: {config.home_offset_episodes} expert episodes "
                f"in each of {len(config.home_offset_seeds)} places"
            )
        config, offset = _measure_goal(config, out, progress)
    (out / "monitor").mkdir(exist_ok=True)
    factories = [
        _EnvFactory(config, i, out, out / "monitor" / str(i), append=resume)
        for i in range(config.n_envs)
    ]
    algo_cls = AsyncRolloutPPO if config.collector == "async" else algo
    if config.vec_env == "subproc":
        # SB3's SubprocVecEnv whose workers can also run whole rollouts, and which closes
        # past a dead one (its error is then the one raised, not a BrokenPipeError)
        venv = AsyncSubprocVecEnv(factories, start_method="forkserver")
    else:
        venv = DummyVecEnv(factories)
    log = EpisodeLog(
        config.timesteps,
        episodes,
        lambda eps: write_json(out / "train_log.json", {"running": True, "per_episode": eps}),
        f"train {config.algo}",
        progress,
    )
    callbacks: list[Any] = [log]
    eval_env = None
    if config.eval_freq:
        # the training env (same places, same rules), kidnapped from held-out seeds
        eval_env = DummyVecEnv([lambda: Monitor(training_env(config, out))])
        callbacks.append(
            HeldOutEvaluation(
                eval_env,
                seed=config.eval_seed,
                at_start=bool(config.demo_episodes) and checkpoint is None,
                n_eval_episodes=config.eval_episodes,
                eval_freq=max(1, config.eval_freq // config.n_envs),
                best_model_save_path=str(out / "best"),
                log_path=str(out / "eval"),
                deterministic=True,
                verbose=0,
            )
        )
    if config.save_freq:
        callbacks.append(
            CheckpointCallback(
                max(1, config.save_freq // config.n_envs), str(out / "checkpoints"), "model"
            )
        )
    # the policy is a small MLP: one torch thread is as fast, and a second one would
    # take a core from the env workers
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    tb = None if tensorboard_log is None else str(tensorboard_log)  # a str: plain JSON in the zip
    try:
        if checkpoint is not None:
            model = load_sb3_model(config.algo, checkpoint, env=venv, device="cpu", cls=algo_cls)
            if tb is not None:
                model.tensorboard_log = tb
        else:
            model = algo_cls("MlpPolicy", venv, tensorboard_log=tb, **_algo_kwargs(config))
            if config.demo_episodes:
                warm_start = _warm_start(model, venv, config, progress)
                write_json(out / "warm_start.json", warm_start)
        if tb is None:
            # without it SB3 makes an empty /tmp/SB3-<date> folder at every learn()
            model.set_logger(Logger(folder=None, output_formats=[]))
        with warnings.catch_warnings():
            # evaluation runs in this process (DummyVecEnv) on purpose
            warnings.filterwarnings("ignore", "Training and eval env are not of the same type")
            model.learn(
                total_timesteps=max(0, config.timesteps - model.num_timesteps),
                callback=CallbackList(callbacks),
                reset_num_timesteps=checkpoint is None,
                tb_log_name=config.algo,
            )
    finally:
        torch.set_num_threads(threads)
        venv.close()
        if eval_env is not None:
            eval_env.close()
    model_path = out / "model.zip"
    write_atomic(model_path, model.save)
    recent = episodes[-50:]
    rate, task_rate = log.decisions_per_s, log.task_steps_per_s
    summary = {
        "model": str(model_path),
        "config": config.to_dict(),
        "duration_s": round(time.perf_counter() - t0, 1),
        # agent decisions per second while the policy trained (no learning phase, no
        # worker start-up): what `vc-gym bench train` compares with the env's own speed
        "decisions_per_s": None if rate is None else round(rate, 2),
        "task_steps_per_s": None if task_rate is None else round(task_rate, 2),
        "episodes": len(episodes),
        "resumed_from": None if checkpoint is None else str(checkpoint),
        "warm_start": warm_start,
        "home_offset": offset,
        "best_model": str(out / "best" / "best_model.zip")
        if (out / "best" / "best_model.zip").is_file()
        else None,
        "recent_success_rate": float(np.mean([e["success"] for e in recent])) if recent else None,
        "recent_mean_stop_error_m": float(np.nanmean([e["stop_error_m"] for e in recent]))
        if recent
        else None,
    }
    write_json(out / "train_log.json", {**summary, "per_episode": episodes})
    if episodes:
        _plot_curve(out / "learning_curve.png", episodes, config)
    return summary


def _measure_goal(
    config: TrainConfig, out: Path, progress: bool
) -> tuple[TrainConfig, dict[str, Any]]:
    """Measure the run's goal correction (:mod:`.home_offset`) and keep it in the run
    folder (``home_offset.json``, ``config.json``); the config to train with."""
    files = {s: f for s, f in _places(config, out)}
    envs = []  # each place going to its atlas' home; the extra ones learned here
    try:
        for s in config.home_offset_seeds:
            envs.append(_place_env(config, s, files.get(s, out / f"home-offset-place{s}.npz")))
        seed = HOME_OFFSET_SEED + MAX_PLACES * config.seed
        measured = measure_home_offset(envs, config.home_offset_episodes, seed, progress=progress)
        if config.home_offset_centre:
            measured = centre_home_offset(
                envs, measured, config.home_offset_episodes, seed, progress=progress
            )
    finally:
        for env in envs:
            env.close()
    config = replace(config, home_offset_m=measured.offset_m)
    write_json(out / "home_offset.json", measured.to_dict())
    write_json(out / "config.json", config.to_dict())
    return config, measured.to_dict()


def _warm_start(model: Any, venv: Any, config: TrainConfig, progress: bool) -> dict[str, Any]:
    """Clone the scripted expert into ``model``'s policy (see :mod:`.imitation`)."""
    expert = HomingFeatureExpert(
        config.max_forward, config.max_turn_deg_s, previous_action=config.previous_action
    )
    demos = collect_demonstrations(venv, expert, config.demo_episodes, config.gamma, progress)
    fit = clone_behaviour(model.policy, demos, seed=config.seed)
    errors = [e["stop_error_m"] for e in demos.episodes]
    return {
        "demo_episodes": len(demos.episodes),
        "demo_decisions": len(demos.actions),
        "demo_success_rate": demos.success_rate,
        "demo_mean_stop_error_m": float(np.nanmean(errors)),
        **fit,
    }


def _algo_kwargs(config: TrainConfig) -> dict[str, Any]:
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
    return kwargs


def _resume_state(out: Path, config: TrainConfig) -> tuple[Path, list[dict[str, Any]], TrainConfig]:
    """The checkpoint to continue from, the episodes logged so far and the config to go
    on with (``config`` with the run's measured ``home_offset_m``), checked first."""
    saved_path = out / "config.json"
    if not saved_path.is_file():
        raise ValueError(f"{out}: no config.json, nothing to resume")
    saved = read_train_config(saved_path)
    if config.home_offset_m is None:  # the run measured it: keep the measurement
        config = replace(config, home_offset_m=saved.home_offset_m)
    if replace(saved, timesteps=config.timesteps) != config:
        raise ValueError(
            f"{saved_path}: the run was started with other settings; resume it with the "
            "same ones (only timesteps may change)"
        )
    checkpoint = latest_checkpoint(out)
    if checkpoint is None:
        raise ValueError(f"{out}: no checkpoint to resume from (train with --save-freq N)")
    steps = _checkpoint_steps(checkpoint)
    log_path = out / "train_log.json"
    episodes: list[dict[str, Any]] = []
    if log_path.is_file():
        try:
            logged = json.loads(log_path.read_text())["per_episode"]
        except (OSError, ValueError, KeyError, TypeError, RecursionError) as exc:
            raise ValueError(f"{log_path}: unreadable training log: {exc}") from None
        episodes = [e for e in logged if isinstance(e, dict) and e.get("timestep", 0) <= steps]
    return checkpoint, episodes, config


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
