"""Learned homing agents: stable-baselines3 policies on the compass' outputs (paper 5.2).

A learned agent sees what :class:`~vc_gym.envs.CompassObservation` adds (the tracker's
heading and position estimates, the spots' goodness), never the camera frame or the
true pose: it acts on ``vc_gym/Homing-v0`` (:mod:`vc_gym.envs.homing`). Training lives
in :mod:`vc_gym.training.train` (``vc-gym train``); this module loads what it
wrote, and any stable-baselines3 PPO or SAC model trained on ``vc_gym/Homing-v0``: one
saved by the RL Baselines3 Zoo (its run folder says how the env was set up) or alone
(the settings then come from the caller, and the model's spaces are checked against
the env's).
"""

from __future__ import annotations

import inspect
import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from vc_gym.config_files import read_settings
from vc_gym.envs.homing import HomingEnv, HomingFeatures, PreviousAction
from vc_gym.envs.learn_then_home import LearnThenHomeEnv
from vc_gym.envs.learning import LearningConfig, scripted_atlas_size
from vc_gym.localization.registry import TRACKERS
from vc_gym.plugins import check_file_spec, check_plain_data
from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.sim.scenes.registry import check_scene_name
from vc_gym.training.algorithms import ALGORITHMS, algorithm_class
from vc_gym.training.safe_load import UnsafeModelError, load_sb3_model, model_algo
from vc_gym.training.zoo_run import find_zoo_run

__all__ = [
    "ALGORITHMS",
    "CONFIG_ENV_KEYS",
    "ENV_KEYS",
    "PRETRAINED_MODEL",
    "PLACE_KEYS",
    "LearnedHomingAgent",
    "algorithm_class",
    "check_agent_env_kwargs",
    "homing_spaces",
    "parse_env_kwargs",
    "read_agent_config",
]

#: Keys of a schema-1 ``config.json`` that are ``vc_gym/Homing-v0`` arguments (schema 2
#: stores them under ``"env"``).
ENV_KEYS = (
    "scene",
    "learn_time_s",
    "stop_time_s",
    "success_radius_m",
    "max_homing_s",
    "max_forward",
    "max_turn_deg_s",
)

#: Every ``vc_gym/Homing-v0`` argument an agent's ``config.json`` may set: what
#: ``TrainConfig.env_kwargs`` writes. A file naming any other (a learner, an atlas file,
#: a render mode) is refused before an env is built.
CONFIG_ENV_KEYS = (
    *ENV_KEYS,
    "tracker",
    "confirm_stop_m",
    "closeness_bonus",
    "min_walk_m",
    "home_offset_m",
    "previous_action",
    "min_walk_s",
    "head_scan",
    "position_std",
    "normalise_at",
    "around_m",
    "landmarks",
)

#: ``vc_gym/Homing-v0`` arguments that choose the place a run trained in. An evaluation
#: learns its own places (its seeds), so a Zoo run's values of these are not used.
PLACE_KEYS = ("learning_seed", "atlas_file", "place_cache")

#: The PPO policy shipped with the package (trained by ``vc-gym train``, see README);
#: ``vc-gym evaluate --agent pretrained`` evaluates it.
PRETRAINED_MODEL = Path(__file__).parent / "pretrained" / "ppo_robolab" / "model.zip"


def read_agent_config(path: Path, allow_imports: bool = False) -> tuple[str, dict[str, Any]]:
    """``(algo, Homing-v0 kwargs)`` from a training run's ``config.json``.

    The file is read with the bounded settings reader (size, depth, repeated keys), and
    what it says is checked before anything is built from it: only the env arguments of
    :data:`CONFIG_ENV_KEYS`, as plain data; a registered scene; a registered tracker
    (a name or ``{"type": name, ...}``), an import path only with ``allow_imports``
    (the person at the keyboard's choice, :func:`vc_gym.plugins.check_file_spec`).

    Raises
    ------
    ValueError
        Naming the file and the field.
    """
    data = read_settings(path)
    if data.get("schema") not in (1, 2):
        raise ValueError(f"{path}: not a vc_gym training config (schema 1 or 2)")
    algo = data.get("algo")
    if algo not in ALGORITHMS:
        raise ValueError(f"{path}: algo must be one of {ALGORITHMS}, got {algo!r}")
    env = data.get("env") if data["schema"] == 2 else {k: data[k] for k in ENV_KEYS if k in data}
    return algo, check_agent_env_kwargs(env, str(path), "env", allow_imports)


