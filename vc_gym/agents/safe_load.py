"""Loading a stable-baselines3 ``model.zip`` without running code from it.

stable-baselines3 keeps part of a model as cloudpickled objects in the zip's ``data``
entry (the policy class, the spaces, the schedules, episode buffers) and unpickles them
on ``load``: a ``model.zip`` from someone else can run any code it likes. Its tensors
are already read with ``torch.load(weights_only=True)``. :func:`load_sb3_model` reads
``data`` as plain JSON first and hands ``load`` a known object for *every* pickled
entry, rebuilt from the entry's plain description (a Box's shape and bounds, a constant
schedule's value) or a fresh default, so nothing is ever unpickled. Anything it does not
know, or that does not describe a ``vc_gym/Homing-v0`` agent, is refused.
"""

from __future__ import annotations

import json
import os
import re
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.persistence import zip_entries_problem

__all__ = ["MAX_ENTRY_BYTES", "MAX_MODEL_BYTES", "UnsafeModelError", "load_sb3_model"]

#: Largest uncompressed size of one entry of a model zip, and of all entries together.
MAX_ENTRY_BYTES = 64_000_000
MAX_MODEL_BYTES = 256_000_000
#: Entries a stable-baselines3 PPO or SAC model zip may hold.
_ENTRIES = {
    "data",
    "policy.pth",
    "pytorch_variables.pth",
    "policy.optimizer.pth",
    "actor.optimizer.pth",
    "critic.optimizer.pth",
    "ent_coef_optimizer.pth",
    "_stable_baselines3_version",
    "system_info.txt",
}
_CONSTANT = re.compile(r"^ConstantSchedule\(val=([-+0-9.eE]+)\)$")


class UnsafeModelError(ValueError):
    """A model file that cannot be loaded without running code from it, or is not ours."""


def _floats(text: Any, what: str) -> np.ndarray:
    if not isinstance(text, str) or len(text) > 10_000:
        raise UnsafeModelError(f"{what} is not a plain list of numbers")
    try:
        return np.array([float(v) for v in text.strip("[]").split()], dtype=np.float64)
    except ValueError:
        raise UnsafeModelError(f"{what} is not a plain list of numbers") from None


def _box(entry: dict[str, Any], name: str, bound: float, sizes: range):
    from gymnasium import spaces

    shape = entry.get("_shape")
    if (
        entry.get(":type:") != "<class 'gymnasium.spaces.box.Box'>"
        or entry.get("dtype") != "float32"
        or not (isinstance(shape, list) and len(shape) == 1 and shape[0] in sizes)
    ):
        raise UnsafeModelError(f"{name}: not the Box a vc_gym/Homing-v0 agent uses")
    low = _floats(entry.get("low"), f"{name}.low")
    high = _floats(entry.get("high"), f"{name}.high")
    if not (np.all(low == -bound) and np.all(high == bound) and low.size == shape[0]):
        raise UnsafeModelError(f"{name}: bounds are not ±{bound}")
    return spaces.Box(-bound, bound, (shape[0],), np.float32)


def _schedule(entry: dict[str, Any], name: str):
    from stable_baselines3.common.utils import ConstantSchedule, FloatSchedule

    m = _CONSTANT.match(str(entry.get("value_schedule", "")))
    if entry.get(":type:") != "<class 'stable_baselines3.common.utils.FloatSchedule'>" or not m:
        raise UnsafeModelError(f"{name}: only a constant schedule can be loaded safely")
    return FloatSchedule(ConstantSchedule(float(m.group(1))))


