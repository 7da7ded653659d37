"""Training learned homing agents with stable-baselines3 (``vc-gym train``).

:func:`train` fits PPO (default) or SAC on ``vc_gym/Homing-v0`` (the task env seen
through the compass and a tracker, :mod:`vc_gym.envs.homing`) in parallel worker
processes (``SubprocVecEnv``) and writes ``model.zip``, ``config.json``,
``train_log.json`` and ``learning_curve.png``;
:class:`~vc_gym.agents.learned.LearnedHomingAgent` loads them.

A run owns its folder: a new run refuses a folder that holds one
(:func:`check_new_run_dir`), and only ``resume`` continues one. Checkpoints and every
other file but SB3's monitor logs are written atomically, and a resume skips a
checkpoint that does not load, so an interrupted run can be resumed from its last whole
checkpoint. Settings files choose no code: a tracker or scene read from a file must be a
registered plug-in (:func:`read_train_config`).
"""

from __future__ import annotations

import json
import numbers
import os
import reprlib
import sys
import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from vc_gym.config_files import read_settings
from vc_gym.envs.homing import LEARNED_CONFIRM_STOP_M, home_offset
from vc_gym.envs.place_pool import PlacePool
from vc_gym.jobs.output import check_out_dir, new_figure, save_figure, write_json
from vc_gym.localization import make_tracker
from vc_gym.localization.registry import TRACKERS
from vc_gym.persistence import write_atomic
from vc_gym.plugins import check_file_spec, check_plain_data
from vc_gym.sim.scenes import check_scene_name
from vc_gym.training.algorithms import ALGORITHMS, algorithm_class
from vc_gym.training.feature_expert import HomingFeatureExpert
from vc_gym.training.home_offset import MIN_STOPS, centre_home_offset, measure_home_offset
from vc_gym.training.imitation import clone_behaviour, collect_demonstrations
from vc_gym.training.safe_load import MAX_LAYER_WIDTH, MAX_LAYERS, load_sb3_model
from vc_gym.validation import finite_real, flag, int_at_least, nonnegative_float, positive_float

