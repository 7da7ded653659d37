"""Loading a stable-baselines3 ``model.zip`` without running code from it.

stable-baselines3 keeps part of a model as cloudpickled objects in the zip's ``data``
entry (the policy class, the spaces, the schedules, episode buffers) and unpickles them
on ``load``: a ``model.zip`` from someone else can run any code it likes. Its tensors
are already read with ``torch.load(weights_only=True)``. :func:`load_sb3_model` reads
``data`` as plain JSON first and hands ``load`` a known object for *every* pickled
entry, rebuilt from the entry's plain description (a Box's shape and bounds, a constant
schedule's value) or a fresh default, so nothing is ever unpickled. Anything it does not
know, or that does not describe a ``vc_gym/Homing-v0`` agent, is refused.

Plain entries of ``data`` choose things too: SB3 copies every key onto the model
(``"env": "module:Id-v0"`` would make it call ``gym.make``, which imports the module;
``n_steps`` sizes the rollout buffer; ``policy_kwargs.net_arch`` sizes the networks).
So only the keys a PPO or SAC homing agent needs are passed on (:data:`PLAIN_FIELDS`),
each checked against its type and bounds; any other key is dropped unread. The
network's layer sizes must match the shapes of the weights in ``policy.pth``, read
with ``torch.load(weights_only=True)`` before any network is built.
"""

from __future__ import annotations

import io
import json
import math
import os
import re
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.persistence import zip_entries_problem

__all__ = [
    "MAX_DATA_BYTES",
    "MAX_ENTRY_BYTES",
    "MAX_LAYERS",
    "MAX_LAYER_WIDTH",
    "MAX_MODEL_BYTES",
    "PLAIN_FIELDS",
    "UnsafeModelError",
    "check_net_arch",
    "load_sb3_model",
    "model_algo",
]

#: Largest uncompressed size of one entry of a model zip, and of all entries together.
MAX_ENTRY_BYTES = 64_000_000
MAX_MODEL_BYTES = 256_000_000
#: Largest ``data`` entry (JSON; a trained agent's is about 20 kB).
MAX_DATA_BYTES = 1_000_000
#: Hidden layers of a policy or value network, and units per layer, at most (a
#: 8 x 4096 MLP holds about 130 M weights, 0.5 GB).
MAX_LAYERS = 8
MAX_LAYER_WIDTH = 4096
#: Parallel envs, rollout steps per env and replay-buffer transitions a loaded model
#: may ask for (they size the buffers built on load).
MAX_ENVS = 64
MAX_ROLLOUT = 2**16
MAX_REPLAY = 2_000_000
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


def _constant_schedule(entry: dict[str, Any], name: str) -> float:
    """A ``ConstantSchedule`` (what the RL Zoo saves as ``learning_rate``) as its value."""
    if entry.get(":type:") != "<class 'stable_baselines3.common.utils.ConstantSchedule'>":
        raise UnsafeModelError(f"{name}: only a constant schedule can be loaded safely")
    try:
        value = float(str(entry.get("val")))
    except ValueError:
        raise UnsafeModelError(f"{name}: its value is not a number") from None
    if not (math.isfinite(value) and 0.0 < value <= 1.0):
        raise UnsafeModelError(f"{name}: {value} is out of bounds")
    return value


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
        "learning_rate": _constant_schedule,  # the RL Zoo's
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


def _int(lo: int, hi: int) -> Callable[[Any], bool]:
    return lambda v: isinstance(v, int) and not isinstance(v, bool) and lo <= v <= hi


def _float(lo: float, hi: float) -> Callable[[Any], bool]:
    def check(v: Any) -> bool:
        number = isinstance(v, int | float) and not isinstance(v, bool)
        return number and math.isfinite(v) and lo <= v <= hi

    return check


def _bool(v: Any) -> bool:
    return isinstance(v, bool)


def _none(v: Any) -> bool:
    return v is None


def _either(*checks: Callable[[Any], bool]) -> Callable[[Any], bool]:
    return lambda v: any(c(v) for c in checks)