def _replacements(algo: str) -> dict[str, Callable[[dict[str, Any], str], Any]]:
    from stable_baselines3 import PPO, SAC
    from stable_baselines3.common.buffers import ReplayBuffer, RolloutBuffer
    from stable_baselines3.common.type_aliases import TrainFreq, TrainFrequencyUnit

    cls = {"ppo": PPO, "sac": SAC}[algo]
    return {
        "policy_class": lambda e, n: cls.policy_aliases["MlpPolicy"],
        # Homing-v0: 8 features + one goodness per spot; walk, turn, stop
        "observation_space": lambda e, n: _box(e, n, 10.0, range(9, 1033)),
        "action_space": lambda e, n: _box(e, n, 1.0, range(3, 4)),
        "lr_schedule": _schedule,
        "clip_range": _schedule,
        # training state that learn() rebuilds when it is missing
        "_last_obs": lambda e, n: None,
        "tensorboard_log": lambda e, n: None,  # a Path object: where logs went, not needed
        "_last_episode_starts": lambda e, n: None,
        "_last_original_obs": lambda e, n: None,
        "ep_info_buffer": lambda e, n: None,
        "ep_success_buffer": lambda e, n: None,
        "rollout_buffer_class": lambda e, n: RolloutBuffer,
        "replay_buffer_class": lambda e, n: ReplayBuffer,
        # SAC's default (what vc-gym train uses): one gradient step per env step
        "train_freq": lambda e, n: TrainFreq(1, TrainFrequencyUnit.STEP),
    }


def _checked_data(path: Path) -> dict[str, Any]:
    """The zip's ``data`` entry as plain JSON, after checking every entry's name and size."""
    try:
        with zipfile.ZipFile(path) as z:
            infos = z.infolist()
            problem = zip_entries_problem(infos, MAX_ENTRY_BYTES, MAX_MODEL_BYTES)
            if problem is not None:
                raise UnsafeModelError(problem)
            names = {i.filename for i in infos}
            unknown = names - _ENTRIES
            if unknown or "data" not in names or "policy.pth" not in names:
                raise UnsafeModelError(
                    f"unexpected entries {sorted(unknown)}"
                    if unknown
                    else "no 'data' or 'policy.pth' entry"
                )
            text = z.read("data").decode("utf-8")
    except (OSError, zipfile.BadZipFile, UnicodeDecodeError, KeyError) as exc:
        raise UnsafeModelError(f"not a readable model zip: {exc}") from None
    try:
        data = json.loads(text)
    except (ValueError, RecursionError) as exc:
        raise UnsafeModelError(f"'data' is not JSON: {exc}") from None
    if not isinstance(data, dict):
        raise UnsafeModelError("'data' is not a JSON object")
    return data


def load_sb3_model(
    algo: str, path: str | os.PathLike, env: Any = None, device: str = "cpu", cls: Any = None
):
    """``PPO.load`` / ``SAC.load`` of a vc_gym homing agent, never unpickling anything.

    Parameters
    ----------
    algo : str
        ``"ppo"`` or ``"sac"``.
    path : path-like
        The ``model.zip``.
    env : gymnasium.Env or VecEnv, optional
        Passed to ``load`` (to continue training).
    device : str
        Torch device.
    cls : type, optional
        A subclass of the algorithm's class to load into (a training run's own PPO).

    Raises
    ------
    UnsafeModelError
        (a ``ValueError``) naming the file: an entry that would have to be unpickled and
        that is not one of the known ones, a space that is not Homing-v0's, a schedule
        that is not constant, unexpected zip entries, or sizes beyond
        :data:`MAX_ENTRY_BYTES` / :data:`MAX_MODEL_BYTES`.
    """
    if algo not in ("ppo", "sac"):
        raise ValueError(f"algo must be 'ppo' or 'sac', got {algo!r}")
    from stable_baselines3 import PPO, SAC

    base = {"ppo": PPO, "sac": SAC}[algo]
    if cls is None:
        cls = base
    elif not (isinstance(cls, type) and issubclass(cls, base)):
        raise ValueError(f"cls must be a subclass of {base.__name__}, got {cls!r}")
    p = Path(path)
    try:
        data = _checked_data(p)
        handlers = _replacements(algo)
        custom: dict[str, Any] = {}
        for key, entry in data.items():
            if isinstance(entry, dict) and ":serialized:" in entry:
                if key not in handlers:
                    raise UnsafeModelError(f"{key!r} would have to be unpickled")
                custom[key] = handlers[key](entry, key)
    except UnsafeModelError as exc:
        raise UnsafeModelError(f"{p}: {exc}; not loaded") from None
    return cls.load(p, env=env, device=device, custom_objects=custom)
