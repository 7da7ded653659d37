"""stable-baselines3 callbacks of ``vc-gym train``: the episode log, held-out evaluation
and checkpoints.

Every file these callbacks write appears whole or not at all
(:func:`vc_gym.persistence.write_atomic`, or a rename of a finished temporary file): a
run interrupted while one is written (Ctrl-C, a killed job) keeps the previous version,
so ``vc-gym train --resume`` finds only whole checkpoints and a whole best model.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback, EvalCallback
from tqdm import tqdm

from vc_gym.persistence import write_atomic

__all__ = ["AtomicCheckpoint", "EpisodeLog", "HeldOutEvaluation"]


class EpisodeLog(BaseCallback):
    """Collects every finished training episode (from ``Monitor``) and shows progress.

    Parameters
    ----------
    total : int
        Decisions the run trains for (the progress bar's end).
    episodes : list
        Where the episodes go: ``{"timestep", "return", "decisions", "stop_error_m",
        "success"}`` each (a resumed run passes the episodes it already had).
    on_checkpoint : callable
        Called with the list every 100 episodes (a log to watch while it runs).
    label : str
        Progress bar label.
    progress : bool
        Show the bar.
    """

    def __init__(
        self,
        total: int,
        episodes: list[dict[str, Any]],
        on_checkpoint: Callable[[list[dict[str, Any]]], None],
        label: str,
        progress: bool,
    ):
        super().__init__()
        self.total, self.episodes = total, episodes
        self.on_checkpoint, self.label, self.progress = on_checkpoint, label, progress
        self.started = self.ended = 0.0
        self.first_timestep = 0
        self.task_steps = 0  # steps of the task env behind the decisions (info "task_steps")

    def _on_training_start(self) -> None:
        self.started = time.perf_counter()
        self.first_timestep = int(self.model.num_timesteps)
        self.bar = tqdm(
            total=self.total,
            initial=self.first_timestep,
            desc=self.label,
            disable=not self.progress,
        )

    def _on_step(self) -> bool:
        self.bar.update(self.training_env.num_envs)
        self.task_steps += sum(int(info.get("task_steps", 1)) for info in self.locals["infos"])
        for info in self.locals["infos"]:
            ep = info.get("episode")
            if ep is None:
                continue
            self.episodes.append(
                {
                    "timestep": int(self.num_timesteps),
                    "return": float(ep["r"]),
                    "decisions": int(ep["l"]),
                    "stop_error_m": float(info.get("stop_error_m", float("nan"))),
                    "success": bool(info.get("success", False)),
                }
            )
            if len(self.episodes) % 100 == 0:
                self.on_checkpoint(self.episodes)
            recent = self.episodes[-50:]
            self.bar.set_postfix(
                success=f"{np.mean([e['success'] for e in recent]):.0%}",
                err=f"{np.nanmean([e['stop_error_m'] for e in recent]):.2f}m",
            )
        return True

    def _on_training_end(self) -> None:
        self.ended = time.perf_counter()
        self.bar.close()

    @property
    def decisions_per_s(self) -> float | None:
        """Decisions per second of this ``learn`` call (no learning phase, no start-up)."""
        seconds = self.ended - self.started
        done = int(self.model.num_timesteps) - self.first_timestep
        return done / seconds if seconds > 0 and done > 0 else None

    @property
    def task_steps_per_s(self) -> float | None:
        """Steps of the task env per second behind those decisions (a stop that stands
        holds its decision for many of them)."""
        seconds = self.ended - self.started
        return self.task_steps / seconds if seconds > 0 and self.task_steps > 0 else None


class AtomicCheckpoint(BaseCallback):
    """Save the model every ``save_freq`` calls as ``<save_path>/<prefix>_<N>_steps.zip``
    (``N``: decisions so far; the names of SB3's ``CheckpointCallback``).

    What SB3's ``CheckpointCallback`` does, but each checkpoint is written to a temporary
    file that is renamed into place when it is complete: an interrupted save leaves no
    torn checkpoint for ``--resume`` to trip on.

    Parameters
    ----------
    save_freq : int
        Calls (``env.step`` of the whole vector env) between checkpoints.
    save_path : path-like
        The checkpoint folder (created when training starts).
    name_prefix : str
        First part of the file names.
    on_save : callable, optional
        Called with no arguments after each checkpoint (the run's episode log is saved
        with it, so that a resume finds the episodes up to the checkpoint).
    """

    def __init__(
        self,
        save_freq: int,
        save_path: str | os.PathLike,
        name_prefix: str,
        on_save: Callable[[], None] | None = None,
    ):
        super().__init__()
        self.save_freq = int(save_freq)
        self.save_path = Path(save_path)
        self.name_prefix = name_prefix
        self.on_save = on_save

    def _init_callback(self) -> None:
        self.save_path.mkdir(parents=True, exist_ok=True)

    def checkpoint_path(self) -> Path:
        """Where the checkpoint at the current decision count goes."""
        return self.save_path / f"{self.name_prefix}_{self.num_timesteps}_steps.zip"

    def _on_step(self) -> bool:
        if self.save_freq > 0 and self.n_calls % self.save_freq == 0:
            # the temporary name ends in .zip too, so SB3 saves to it as it is
            write_atomic(self.checkpoint_path(), self.model.save)
            if self.on_save is not None:
                self.on_save()
        return True


class HeldOutEvaluation(EvalCallback):
    """:class:`EvalCallback` on the same kidnappings at every evaluation.

    The evaluation env is reseeded with ``seed`` before each evaluation, so every
    evaluation (and the best model it keeps) is judged on one fixed set of held-out
    kidnappings, not on whichever the env happened to draw next. With ``at_start`` it
    also evaluates once before training.

    ``best_model_save_path/best_model.zip`` and ``log_path/evaluations.npz`` are written
    atomically: the best model through :func:`~vc_gym.persistence.write_atomic`, the
    evaluations to a hidden file beside them that is renamed over the old one.
    """

    def __init__(self, *args: Any, seed: int, at_start: bool = False, **kwargs: Any):
        best = kwargs.pop("best_model_save_path", None)
        super().__init__(*args, **kwargs)  # without a best-model path: saved here instead
        self.seed = int(seed)
        self.at_start = bool(at_start)
        self.best_model_file = None if best is None else Path(best) / "best_model.zip"
        self.evaluations_file: Path | None = None
        if self.log_path is not None:
            # EvalCallback appends ".npz" and writes in place: point it at a hidden name
            # in the same folder and rename the finished file
            log = Path(self.log_path)
            self.evaluations_file = log.with_name(log.name + ".npz")
            self.log_path = str(log.with_name(f".{log.name}.partial"))

    def _init_callback(self) -> None:
        super()._init_callback()
        if self.best_model_file is not None:
            self.best_model_file.parent.mkdir(parents=True, exist_ok=True)

    def _on_training_start(self) -> None:
        # with ``at_start`` the policy is also judged before it trains (a warm-started
        # clone may be the best model); ``n_calls`` is 0 here, a multiple of any period
        if self.at_start and self.eval_freq > 0:
            self._on_step()

    def _on_step(self) -> bool:
        if not (self.eval_freq > 0 and self.n_calls % self.eval_freq == 0):
            return super()._on_step()
        self.eval_env.seed(self.seed)
        best_before = self.best_mean_reward
        go_on = super()._on_step()
        if self.evaluations_file is not None:
            written = Path(f"{self.log_path}.npz")
            if written.is_file():
                os.replace(written, self.evaluations_file)
        if self.best_model_file is not None and self.best_mean_reward > best_before:
            write_atomic(self.best_model_file, self.model.save)
        return go_on