def _homing_arguments() -> set[str]:
    """Every keyword ``vc_gym/Homing-v0`` takes (its own, the task's, the room's)."""
    names: set[str] = set()
    for cls in (HomingEnv, LearnThenHomeEnv, AiboRoomEnv):
        names |= {
            n
            for n, p in inspect.signature(cls).parameters.items()
            if p.kind is not inspect.Parameter.VAR_KEYWORD
        }
    return names


def check_agent_env_kwargs(
    env: Any, source: str, field: str | None = None, allow_imports: bool = False
) -> dict[str, Any]:
    """The ``vc_gym/Homing-v0`` arguments of an agent, checked before any env is built.

    Only the arguments of :data:`CONFIG_ENV_KEYS`, as plain data; a registered scene; a
    registered tracker (a name or ``{"type": name, ...}``), an import path only with
    ``allow_imports`` (:func:`vc_gym.plugins.check_file_spec`).

    Parameters
    ----------
    env : mapping
        The arguments.
    source : str
        Where they come from (a file, or a command-line flag), for errors.
    field : str, optional
        The field of ``source`` that holds them.
    allow_imports : bool
        Accept a tracker named by import path.

    Raises
    ------
    ValueError
        Naming ``source`` and the field: not a mapping with text keys, an argument that is not
        one of ``vc_gym/Homing-v0``'s, one an agent may not set, or a value refused.
    """
    where = f"{source}: field '{field}'" if field else source

    def at(key: str) -> str:
        return f"{source}: field '{field}.{key}'" if field else f"{source}: '{key}'"

    if not isinstance(env, Mapping) or not all(isinstance(k, str) for k in env):
        raise ValueError(f"{where}: must be a dict of Homing-v0 arguments")
    env = dict(env)
    unknown = sorted(set(env) - _homing_arguments())
    if unknown:
        raise ValueError(f"{where}: {unknown} are not arguments of vc_gym/Homing-v0")
    refused = sorted(set(env) - set(CONFIG_ENV_KEYS))
    if refused:
        raise ValueError(
            f"{where}: names {refused}, which an agent's settings may not set "
            f"(accepted: {list(CONFIG_ENV_KEYS)})"
        )
    check_plain_data(env, where)
    if "scene" in env:
        try:
            check_scene_name(env["scene"])
        except ValueError as exc:
            raise ValueError(f"{at('scene')}: {exc}") from None
    if "tracker" in env:
        check_file_spec(env["tracker"], TRACKERS, "tracker", at("tracker"), allow_imports)
    return env


def parse_env_kwargs(pairs: Sequence[str], where: str = "--env-kwargs") -> dict[str, Any]:
    """``["key=value", ...]`` as a dict: each value read as JSON (``0.25``, ``true``,
    ``[0.1, 0.0]``, ``"office"``), else as the text itself; ``True``/``False``/``None``
    are read as Python spells them. Nothing is evaluated.

    Raises
    ------
    ValueError
        For an item without ``=``, an empty or repeated key.
    """
    out: dict[str, Any] = {}
    for item in pairs:
        key, sep, text = str(item).partition("=")
        key = key.strip()
        if not sep or not key:
            raise ValueError(f"{where}: expected key=value, got {item!r}")
        if key in out:
            raise ValueError(f"{where}: {key!r} is given twice")
        literals = {"True": True, "False": False, "None": None}
        if text in literals:
            out[key] = literals[text]
            continue
        try:
            out[key] = json.loads(text)
        except ValueError:
            out[key] = text
    return out