_COUNT = _int(0, 10**12)
_AUTO = re.compile(r"^auto(_[0-9.eE+-]{1,20})?$")
#: The plain (not pickled) ``data`` keys passed on to SB3, each with its check. Every
#: other plain key is dropped unread.
PLAIN_FIELDS: dict[str, Callable[[Any], bool]] = {
    # every algorithm
    "verbose": _int(0, 2),
    "num_timesteps": _COUNT,
    "_total_timesteps": _COUNT,
    "_num_timesteps_at_start": _COUNT,
    "seed": _either(_none, _int(-(2**63), 2**64)),
    "action_noise": _none,
    "start_time": _either(_int(0, 2**64), _float(0.0, 2.0**64)),
    "learning_rate": _float(0.0, 1.0),
    "_episode_num": _COUNT,
    "use_sde": _bool,
    "sde_sample_freq": _int(-1, 10**9),
    "_current_progress_remaining": _float(-1.0, 1.0),
    "_stats_window_size": _int(1, 10_000),
    "_n_updates": _COUNT,
    "n_envs": _int(1, MAX_ENVS),
    "gamma": _float(0.0, 1.0),
    "batch_size": _int(1, MAX_ROLLOUT),
    "n_steps": _int(1, MAX_ROLLOUT),
    # PPO
    "gae_lambda": _float(0.0, 1.0),
    "ent_coef": _either(_float(0.0, 1e3), lambda v: isinstance(v, str) and _AUTO.match(v)),
    "vf_coef": _float(0.0, 1e3),
    "max_grad_norm": _float(0.0, 1e6),
    "rollout_buffer_kwargs": lambda v: v == {},
    "n_epochs": _int(1, 1000),
    "clip_range_vf": _either(_none, _float(0.0, 1e3)),
    "normalize_advantage": _bool,
    "target_kl": _either(_none, _float(0.0, 1e3)),
    # SAC
    "buffer_size": _int(1, MAX_REPLAY),
    "learning_starts": _COUNT,
    "tau": _float(0.0, 1.0),
    "gradient_steps": _int(-1, 10_000),
    "optimize_memory_usage": _bool,
    "replay_buffer_kwargs": lambda v: v == {},
    "use_sde_at_warmup": _bool,
    "target_entropy": _either(_float(-1e6, 1e6), lambda v: v == "auto"),
    "target_update_interval": _int(1, 10**6),
    "batch_norm_stats": lambda v: v == [],
    "batch_norm_stats_target": lambda v: v == [],
    # checked on their own (check_net_arch)
    "policy_kwargs": lambda v: isinstance(v, dict),
}
#: ``policy_kwargs`` keys a loaded model may set.
_POLICY_KWARGS = {
    "ppo": {"net_arch", "log_std_init", "use_sde"},
    "sac": {"net_arch", "log_std_init", "use_sde", "n_critics"},
}


def check_net_arch(net_arch: Any, heads: tuple[str, ...] = ("pi", "vf")) -> dict[str, list[int]]:
    """The hidden layers of each network in ``net_arch`` (SB3's list, or a dict by head).

    Parameters
    ----------
    net_arch : list of int or dict
        ``[64, 64]`` (the same layers for every head) or ``{"pi": [...], "vf": [...]}``
        (SAC: ``"qf"`` for the critic).
    heads : tuple of str
        The algorithm's heads.

    Raises
    ------
    ValueError
        Layers that are not positive integers, more than :data:`MAX_LAYERS` of them or
        wider than :data:`MAX_LAYER_WIDTH`, or a dict with other keys.
    """

    def layers(v: Any, what: str) -> list[int]:
        if not isinstance(v, list | tuple) or len(v) > MAX_LAYERS:
            raise ValueError(
                f"{what} must be a list of at most {MAX_LAYERS} layer sizes, got {v!r}"
            )
        for n in v:
            if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_LAYER_WIDTH:
                raise ValueError(
                    f"{what}: layer sizes must be integers from 1 to {MAX_LAYER_WIDTH}, got {n!r}"
                )
        return list(v)

    if isinstance(net_arch, dict):
        if set(net_arch) != set(heads):
            raise ValueError(
                f"net_arch as a dict must have the keys {list(heads)}, got {net_arch!r}"
            )
        return {h: layers(net_arch[h], f"net_arch[{h!r}]") for h in heads}
    arch = layers(net_arch, "net_arch")
    return {h: list(arch) for h in heads}