__all__ = [
    "TrainConfig",
    "check_names",
    "check_new_run_dir",
    "checkpoints",
    "continue_run",
    "latest_checkpoint",
    "read_train_config",
    "run_files",
    "train",
]

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
#: Accepted values of ``TrainConfig.vec_env``.
VEC_ENVS = ("subproc", "dummy")
#: At most this many parallel environments (``TrainConfig.n_envs``): one worker process
#: each.
MAX_N_ENVS = 256
#: Checkpoints of a run are ``checkpoints/<prefix>_<decisions>_steps.zip``.
CHECKPOINT_PREFIX = "model"
#: What a training run writes into its folder (besides the atlases, which a new run may
#: find there and reuse, :func:`learn_places`), and the marker of a sweep's folder: a
#: folder holding any of them holds a run, and a new run refuses it
#: (:func:`check_new_run_dir`).
RUN_FILES = (
    "config.json",
    "model.zip",
    "train_log.json",
    "checkpoints",
    "best",
    "eval",
    "monitor",
    "warm_start.json",
    "home_offset.json",
    "learning_curve.png",
    "jobs",
)
#: Largest ``train_log.json`` read back when a run resumes (bytes; an episode takes
#: about 150).
MAX_TRAIN_LOG_BYTES = 100_000_000
#: Integer fields of :class:`TrainConfig` and the smallest value each accepts.
_INT_FIELDS = {
    "timesteps": 1,
    "n_envs": 1,
    "n_steps": 1,
    "batch_size": 1,
    "eval_episodes": 1,
    "eval_freq": 0,
    "eval_seed": 0,
    "save_freq": 0,
    "seed": 0,
    "demo_episodes": 0,
    "home_offset_episodes": 0,
    "home_offset_places": 0,
}
#: Float fields of :class:`TrainConfig` that must be finite and > 0.
_POSITIVE_FIELDS = (
    "learn_time_s",
    "stop_time_s",
    "success_radius_m",
    "max_homing_s",
    "learning_rate",
    "max_forward",
    "max_turn_deg_s",
)


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
        (``vc_gym.envs.homing.LEARNED_CONFIRM_STOP_M``), so the policy learns
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
        (``home_offset_m`` of ``vc_gym/Homing-v0``; :mod:`vc_gym.training.home_offset`;
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
        (:func:`~vc_gym.training.home_offset.centre_home_offset`; twice the expert
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
        :mod:`vc_gym.training.async_rollouts`; the same rollouts as SB3's, faster
        when decisions differ in cost, as a checked stop's stand does) or
        ``"lockstep"`` (SB3's: every step waits for the slowest worker). Default
        (``None``): ``"async"`` with PPO in worker processes, else ``"lockstep"``. A
        ``config.json`` saved before the field existed was trained in lockstep.
    net_arch : tuple of int
        Hidden layers of the policy and value MLPs: 1 to :data:`MAX_LAYERS` widths, each
        an integer from 1 to :data:`MAX_LAYER_WIDTH`.
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
    tracker : str or dict
        Tracker of the agent's env: a registered name (``"grid"``, ``"particle"``,
        ``"kalman"``, any ``register_tracker`` name) or ``{"type": name, **kwargs}`` with
        plain-data arguments (kept as a plain dict, so ``config.json`` stays JSON). From
        Python code or the command line the name may also be an import path
        ``"package.module:factory"``; from a file only with ``allow_imports``
        (:func:`read_train_config`).
    eval_freq : int
        Decisions between evaluations on held-out kidnappings (0: none). The model with
        the best mean return is kept as ``best/best_model.zip``.
    eval_episodes : int
        Kidnappings per evaluation (the same ones every time).
    eval_seed : int
        Seed of the held-out kidnappings (training envs use ``seed + i``).
    save_freq : int
        Decisions between checkpoints in ``checkpoints/`` (0: none); ``--resume DIR``
        continues from the latest that loads.
    demo_episodes : int
        Warm start (PPO only): episodes of the scripted expert
        (:class:`~vc_gym.agents.HomingFeatureExpert`) whose decisions the policy is
        cloned from before PPO starts (:mod:`vc_gym.training.imitation`); 0: PPO
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
    tracker: str | dict[str, Any] = "grid"
    eval_freq: int = 20_000
    eval_episodes: int = 10
    eval_seed: int = 1_000_000
    save_freq: int = 0
    demo_episodes: int | None = None

    def __post_init__(self) -> None:
        # every field's type is checked here, whoever built the config (Python code, a
        # settings file, a run's config.json): a ValueError names the field and what it
        # accepts; the values are stored as plain Python ints, floats, bools and strings
        # (numpy numbers too become plain ones), so config.json stays JSON
        if not isinstance(self.algo, str) or self.algo not in ALGORITHMS:
            raise ValueError(f"algo must be one of {ALGORITHMS}, got {self.algo!r}")
        if self.demo_episodes is None:
            object.__setattr__(self, "demo_episodes", DEFAULT_DEMO_EPISODES[self.algo])
        for name, minimum in _INT_FIELDS.items():
            object.__setattr__(self, name, int_at_least(name, getattr(self, name), minimum))
        for name, maximum in (("n_envs", MAX_N_ENVS), ("home_offset_places", MAX_PLACES)):
            if getattr(self, name) > maximum:
                raise ValueError(f"{name} must be at most {maximum}, got {getattr(self, name)}")
        for name in _POSITIVE_FIELDS:
            object.__setattr__(self, name, positive_float(name, getattr(self, name)))
        for name in ("closeness_bonus", "min_walk_m"):
            object.__setattr__(self, name, nonnegative_float(name, getattr(self, name)))
        object.__setattr__(self, "log_std_init", finite_real("log_std_init", self.log_std_init))
        if self.confirm_stop_m is not None:
            object.__setattr__(
                self, "confirm_stop_m", positive_float("confirm_stop_m", self.confirm_stop_m)
            )
        gamma = finite_real("gamma", self.gamma)
        if not (0 < gamma <= 1):
            raise ValueError(f"gamma must be in (0, 1], got {self.gamma!r}")
        object.__setattr__(self, "gamma", gamma)
        for name in ("previous_action", "home_offset_centre"):
            object.__setattr__(self, name, flag(name, getattr(self, name)))
        if not isinstance(self.scene, str) or not self.scene:
            raise ValueError(f"scene must be a scene name (a string), got {self.scene!r}")
        object.__setattr__(self, "tracker", _tracker_field(self.tracker))
        if not isinstance(self.vec_env, str) or self.vec_env not in VEC_ENVS:
            raise ValueError(f"vec_env must be one of {VEC_ENVS}, got {self.vec_env!r}")
        if self.collector is None:
            parallel = self.algo == "ppo" and self.vec_env == "subproc"
            object.__setattr__(self, "collector", "async" if parallel else "lockstep")
        if not isinstance(self.collector, str) or self.collector not in COLLECTORS:
            raise ValueError(f"collector must be one of {COLLECTORS}, got {self.collector!r}")
        if self.collector == "async" and (self.algo != "ppo" or self.vec_env != "subproc"):
            raise ValueError(
                "collector 'async' needs algo 'ppo' and vec_env 'subproc' (worker processes; "
                "vc-gym train --n-envs 1 runs its env in-process)"
            )
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
        object.__setattr__(self, "net_arch", _net_arch(self.net_arch))
        places = self.places
        if isinstance(places, (str, bytes)) or not isinstance(places, (Sequence, np.ndarray)):
            raise ValueError(f"places must be a sequence of learning seeds, got {places!r}")
        if len(places) > MAX_PLACES:
            raise ValueError(
                f"places must be at most {MAX_PLACES} distinct learning seeds, "
                f"got {reprlib.repr(places)}"
            )
        places = tuple(int_at_least("places entry", s, 0) for s in places)
        if len(set(places)) != len(places):
            raise ValueError(
                f"places must be at most {MAX_PLACES} distinct learning seeds, got {places!r}"
            )
        object.__setattr__(self, "places", places)
        n_measured = self.home_offset_episodes * len(self.home_offset_seeds)
        if 0 < n_measured < MIN_STOPS:
            raise ValueError(
                f"the home offset needs at least {MIN_STOPS} expert episodes, got "
                f"home_offset_episodes={self.home_offset_episodes} in "
                f"{len(self.home_offset_seeds)} place(s)"
            )

    def __hash__(self) -> int:
        # the tracker may be a dict: hash the config's JSON form
        return hash(json.dumps(self.to_dict(), sort_keys=True))

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
            "tracker": _plain_copy(self.tracker),
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


def _plain_copy(value: Any) -> Any:
    """A deep copy of JSON-like plain data (tuples become lists)."""
    return json.loads(json.dumps(value))


def _tracker_field(spec: Any) -> str | dict[str, Any]:
    """``TrainConfig.tracker`` checked: a name, or a ``{"type": name, ...}`` dict of plain
    data (returned as a plain dict of its own)."""
    if isinstance(spec, str):
        if not spec:
            raise ValueError("tracker must be a tracker name, got ''")
        return spec
    if isinstance(spec, Mapping):
        name = spec.get("type")
        if not isinstance(name, str) or not name:
            raise ValueError(
                f"tracker: a {{'type': name, **kwargs}} dict needs a 'type' name, "
                f"got {reprlib.repr(spec)}"
            )
        check_plain_data(dict(spec), "tracker")
        return _plain_copy(dict(spec))
    raise ValueError(
        "tracker must be a tracker name or a {'type': name, **kwargs} dict of plain data, "
        f"got {type(spec).__name__}"
    )


def _net_arch(value: Any) -> tuple[int, ...]:
    """``TrainConfig.net_arch`` checked: 1 to :data:`MAX_LAYERS` integer widths from 1 to
    :data:`MAX_LAYER_WIDTH` (a string, a float or a bool is no width)."""
    expected = (
        f"net_arch must be a list of 1 to {MAX_LAYERS} layer widths, each an integer "
        f"from 1 to {MAX_LAYER_WIDTH}, got {reprlib.repr(value)}"
    )
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
        raise ValueError(expected)
    if not 1 <= len(value) <= MAX_LAYERS:
        raise ValueError(expected)
    widths = []
    for n in value:
        if isinstance(n, (bool, np.bool_)) or not isinstance(n, numbers.Integral):
            raise ValueError(expected)
        if not 1 <= int(n) <= MAX_LAYER_WIDTH:
            raise ValueError(expected)
        widths.append(int(n))
    return tuple(widths)


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
    """Refuse an unregistered scene or tracker of ``config`` with a clear ``ValueError``.

    Builds the tracker once (a ``{"type": ...}`` dict's arguments are checked by its
    constructor); an import path is imported. A config read from a file passed
    :func:`read_train_config`'s checks first, which admit import paths only with
    ``allow_imports``.
    """
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


def read_train_config(
    path: str | os.PathLike, allow_imports: bool = False, **overrides: Any
) -> TrainConfig:
    """A :class:`TrainConfig` from a YAML or JSON file of its fields, with ``overrides``
    on top. Any subset of the fields: the others take their defaults. A ``config.json``
    written by :func:`train` works too (it has a ``schema``; a field it lacks takes the
    value it had when the file was written, :meth:`TrainConfig.from_dict`).

    A file chooses no code: its ``tracker`` must be a registered tracker name or
    ``{"type": registered name, **plain-data kwargs}`` and its ``scene`` a registered
    scene name, checked before anything is imported or built
    (:func:`vc_gym.plugins.check_file_spec`). ``overrides`` are the caller's (Python
    code, the command line) and are not checked this way: they may name import paths.

    Parameters
    ----------
    path : path-like
        The settings file (``.json``, ``.yml``, ``.yaml``; read with
        :func:`vc_gym.config_files.read_settings`: bounded size and depth, no YAML
        aliases, no repeated keys).
    allow_imports : bool
        Let the file's tracker be an import path ``"package.module:factory"`` (or a dict
        whose ``type`` is one): the person at the keyboard vouches for the file. Default
        False.
    **overrides
        Fields that replace the file's.

    Raises
    ------
    ValueError
        Naming the file (and the field), for a file that cannot be read, an unknown or
        bad field, or a tracker or scene that is not a registered plug-in.
    """
    data = read_settings(path)
    if "tracker" in data and "tracker" not in overrides:
        check_file_spec(
            data["tracker"], TRACKERS, "tracker", f"{path}: field 'tracker'", allow_imports
        )
    if "scene" in data and "scene" not in overrides:
        try:
            check_scene_name(data["scene"])
        except ValueError as exc:
            raise ValueError(f"{path}: field 'scene': {exc}") from None
    data = {**data, **overrides}
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
    prefix, suffix = f"{CHECKPOINT_PREFIX}_", "_steps"
    if not (path.stem.startswith(prefix) and path.stem.endswith(suffix)):
        return None
    steps = path.stem[len(prefix) : -len(suffix)]
    return int(steps) if steps.isdigit() else None


def checkpoints(run_dir: str | os.PathLike) -> list[Path]:
    """The checkpoints in ``run_dir/checkpoints``, the one with the most decisions first."""
    found = [
        (steps, p)
        for p in (Path(run_dir) / "checkpoints").glob(f"{CHECKPOINT_PREFIX}_*_steps.zip")
        if (steps := _checkpoint_steps(p)) is not None
    ]
    return [p for _, p in sorted(found, reverse=True)]


def latest_checkpoint(run_dir: str | os.PathLike) -> Path | None:
    """The checkpoint with the most decisions in ``run_dir/checkpoints`` (None if none)."""
    found = checkpoints(run_dir)
    return found[0] if found else None


def run_files(run_dir: str | os.PathLike) -> list[str]:
    """Which of :data:`RUN_FILES` ``run_dir`` holds (none for a missing folder)."""
    out = Path(run_dir)
    if not out.is_dir():
        return []
    return [name for name in RUN_FILES if os.path.lexists(out / name)]


def check_new_run_dir(run_dir: str | os.PathLike) -> None:
    """Refuse ``run_dir`` for a new run if it holds a run already.

    A folder holding any of :data:`RUN_FILES` (``config.json``, ``model.zip``,
    ``checkpoints/``, ``train_log.json``, ...) is another run's, or this one's from
    before: training into it would mix two runs (a new ``config.json`` beside an old
    ``model.zip``, old checkpoints that ``--resume`` would continue from). A missing or
    empty folder, or one with only atlases (``atlas*.npz``, reused when learned the same
    way, :func:`learn_places`) or unrelated files, is accepted.

    Raises
    ------
    ValueError
        ``--out DIR: ...`` naming what it holds and how to go on (``--resume`` or
        another folder).
    """
    found = run_files(run_dir)
    if found:
        out = Path(run_dir)
        raise ValueError(
            f"--out {out}: holds a training run already ({', '.join(found)}); a new run "
            f"starts in a folder without one. Continue that run with vc-gym train --resume "
            f"{out} (train(..., resume=True)), or choose another --out"
        )


@dataclass
class _RunStart:
    """Where a run starts: its config, and with a checkpoint what it continues from."""

    config: TrainConfig
    checkpoint: Path | None = None
    episodes: list[dict[str, Any]] = field(default_factory=list)
    skipped: list[tuple[Path, str]] = field(default_factory=list)


def _check_start(config: TrainConfig, tensorboard_log: str | os.PathLike | None) -> None:
    """What :func:`train` checks before it touches the run folder."""
    algorithm_class(config.algo)  # stable-baselines3 is installed
    check_names(config)  # before the run folder is made, not in the workers
    if tensorboard_log is not None:
        try:
            import tensorboard  # noqa: F401
        except ImportError:
            raise ValueError(
                "--tensorboard-log needs the tensorboard package: pip install tensorboard"
            ) from None


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
    ``save_freq`` ``checkpoints/model_<N>_steps.zip``. Every file but the monitor logs
    (appended line by line) is written atomically, so an interrupted run (Ctrl-C) keeps
    whole checkpoints to resume from.

    Parameters
    ----------
    config : TrainConfig
        The run's settings (saved as ``config.json`` before training starts).
    out_dir : path-like
        The run folder. A new run refuses a folder that holds a run already
        (:func:`check_new_run_dir`), before anything is written.
    progress : bool
        Show progress.
    tensorboard_log : path-like, optional
        Also write TensorBoard logs there (needs the ``tensorboard`` package).
    resume : bool
        Continue the run in ``out_dir`` from its latest checkpoint up to
        ``config.timesteps`` decisions (its ``config.json`` must match ``config`` except
        for ``timesteps``). A checkpoint that does not load (a torn or foreign file) is
        skipped for the next older one; each skipped one is printed to stderr with the
        reason and listed in the result's ``skipped_checkpoints``.

    Returns
    -------
    dict
        Paths, duration, decisions per second while the policy trained, episodes seen,
        and the success rate and mean stop error of the last 50 training episodes.

    Raises
    ------
    ValueError
        A bad name, a folder that holds a run (without ``resume``), or a run that cannot
        be resumed (no ``config.json``, other settings, no checkpoint that loads).
    """
    out = Path(out_dir)
    _check_start(config, tensorboard_log)
    if resume:
        start = resume_state(out, config)
        if start.checkpoint is None:
            tried = "; ".join(f"{p.name}: {why}" for p, why in start.skipped)
            raise ValueError(
                f"{out}: no checkpoint to resume from (train with --save-freq N)"
                if not tried
                else f"{out}: no checkpoint loads ({tried})"
            )
    else:
        check_new_run_dir(out)
        start = _RunStart(config)
    return _train(start, out, progress, tensorboard_log)


def continue_run(
    config: TrainConfig, out_dir: str | os.PathLike, progress: bool = False
) -> dict[str, Any]:
    """Train ``config`` in ``out_dir``, going on from what an earlier attempt of the same
    run left there (a sweep's job run again after an interruption or a failure).

    A folder without a run: a new run. A run of the same settings (its ``config.json``
    equals ``config``, a measured goal aside): resumed from its latest checkpoint that
    loads, or, without one, trained again from the start in the same folder (its atlases
    and measured goal are kept). Any other run there is refused.

    Raises
    ------
    ValueError
        Naming the folder: it holds another run (or files of one without its
        ``config.json``).
    """
    out = Path(out_dir)
    _check_start(config, None)
    if not run_files(out):
        return _train(_RunStart(config), out, progress, None)
    if not (out / "config.json").is_file():
        raise ValueError(
            f"{out}: holds files of a training run ({', '.join(run_files(out))}) but no "
            "config.json: not a run of these settings; remove it or choose another --out"
        )
    return _train(resume_state(out, config), out, progress, None)


def _train(
    start: _RunStart,
    out: Path,
    progress: bool,
    tensorboard_log: str | os.PathLike | None,
) -> dict[str, Any]:
    """The run itself (:func:`train`), once the folder is checked."""
    import torch
    from stable_baselines3.common.callbacks import CallbackList
    from stable_baselines3.common.logger import Logger
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    from vc_gym.training.async_rollouts import AsyncRolloutPPO, AsyncSubprocVecEnv
    from vc_gym.training.callbacks import (
        AtomicCheckpoint,
        EpisodeLog,
        HeldOutEvaluation,
    )

    config, checkpoint, episodes = start.config, start.checkpoint, start.episodes
    resume = checkpoint is not None
    algo = algorithm_class(config.algo)
    warm_start: dict[str, Any] | None = None
    offset: dict[str, Any] | None = None
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

    def write_log(eps: list[dict[str, Any]]) -> None:
        write_json(out / "train_log.json", {"running": True, "per_episode": eps})

    log = EpisodeLog(config.timesteps, episodes, write_log, f"train {config.algo}", progress)
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
            AtomicCheckpoint(
                max(1, config.save_freq // config.n_envs),
                out / "checkpoints",
                CHECKPOINT_PREFIX,
                # the log of the episodes so far with each checkpoint (after it: EpisodeLog
                # runs first), so that a run stopped here resumes with them
                on_save=lambda: write_log(episodes),
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
        "skipped_checkpoints": [{"checkpoint": str(p), "error": why} for p, why in start.skipped],
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


def resume_state(out: Path, config: TrainConfig) -> _RunStart:
    """Where the run in ``out`` goes on from: the config to go on with (``config`` with
    the run's measured ``home_offset_m``), its newest checkpoint that loads (None if
    none does; each one skipped printed to stderr with the reason) and the episodes
    logged up to it. The run's settings are checked first."""
    saved_path = out / "config.json"
    if not saved_path.is_file():
        raise ValueError(f"{out}: no config.json, nothing to resume")
    # the saved config is only compared with the caller's ``config`` and nothing is built
    # from it, so an import path in it (the caller's own, or a mismatch) is read as a name
    saved = read_train_config(saved_path, allow_imports=True)
    if config.home_offset_m is None:  # the run measured it: keep the measurement
        config = replace(config, home_offset_m=saved.home_offset_m)
    if replace(saved, timesteps=config.timesteps) != config:
        raise ValueError(
            f"{saved_path}: the run was started with other settings; resume it with the "
            "same ones (only timesteps may change)"
        )
    skipped: list[tuple[Path, str]] = []
    for path in checkpoints(out):
        try:
            load_sb3_model(config.algo, path, device="cpu")
        except Exception as exc:  # noqa: BLE001 - whatever keeps it from loading: skip it
            skipped.append((path, f"{type(exc).__name__}: {exc}"))
            print(f"skipping checkpoint {path}: it does not load ({exc})", file=sys.stderr)
            continue
        steps = _checkpoint_steps(path)
        assert steps is not None  # checkpoints() lists only such names
        episodes = _read_train_log(out / "train_log.json", steps)
        return _RunStart(config, path, episodes, skipped)
    return _RunStart(config, None, [], skipped)


#: The fields of one episode in ``train_log.json`` and the types each may have.
_EPISODE_FIELDS = {
    "timestep": numbers.Integral,
    "return": numbers.Real,
    "decisions": numbers.Integral,
    "stop_error_m": numbers.Real,
    "success": bool,
}


def _read_train_log(path: Path, steps: int) -> list[dict[str, Any]]:
    """The episodes of the training log ``path`` up to ``steps`` decisions (none without
    a log); a log larger than :data:`MAX_TRAIN_LOG_BYTES` or not of
    :class:`~.training_callbacks.EpisodeLog`'s episodes is refused, naming the file."""
    if not path.is_file():
        return []
    try:
        with path.open("rb") as f:
            raw = f.read(MAX_TRAIN_LOG_BYTES + 1)
        if len(raw) > MAX_TRAIN_LOG_BYTES:
            raise ValueError(f"larger than {MAX_TRAIN_LOG_BYTES} bytes")
        logged = json.loads(raw.decode("utf-8"))["per_episode"]
        if not isinstance(logged, list):
            raise ValueError("'per_episode' is not a list")
    except (OSError, ValueError, KeyError, TypeError, RecursionError) as exc:
        raise ValueError(f"{path}: unreadable training log: {exc}") from None
    episodes = []
    for i, e in enumerate(logged):
        if not (
            isinstance(e, dict)
            and set(e) == set(_EPISODE_FIELDS)
            and all(
                isinstance(e[k], t) and (t is bool or not isinstance(e[k], bool))
                for k, t in _EPISODE_FIELDS.items()
            )
        ):
            raise ValueError(
                f"{path}: per_episode[{i}] is not an episode record "
                f"({', '.join(_EPISODE_FIELDS)}): {reprlib.repr(e)}"
            )
        if e["timestep"] <= steps:
            episodes.append(e)
    return episodes


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
