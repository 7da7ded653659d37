"""A training run's folder: what it holds, its checkpoints, and where a resume starts.

A run owns its folder: a new run refuses a folder that holds one
(:func:`check_new_run_dir`, :data:`RUN_FILES`), and only a resume continues one.
Checkpoints are ``checkpoints/model_<decisions>_steps.zip`` (:func:`checkpoints`);
:func:`resume_state` checks that the run was started with the same settings and finds
its newest checkpoint that loads and the training episodes logged up to it.
"""

from __future__ import annotations

import json
import numbers
import os
import reprlib
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from vc_gym.training.config import TrainConfig, read_train_config
from vc_gym.training.safe_load import load_sb3_model

__all__ = [
    "CHECKPOINT_PREFIX",
    "MAX_TRAIN_LOG_BYTES",
    "RUN_FILES",
    "RunStart",
    "check_new_run_dir",
    "checkpoint_steps",
    "checkpoints",
    "latest_checkpoint",
    "read_train_log",
    "resume_state",
    "run_files",
]

#: Checkpoints of a run are ``checkpoints/<prefix>_<decisions>_steps.zip``.
CHECKPOINT_PREFIX = "model"
#: What a training run writes into its folder (besides the atlases, which a new run may
#: find there and reuse, :func:`~vc_gym.training.environments.learn_places`), and the
#: marker of a sweep's folder: a folder holding any of them holds a run, and a new run
#: refuses it (:func:`check_new_run_dir`).
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


def checkpoint_steps(path: Path) -> int | None:
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
        if (steps := checkpoint_steps(p)) is not None
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
    ``checkpoints/``, ``train_log.json``, ...) holds a run already: training into it
    would mix two runs (a new ``config.json`` beside an old ``model.zip``, old
    checkpoints that ``--resume`` would continue from). A missing or empty folder, or
    one with only atlases (``atlas*.npz``, reused when learned the same way,
    :func:`~vc_gym.training.environments.learn_places`) or unrelated files, is accepted.

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
class RunStart:
    """Where a run starts: its config, and with a checkpoint what it continues from."""

    config: TrainConfig
    checkpoint: Path | None = None
    episodes: list[dict[str, Any]] = field(default_factory=list)
    skipped: list[tuple[Path, str]] = field(default_factory=list)


def resume_state(out: Path, config: TrainConfig) -> RunStart:
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
        steps = checkpoint_steps(path)
        assert steps is not None  # checkpoints() lists only such names
        episodes = read_train_log(out / "train_log.json", steps)
        return RunStart(config, path, episodes, skipped)
    return RunStart(config, None, [], skipped)


#: The fields of one episode in ``train_log.json`` and the types each may have.
_EPISODE_FIELDS = {
    "timestep": numbers.Integral,
    "return": numbers.Real,
    "decisions": numbers.Integral,
    "stop_error_m": numbers.Real,
    "success": bool,
}


def read_train_log(path: Path, steps: int) -> list[dict[str, Any]]:
    """The episodes of the training log ``path`` up to ``steps`` decisions (none without
    a log); a log larger than :data:`MAX_TRAIN_LOG_BYTES` or not of
    :class:`~vc_gym.training.callbacks.EpisodeLog`'s episodes is refused, naming the file."""
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