def _mlp_shapes(prefix: str, n_in: int, hidden: list[int], n_out: int | None) -> dict:
    """The parameter shapes of SB3's ``create_mlp`` (Linear layers at even indices)."""
    shapes: dict[str, tuple[int, ...]] = {}
    sizes = [n_in, *hidden] + ([n_out] if n_out is not None else [])
    for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:], strict=True)):
        shapes[f"{prefix}.{2 * i}.weight"] = (b, a)
        shapes[f"{prefix}.{2 * i}.bias"] = (b,)
    return shapes


def _expected_shapes(algo: str, arch: dict[str, list[int]], n_obs: int, n_act: int, n_critics: int):
    """Every parameter of an SB3 ``MlpPolicy`` and its shape, from the sizes alone."""
    if algo == "ppo":
        pi, vf = arch["pi"], arch["vf"]
        last_pi, last_vf = (pi or [n_obs])[-1], (vf or [n_obs])[-1]
        return {
            "log_std": (n_act,),
            **_mlp_shapes("mlp_extractor.policy_net", n_obs, pi, None),
            **_mlp_shapes("mlp_extractor.value_net", n_obs, vf, None),
            "action_net.weight": (n_act, last_pi),
            "action_net.bias": (n_act,),
            "value_net.weight": (1, last_vf),
            "value_net.bias": (1,),
        }
    pi, qf = arch["pi"], arch["qf"]
    last_pi = (pi or [n_obs])[-1]
    shapes = {
        **_mlp_shapes("actor.latent_pi", n_obs, pi, None),
        "actor.mu.weight": (n_act, last_pi),
        "actor.mu.bias": (n_act,),
        "actor.log_std.weight": (n_act, last_pi),
        "actor.log_std.bias": (n_act,),
    }
    for net in ("critic", "critic_target"):
        for k in range(n_critics):
            shapes.update(_mlp_shapes(f"{net}.qf{k}", n_obs + n_act, qf, 1))
    return shapes


def _tensor_files(path: Path) -> dict[str, Any]:
    """Every ``.pth`` entry of the zip, read with ``torch.load(weights_only=True)``: no
    code runs, and a file that is not plain tensors and numbers is refused here, in our
    words (torch's own message would suggest ``weights_only=False``, which runs code)."""
    import torch

    loaded: dict[str, Any] = {}
    try:
        with zipfile.ZipFile(path) as z:
            raws = {n: z.read(n) for n in z.namelist() if n.endswith(".pth")}
    except Exception as exc:  # noqa: BLE001 - a bad CRC, a broken deflate stream, ...
        raise UnsafeModelError(f"its tensor files cannot be read: {exc}") from None
    for name, raw in raws.items():
        try:
            loaded[name] = torch.load(io.BytesIO(raw), map_location="cpu", weights_only=True)
        except Exception as exc:  # noqa: BLE001 - torch raises many kinds on a bad file
            raise UnsafeModelError(
                f"{name!r} is not plain tensors and cannot be loaded safely "
                f"({type(exc).__name__})"
            ) from None
    return loaded


def _weight_shapes(path: Path) -> dict[str, tuple[int, ...]]:
    """The shape of every tensor in the zip's ``policy.pth`` (see :func:`_tensor_files`)."""
    state = _tensor_files(path).get("policy.pth")
    if not isinstance(state, dict) or not all(hasattr(v, "shape") for v in state.values()):
        raise UnsafeModelError("'policy.pth' is not a dict of tensors")
    return {str(k): tuple(v.shape) for k, v in state.items()}