def homing_spaces(env_kwargs: Mapping[str, Any]) -> tuple[spaces.Box, spaces.Box]:
    """The observation and action spaces of ``vc_gym/Homing-v0`` with ``env_kwargs``,
    without building it: the features (:class:`~vc_gym.envs.HomingFeatures`) of the
    scripted learning's atlas (four spots, or 25 entries with ``around_m``), the
    position's spread with ``position_std``, the last action with ``previous_action``."""
    # LearningConfig checks around_m (a number of metres, at most half the spot distance)
    n_spots = scripted_atlas_size(LearningConfig(around_m=env_kwargs.get("around_m", 0.0)))
    n = HomingFeatures.GOODNESS_START + 1 + n_spots
    if env_kwargs.get("position_std", False):
        n += HomingFeatures.POSITION_STD_WIDTH
    if env_kwargs.get("previous_action", False):
        n += PreviousAction.WIDTH
    return (
        spaces.Box(-10.0, 10.0, (n,), np.float32),
        spaces.Box(-1.0, 1.0, (3,), np.float32),
    )


def _same_box(a: Any, b: spaces.Box) -> bool:
    return (
        isinstance(a, spaces.Box)
        and a.shape == b.shape
        and np.array_equal(a.low, b.low)
        and np.array_equal(a.high, b.high)
    )


