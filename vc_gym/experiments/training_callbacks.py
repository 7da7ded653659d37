"""stable-baselines3 callbacks of ``vc-gym train``: the episode log and held-out evaluation."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback, EvalCallback
from tqdm import tqdm

__all__ = ["EpisodeLog", "HeldOutEvaluation"]


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


class HeldOutEvaluation(EvalCallback):
    """:class:`EvalCallback` on the same kidnappings at every evaluation.

    The evaluation env is reseeded with ``seed`` before each evaluation, so every
    evaluation (and the best model it keeps) is judged on one fixed set of held-out
    kidnappings, not on whichever the env happened to draw next. With ``at_start`` it
    also evaluates once before training.
    """

    def __init__(self, *args: Any, seed: int, at_start: bool = False, **kwargs: Any):
        super().__init__(*args, **kwargs)
        self.seed = int(seed)
        self.at_start = bool(at_start)

    def _on_training_start(self) -> None:
        # with ``at_start`` the policy is also judged before it trains (a warm-started
        # clone may be the best model); ``n_calls`` is 0 here, a multiple of any period
        if self.at_start and self.eval_freq > 0:
            self._on_step()

    def _on_step(self) -> bool:
        if self.eval_freq > 0 and self.n_calls % self.eval_freq == 0:
            self.eval_env.seed(self.seed)
        return super()._on_step()
