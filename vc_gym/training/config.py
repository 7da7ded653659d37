"""The configuration of a training run: :class:`TrainConfig` and the files it is read from.

A :class:`TrainConfig` holds every setting of a run, each field checked when the config
is built, and is saved as the run's ``config.json`` (:meth:`TrainConfig.to_dict`).
:func:`read_train_config` reads one from a hand-written YAML or JSON settings file, or
from a run's ``config.json``. Settings files choose no code: a tracker or scene read from
a file must be a registered plug-in (:func:`read_train_config`); :func:`check_names`
refuses an unregistered one before a run starts.
"""

from __future__ import annotations

import json
import numbers
import os
import reprlib
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.config_files import read_settings
from vc_gym.envs.homing import LEARNED_CONFIRM_STOP_M, home_offset
from vc_gym.envs.homing_modes import LEARNED_AGENT_MODE, canonical_homing_mode, homing_mode
from vc_gym.localization import make_tracker
from vc_gym.localization.registry import TRACKERS
from vc_gym.plugins import check_file_spec, check_plain_data
from vc_gym.sim.scenes import check_scene_name
from vc_gym.training.algorithms import ALGORITHMS
from vc_gym.training.home_offset import MIN_STOPS
from vc_gym.training.safe_load import MAX_LAYER_WIDTH, MAX_LAYERS
from vc_gym.validation import finite_real, flag, int_at_least, nonnegative_float, positive_float

__all__ = [
    "COLLECTORS",
    "CONFIG_SCHEMA",
    "DEFAULT_DEMO_EPISODES",
    "DEFAULT_HOME_OFFSET_EPISODES",
    "HOME_OFFSET_SEED",
    "MAX_N_ENVS",
    "MAX_PLACES",
    "VEC_ENVS",
    "TrainConfig",
    "check_names",
    "read_train_config",
]