class LearnedHomingAgent:
    """A trained homing agent: a stable-baselines3 PPO or SAC ``model.zip`` trained on
    ``vc_gym/Homing-v0``.

    It acts in ``vc_gym/Homing-v0`` (:attr:`env_id`) with the settings it was trained
    with (:attr:`env_kwargs`); whoever runs it builds that env and asks for
    :meth:`policy`. The settings come from, in this order:

    1. ``config.json`` beside the model (written by ``vc-gym train``);
    2. the RL Baselines3 Zoo run the model belongs to (``RUN/vc_gym-Homing-v0/config.yml``
       and ``args.yml`` beside ``RUN/vc_gym-Homing-v0.zip``,
       :mod:`vc_gym.training.zoo_run`): its ``env_kwargs``, less those that choose the
       training's place (:data:`PLACE_KEYS`);
    3. nothing else (a model saved by ``model.save`` alone): the env's defaults; its
       algorithm is told by its weights.

    ``env_kwargs`` given here go on top. The model's spaces, stored in its zip, must be
    the env's: ``previous_action`` is read from the length of its observations when no
    setting names it, and a model whose spaces the env cannot give is refused.

    Parameters
    ----------
    model_path : path
        The ``model.zip``.
    allow_imports : bool
        Let the settings name a tracker by import path (``"module:attr"``), which
        imports that module: only for files you trust (:func:`read_agent_config`).
    env_kwargs : mapping, optional
        ``vc_gym/Homing-v0`` arguments on top of the saved ones (checked as
        :func:`check_agent_env_kwargs` does).

    Raises
    ------
    ValueError
        Naming the file or setting: a model that cannot be loaded safely
        (:class:`~vc_gym.training.safe_load.UnsafeModelError`), settings refused, or
        spaces that do not match.
    """

    #: The registered env the agent acts in.
    env_id: ClassVar[str] = "vc_gym/Homing-v0"
    #: What it observes: ``vc_gym/Homing-v0``'s feature vector.
    observation: ClassVar[str] = "features"

    def __init__(
        self,
        model_path: str | os.PathLike,
        allow_imports: bool = False,
        env_kwargs: Mapping[str, Any] | None = None,
    ):
        path = Path(model_path)
        if path.suffix != ".zip" or not path.is_file():
            raise ValueError(f"{path}: not a model file (expected a stable-baselines3 .zip)")
        cfg_path = path.with_name("config.json")
        zoo = None if cfg_path.is_file() else find_zoo_run(path)
        if cfg_path.is_file():
            #: Where the settings came from: vc-gym train's config.json, a Zoo run's
            #: config.yml, or the model itself.
            self.settings_source = "vc-gym train"
            self.algo, saved = read_agent_config(cfg_path, allow_imports)
        elif zoo is not None:
            self.settings_source = "rl-zoo"
            cfg_path = zoo.config_path
            if zoo.algo not in ALGORITHMS:
                raise ValueError(
                    f"{zoo.folder / 'args.yml'}: algo {zoo.algo!r}; vc_gym loads {ALGORITHMS}"
                )
            self.algo = zoo.algo
            own = {k: v for k, v in zoo.env_kwargs.items() if k not in PLACE_KEYS}
            saved = check_agent_env_kwargs(own, str(cfg_path), "env_kwargs", allow_imports)
        else:
            self.settings_source = "model"
            cfg_path = path
            try:
                self.algo, saved = model_algo(path), {}
            except UnsafeModelError as exc:
                raise UnsafeModelError(
                    f"cannot load the model, which has no config.json (vc-gym train) or RL "
                    f"Zoo run folder beside it to say how it was trained: {exc}"
                ) from None
        given = (
            check_agent_env_kwargs(env_kwargs, "env_kwargs", None, allow_imports)
            if env_kwargs
            else {}
        )
        self.env_kwargs = {**saved, **given}
        try:
            # never unpickles: a model file from anyone cannot run code here
            self.model = load_sb3_model(self.algo, path, device="cpu")
        except UnsafeModelError as exc:
            raise UnsafeModelError(f"cannot load the {self.algo} model: {exc}") from None
        except Exception as exc:  # SB3 raises many kinds on a corrupt zip
            raise ValueError(f"{path}: cannot load the {self.algo} model: {exc}") from exc
        self.path = path
        #: The file the agent's settings came from (``config.json``, a Zoo run's
        #: ``config.yml``, or the model itself).
        self.config_path = cfg_path
        self._check_spaces()

    def _check_spaces(self) -> None:
        """Refuse a model whose spaces ``vc_gym/Homing-v0`` with :attr:`env_kwargs` does
        not have; read ``previous_action`` from the observations' length if unset."""
        obs_space = self.model.observation_space
        if "previous_action" not in self.env_kwargs and isinstance(obs_space, spaces.Box):
            with_action = homing_spaces({"previous_action": True})[0]
            if obs_space.shape == with_action.shape:
                self.env_kwargs["previous_action"] = True
        want_obs, want_act = homing_spaces(self.env_kwargs)
        for what, got, want in (
            ("observation", obs_space, want_obs),
            ("action", self.model.action_space, want_act),
        ):
            if not _same_box(got, want):
                hint = (
                    "; nothing beside the model says how its env was built: give its "
                    "arguments (--env-kwargs, or env_kwargs=; vc-gym train keeps them "
                    "under 'env' in its config.json)"
                    if self.settings_source == "model"
                    else ""
                )
                raise ValueError(
                    f"{self.path}: the model's {what} space is {got}, but vc_gym/Homing-v0 "
                    f"with {self.env_kwargs} has {want}{hint}"
                )

    @property
    def scene(self) -> str:
        """The scene the agent was trained in."""
        return str(self.env_kwargs.get("scene", "robolab"))

    def policy(self, env: gym.Env) -> LearnedHomingAgent:
        """The policy acting in ``env`` (built from :attr:`env_id` and :attr:`env_kwargs`):
        the loaded model itself, once its spaces are checked against ``env``'s.

        Raises
        ------
        ValueError
            If ``env``'s observation or action space is not the model's.
        """
        for what in ("observation_space", "action_space"):
            theirs, ours = getattr(env, what), getattr(self.model, what)
            if not _same_box(theirs, ours):
                raise ValueError(f"{self.path}: the model's {what} is {ours}, the env's {theirs}")
        return self

    def reset(self) -> None:
        """Start of an episode (the policy keeps no state between decisions)."""

    def predict(self, obs: np.ndarray) -> np.ndarray:
        """Deterministic action for one feature vector."""
        action, _ = self.model.predict(obs, deterministic=True)
        return action