def _plain_data(algo: str, data: dict[str, Any], path: Path) -> dict[str, Any]:
    """The plain keys of ``data`` that are passed on, each checked; the network checked
    against the weights' shapes."""
    kept: dict[str, Any] = {}
    for key, value in data.items():
        if isinstance(value, dict) and ":serialized:" in value:
            kept[key] = value  # replaced by a known object (custom_objects) or refused
        elif key in PLAIN_FIELDS:
            if not PLAIN_FIELDS[key](value):
                raise UnsafeModelError(f"'data' field {key!r} = {value!r} is out of bounds")
            kept[key] = value
    kwargs = kept.get("policy_kwargs", {})
    extra = set(kwargs) - _POLICY_KWARGS[algo]
    if extra:
        raise UnsafeModelError(f"'data' field 'policy_kwargs' sets {sorted(extra)}")
    if "log_std_init" in kwargs and not _float(-20.0, 20.0)(kwargs["log_std_init"]):
        raise UnsafeModelError("'data' field 'policy_kwargs.log_std_init' is out of bounds")
    n_critics = kwargs.get("n_critics", 2)
    if not _int(1, 10)(n_critics):
        raise UnsafeModelError("'data' field 'policy_kwargs.n_critics' is out of bounds")
    if "use_sde" in kwargs and not _bool(kwargs["use_sde"]):
        raise UnsafeModelError("'data' field 'policy_kwargs.use_sde' is not a bool")
    if kwargs.get("use_sde") or kept.get("use_sde"):
        raise UnsafeModelError("generalised state-dependent exploration (use_sde) is not ours")
    heads = ("pi", "vf") if algo == "ppo" else ("pi", "qf")
    default = [64, 64] if algo == "ppo" else [256, 256]
    try:
        arch = check_net_arch(kwargs.get("net_arch", default), heads)
    except ValueError as exc:
        raise UnsafeModelError(f"'data' field 'policy_kwargs': {exc}") from None
    shapes = {}
    for name in ("observation_space", "action_space"):
        shape = data.get(name, {}).get("_shape") if isinstance(data.get(name), dict) else None
        if not (isinstance(shape, list) and len(shape) == 1 and _int(1, 4096)(shape[0])):
            raise UnsafeModelError(f"{name}: not the Box a vc_gym/Homing-v0 agent uses")
        shapes[name] = shape[0]
    expected = _expected_shapes(
        algo, arch, shapes["observation_space"], shapes["action_space"], n_critics
    )
    got = _weight_shapes(path)
    if got != expected:
        wrong = sorted(k for k in set(got) | set(expected) if got.get(k) != expected.get(k))
        raise UnsafeModelError(
            f"the weights in 'policy.pth' do not match the network 'data' describes "
            f"(policy_kwargs {kwargs!r}): {len(wrong)} tensors differ, e.g. {wrong[:3]}"
        )
    return kept


def _sanitised_zip(path: Path, data: dict[str, Any]) -> io.BytesIO:
    """A copy of the model zip in memory whose ``data`` holds only ``data``."""
    buf = io.BytesIO()
    with zipfile.ZipFile(path) as zin, zipfile.ZipFile(buf, "w") as zout:
        for info in zin.infolist():
            content = json.dumps(data).encode() if info.filename == "data" else zin.read(info)
            zout.writestr(info.filename, content)
    buf.seek(0)
    return buf


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
            if z.getinfo("data").file_size > MAX_DATA_BYTES:
                raise UnsafeModelError(f"its 'data' entry is larger than {MAX_DATA_BYTES} bytes")
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
        that is not constant, a plain field out of its bounds (:data:`PLAIN_FIELDS`), a
        network that does not match its weights or is larger than :data:`MAX_LAYERS` x
        :data:`MAX_LAYER_WIDTH`, unexpected zip entries, or sizes beyond
        :data:`MAX_DATA_BYTES` / :data:`MAX_ENTRY_BYTES` / :data:`MAX_MODEL_BYTES`.
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
        plain = _plain_data(algo, data, p)
    except UnsafeModelError as exc:
        raise UnsafeModelError(f"{p}: {exc}; not loaded") from None
    return cls.load(_sanitised_zip(p, plain), env=env, device=device, custom_objects=custom)


def model_algo(path: str | os.PathLike) -> str:
    """Which algorithm wrote a ``model.zip``: ``"ppo"`` or ``"sac"``, told by the names of
    the tensors in its ``policy.pth`` (read with ``torch.load(weights_only=True)``, after
    the zip's entries are checked as for :func:`load_sb3_model`).

    Raises
    ------
    UnsafeModelError
        Naming the file: not a readable model zip, or weights of neither algorithm's
        ``MlpPolicy``.
    """
    p = Path(path)
    try:
        _checked_data(p)
        names = set(_weight_shapes(p))
    except UnsafeModelError as exc:
        raise UnsafeModelError(f"{p}: {exc}") from None
    if {"action_net.weight", "value_net.weight", "log_std"} <= names:
        return "ppo"
    if {"actor.mu.weight", "actor.log_std.weight"} <= names and any(
        n.startswith("critic.qf0.") for n in names
    ):
        return "sac"
    raise UnsafeModelError(f"{p}: the weights are neither a PPO nor a SAC MlpPolicy's")