CONFIG_SCHEMA = 2
#: Warm-start episodes of each algorithm by default (``TrainConfig.demo_episodes``).
DEFAULT_DEMO_EPISODES = {"ppo": 60, "sac": 0}
#: Expert episodes that measure the goal correction by default in the paper's mode
#: (``TrainConfig.home_offset_episodes``; then centred, ``home_offset_centre``); the other
#: modes normalise the spots at the true home and measure none by default.
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
    "expert_speed_m_s",
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
    mode : str
        The homing mode whose places the run learns and whose tracker it homes on
        (:data:`~vc_gym.envs.homing_modes.HOMING_MODES`; its ``learning`` settings
        become arguments of the agent's env, so that every evaluation learns its places
        the same way). Default :data:`~vc_gym.envs.homing_modes.LEARNED_AGENT_MODE`
        (``"pose-home"``: turns learned around the spots, normalised at the true home,
        the ``pose-grid`` tracker); a ``config.json`` without this field reads as
        ``"paper"``.
    position_std : bool
        The policy also sees the tracker's position spread (``position_std`` of
        ``vc_gym/Homing-v0``), so that it can learn when to trust the position. Default
        True; a ``config.json`` without this field reads as False.
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
        with the check it is evaluated with. ``None``: a stop is final; a
        ``config.json`` without this field reads as ``None``.
    closeness_bonus : float
        Reward of a successful stop for its closeness to home (``closeness_bonus`` of
        ``vc_gym/LearnThenHome-v0``: ``closeness_bonus × (1 − d / success_radius_m)`` on
        top of the success bonus). Default 0: the task's rewards, under which a stop
        25 cm from home earns as much as one at home, less the 10 per metre of the
        progress reward. A ``config.json`` without this field reads as 0.
    min_walk_m : float
        Stop requests are ignored until the robot has walked this far by its own
        forward commands (``min_walk_m`` of ``vc_gym/Homing-v0``). Default 0; a
        ``config.json`` without this field reads as 0.
    previous_action : bool
        The policy also sees its last action (``previous_action`` of
        ``vc_gym/Homing-v0``, :class:`~vc_gym.envs.PreviousAction`), and the expert it is
        warm-started from keeps a turn going while home is behind, so that the clone can
        learn to turn through rather than stall with home behind it. Default True; a
        ``config.json`` without this field reads as False.
    home_offset_episodes : int
        Before the warm start, the scripted expert homes this many times in each of the
        training place(s) and ``home_offset_places`` more, and the median ``estimate −
        true position`` at its stops becomes the goal of the agent's env
        (``home_offset_m`` of ``vc_gym/Homing-v0``; :mod:`vc_gym.training.home_offset`;
        ``DIR/home_offset.json``): the policy learns to stop where that error says the
        true home is, not where the tracker believes home is. Default (``None``): 10 in
        the ``"paper"`` mode, whose spots are normalised where the walk back's odometry
        ends, 0 in the others (normalised at the true home); 0: the atlas' home (then
        ``home_offset_centre=False``). A ``config.json`` without this field reads as 0.
    home_offset_places : int
        Places learned only for that measurement (learning seeds
        ``HOME_OFFSET_SEED + 16 × seed + k``, ``DIR/home-offset-place<s>.npz``): part of
        the offset belongs to the place. Default 3; a ``config.json`` without this
        field reads as 0.
    home_offset_centre : bool
        Then correct the measured goal so that the expert's median stop lies at the true
        home: the expert homes again on the same kidnappings going to it, and a secant
        step per axis moves the goal
        (:func:`~vc_gym.training.home_offset.centre_home_offset`; twice the expert
        episodes; needs ``home_offset_episodes``). Default (``None``): whether the
        offset is measured; a ``config.json`` without this field reads as ``False``.
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
        (``None``): ``"async"`` with PPO in worker processes, else ``"lockstep"``; a
        ``config.json`` without this field reads as ``"lockstep"``.
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
    tracker : str or dict, optional
        Tracker of the agent's env (default ``None``: the mode's,
        :attr:`~vc_gym.envs.homing_modes.HomingMode.tracker`): a registered name
        (``"grid"``, ``"particle"``, ``"kalman"``, any ``register_tracker`` name) or
        ``{"type": name, **kwargs}`` with plain-data arguments (kept as a plain dict, so
        ``config.json`` stays JSON). From Python code or the command line the name may
        also be an import path ``"package.module:factory"``; from a file only with
        ``allow_imports`` (:func:`read_train_config`).
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
    expert_speed_m_s : float
        Fastest walk (m/s) of the scripted expert the policy is cloned from
        (``max_speed_m_s`` of :class:`~vc_gym.agents.HomingFeatureExpert`), at most
        ``max_forward``. Default 0.25, the scripted agent's; PPO learns to walk faster
        itself (a faster expert homed faster alone but trained a worse policy, see the
        results notes). A ``config.json`` without this field reads as 0.25.
    demo_episodes : int
        Warm start (PPO only): episodes of the scripted expert
        (:class:`~vc_gym.agents.HomingFeatureExpert`) whose decisions the policy is
        cloned from before PPO starts (:mod:`vc_gym.training.imitation`); 0: PPO
        from scratch. They are not counted in ``timesteps``. With evaluations on, the
        clone is evaluated before PPO starts, so the best model can be the clone.
        Default (``None``): 60 with PPO (about 6,000 decisions), 0 with SAC.
    """

    algo: str = "ppo"
    timesteps: int = 60_000
    n_envs: int = 2
    seed: int = 0
    places: tuple[int, ...] = ()
    scene: str = "robolab"
    mode: str = LEARNED_AGENT_MODE
    position_std: bool = True
    learn_time_s: float = 5.0
    stop_time_s: float = 5.0
    confirm_stop_m: float | None = LEARNED_CONFIRM_STOP_M
    closeness_bonus: float = 0.0
    min_walk_m: float = 0.0
    previous_action: bool = True
    home_offset_episodes: int | None = None
    home_offset_places: int = 3
    home_offset_centre: bool | None = None
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
    tracker: str | dict[str, Any] | None = None
    eval_freq: int = 20_000
    eval_episodes: int = 10
    eval_seed: int = 1_000_000
    save_freq: int = 0
    demo_episodes: int | None = None
    expert_speed_m_s: float = 0.25

    def __post_init__(self) -> None:
        # every field's type is checked here, whoever built the config (Python code, a
        # settings file, a run's config.json): a ValueError names the field and what it
        # accepts; the values are stored as plain Python ints, floats, bools and strings
        # (numpy numbers too become plain ones), so config.json stays JSON
        if not isinstance(self.algo, str) or self.algo not in ALGORITHMS:
            raise ValueError(f"algo must be one of {ALGORITHMS}, got {self.algo!r}")
        if self.demo_episodes is None:
            object.__setattr__(self, "demo_episodes", DEFAULT_DEMO_EPISODES[self.algo])
        object.__setattr__(self, "mode", canonical_homing_mode(self.mode))
        if self.tracker is None:
            object.__setattr__(self, "tracker", homing_mode(self.mode).tracker)
        if self.home_offset_episodes is None:
            measured = self.mode == "paper" and self.home_offset_m is None
            episodes = DEFAULT_HOME_OFFSET_EPISODES if measured else 0
            object.__setattr__(self, "home_offset_episodes", episodes)
        if self.home_offset_centre is None:
            object.__setattr__(self, "home_offset_centre", bool(self.home_offset_episodes))
        for name, minimum in _INT_FIELDS.items():
            object.__setattr__(self, name, int_at_least(name, getattr(self, name), minimum))
        for name, maximum in (("n_envs", MAX_N_ENVS), ("home_offset_places", MAX_PLACES)):
            if getattr(self, name) > maximum:
                raise ValueError(f"{name} must be at most {maximum}, got {getattr(self, name)}")
        for name in _POSITIVE_FIELDS:
            object.__setattr__(self, name, positive_float(name, getattr(self, name)))
        for name in ("closeness_bonus", "min_walk_m"):
            object.__setattr__(self, name, nonnegative_float(name, getattr(self, name)))
        if self.expert_speed_m_s > self.max_forward:
            raise ValueError(
                f"expert_speed_m_s ({self.expert_speed_m_s}) must be at most max_forward "
                f"({self.max_forward}), the speed of a full walk action"
            )
        object.__setattr__(self, "log_std_init", finite_real("log_std_init", self.log_std_init))
        if self.confirm_stop_m is not None:
            object.__setattr__(
                self, "confirm_stop_m", positive_float("confirm_stop_m", self.confirm_stop_m)
            )
        gamma = finite_real("gamma", self.gamma)
        if not (0 < gamma <= 1):
            raise ValueError(f"gamma must be in (0, 1], got {self.gamma!r}")
        object.__setattr__(self, "gamma", gamma)
        for name in ("previous_action", "home_offset_centre", "position_std"):
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
        # the optional env settings appear only when they change the env: a config.json
        # without those fields then has the same "env", which from_dict checks
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
        if self.position_std:
            checked["position_std"] = True
        return {
            "scene": self.scene,
            "learn_time_s": self.learn_time_s,
            "stop_time_s": self.stop_time_s,
            "success_radius_m": self.success_radius_m,
            "max_homing_s": self.max_homing_s,
            "max_forward": self.max_forward,
            "max_turn_deg_s": self.max_turn_deg_s,
            "tracker": _plain_copy(self.tracker),
            **homing_mode(self.mode).learning,
            **checked,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrainConfig:
        """Inverse of :meth:`to_dict`; unknown keys or another schema are errors.

        A field missing from a saved config reads as the value that turns its feature
        off (final stops, no closeness bonus or minimum walk, no previous action, the
        tracker's home, lockstep rollouts, the paper's mode, no position spread), not as
        the field's default; each field of
        :class:`TrainConfig` says which.
        """
        data = dict(data)
        schema = data.pop("schema", None)
        if schema not in (1, CONFIG_SCHEMA):  # schema 1 has no "env" (derived from the rest)
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
        data.setdefault("mode", "paper")
        data.setdefault("position_std", False)
        data.setdefault("expert_speed_m_s", 0.25)
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



def check_names(config: TrainConfig) -> None:
    """Refuse an unregistered scene or tracker of ``config`` with a clear ``ValueError``.

    Builds the tracker once (a ``{"type": ...}`` dict's arguments are checked by its
    constructor); an import path is imported. A config read from a file passed
    :func:`read_train_config`'s checks first, which admit import paths only with
    ``allow_imports``.
    """
    check_scene_name(config.scene)
    make_tracker(config.tracker)



def read_train_config(
    path: str | os.PathLike, allow_imports: bool = False, **overrides: Any
) -> TrainConfig:
    """A :class:`TrainConfig` from a YAML or JSON file of its fields, with ``overrides``
    on top. Any subset of the fields: the others take their defaults. A ``config.json``
    written by :func:`~vc_gym.training.train.train` works too (it has a ``schema``; a
    field it lacks reads as :meth:`TrainConfig.from_dict` says).

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
        if "schema" in data:  # a run's config.json: missing fields read as from_dict says
            data.pop("env", None)  # derived from the fields (a --config file overrides them)
            return TrainConfig.from_dict(data)
        return TrainConfig.from_settings(data)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}") from None

