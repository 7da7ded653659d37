"""Learned homing agents: stable-baselines3 policies on the compass' outputs (paper 5.2).

A learned agent sees what :class:`~vc_gym.envs.CompassObservation` adds (the tracker's
heading and position estimates, the spots' goodness), never the camera frame or the
true pose: it acts on ``vc_gym/Homing-v0`` (:mod:`vc_gym.envs.homing`). Training lives
in :mod:`vc_gym.training.train` (``vc-gym train``); this module loads what it
wrote.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np

from vc_gym.config_files import read_settings
from vc_gym.localization.registry import TRACKERS
from vc_gym.plugins import check_file_spec, check_plain_data
from vc_gym.sim.scenes.registry import check_scene_name
from vc_gym.training.algorithms import ALGORITHMS, algorithm_class
from vc_gym.training.safe_load import UnsafeModelError, load_sb3_model

__all__ = [
    "ALGORITHMS",
    "CONFIG_ENV_KEYS",
    "ENV_KEYS",
    "PRETRAINED_MODEL",
    "LearnedHomingAgent",
    "algorithm_class",
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
)

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
    if not isinstance(env, dict) or not all(isinstance(k, str) for k in env):
        raise ValueError(f"{path}: 'env' must be a dict of Homing-v0 arguments")
    unknown = sorted(set(env) - set(CONFIG_ENV_KEYS))
    if unknown:
        raise ValueError(
            f"{path}: field 'env' names {unknown}, which an agent's config may not set "
            f"(accepted: {list(CONFIG_ENV_KEYS)})"
        )
    check_plain_data(env, f"{path}: field 'env'")
    if "scene" in env:
        try:
            check_scene_name(env["scene"])
        except ValueError as exc:
            raise ValueError(f"{path}: field 'env.scene': {exc}") from None
    if "tracker" in env:
        check_file_spec(
            env["tracker"], TRACKERS, "tracker", f"{path}: field 'env.tracker'", allow_imports
        )
    return algo, env


class LearnedHomingAgent:
    """A trained homing agent, loaded from ``DIR/model.zip`` and ``DIR/config.json``.

    It acts in ``vc_gym/Homing-v0`` (:attr:`env_id`) with the settings it was trained
    with (:attr:`env_kwargs`, from ``config.json``); whoever runs it builds that env and
    asks for :meth:`policy`.

    Parameters
    ----------
    model_path : path
        The ``model.zip`` written by :func:`vc_gym.training.train.train`.
    allow_imports : bool
        Let the ``config.json`` name a tracker by import path (``"module:attr"``), which
        imports that module: only for files you trust (:func:`read_agent_config`).
    """

    #: The registered env the agent acts in.
    env_id: ClassVar[str] = "vc_gym/Homing-v0"
    #: What it observes: ``vc_gym/Homing-v0``'s feature vector.
    observation: ClassVar[str] = "features"

    def __init__(self, model_path: str | os.PathLike, allow_imports: bool = False):
        path = Path(model_path)
        if path.suffix != ".zip" or not path.is_file():
            raise ValueError(f"{path}: not a model file (expected DIR/model.zip from train)")
        cfg_path = path.with_name("config.json")
        if not cfg_path.is_file():
            raise ValueError(f"{cfg_path}: missing (train writes it next to the model)")
        self.algo, self.env_kwargs = read_agent_config(cfg_path, allow_imports)
        try:
            # never unpickles: a model file from anyone cannot run code here
            self.model = load_sb3_model(self.algo, path, device="cpu")
        except UnsafeModelError as exc:
            raise UnsafeModelError(f"cannot load the {self.algo} model: {exc}") from None
        except Exception as exc:  # SB3 raises many kinds on a corrupt zip
            raise ValueError(f"{path}: cannot load the {self.algo} model: {exc}") from exc
        self.path = path
        #: The ``config.json`` the agent's settings came from.
        self.config_path = cfg_path

    @property
    def scene(self) -> str:
        """The scene the agent was trained in."""
        return str(self.env_kwargs.get("scene", "robolab"))

    def policy(self, env: gym.Env) -> LearnedHomingAgent:
        """The policy acting in ``env`` (built from :attr:`env_id` and :attr:`env_kwargs`):
        the loaded model itself."""
        return self

    def reset(self) -> None:
        """Start of an episode (the policy keeps no state between decisions)."""

    def predict(self, obs: np.ndarray) -> np.ndarray:
        """Deterministic action for one feature vector."""
        action, _ = self.model.predict(obs, deterministic=True)
        return action
