"""Several training runs as one sweep on the experiment runner (``vc-gym train --seeds``).

Each seed is a job: a full :func:`~vc_gym.training.train.train` run in its own
folder ``DIR/seed-<s>`` (the place learned with that seed, PPO seeded with it). The
sweep's ``results.json`` holds every run's figures and their mean ± std over the seeds;
``run.json`` the timings. Rerunning the command resumes: finished runs are not trained
again, and a run that was cut short goes on from its latest checkpoint (or starts over
in its folder without one, :func:`~vc_gym.training.train.continue_run`); a seed
folder holding a run of other settings is refused. Jobs run on the local pool or on Ray
like every experiment; on a small machine one job at a time (``--workers 1``, the default
here) with ``n_envs`` env workers each uses the cores best.
"""

from __future__ import annotations

import os
import zipfile
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.jobs.job import Job
from vc_gym.jobs.run import ExperimentRun
from vc_gym.persistence import zip_entries_problem
from vc_gym.training.config import TrainConfig, read_train_config
from vc_gym.training.run_folder import run_files
from vc_gym.training.train import continue_run

__all__ = ["FIGURES", "train_job", "run_train_sweep"]

#: The figures of one training run that the sweep summarises over seeds.
FIGURES = (
    "recent_success_rate",
    "recent_mean_stop_error_m",
    "eval_final_mean_return",
    "eval_best_mean_return",
    "eval_final_success_rate",
    "home_offset_x_m",
    "home_offset_y_m",
)
#: Largest ``eval/evaluations.npz`` of a run read for the figures (bytes of its arrays
#: together, judged before anything is decompressed).
MAX_EVALUATIONS_BYTES = 64_000_000


def _evaluation_figures(run_dir: Path) -> dict[str, float | None]:
    """Final and best mean return (and final success rate) of the held-out evaluations."""
    path = run_dir / "eval" / "evaluations.npz"
    out: dict[str, float | None] = {
        "eval_final_mean_return": None,
        "eval_best_mean_return": None,
        "eval_final_success_rate": None,
    }
    if not path.is_file():
        return out
    try:
        with zipfile.ZipFile(path) as z:
            problem = zip_entries_problem(
                z.infolist(), MAX_EVALUATIONS_BYTES, MAX_EVALUATIONS_BYTES
            )
        if problem is not None:
            raise ValueError(problem)
        with np.load(path, allow_pickle=False) as ev:
            returns = np.asarray(ev["results"], dtype=np.float64).mean(axis=1)
            out["eval_final_mean_return"] = round(float(returns[-1]), 4)
            out["eval_best_mean_return"] = round(float(returns.max()), 4)
            if "successes" in ev.files and ev["successes"].size:
                out["eval_final_success_rate"] = round(float(np.mean(ev["successes"][-1])), 4)
    except (OSError, ValueError, KeyError, IndexError, zipfile.BadZipFile) as exc:
        raise ValueError(f"{path}: not a readable evaluations file: {exc}") from None
    return out


def _goal_figures(run_dir: Path) -> dict[str, float | None]:
    """The goal correction the run measured and trained with (its ``config.json``)."""
    path = run_dir / "config.json"
    # only the measured goal is read from it and nothing it names is built, so a tracker
    # given as an import path on the command line is read as a name
    offset = read_train_config(path, allow_imports=True).home_offset_m if path.is_file() else None
    x, y = (None, None) if offset is None else offset
    return {"home_offset_x_m": x, "home_offset_y_m": y}


def train_job(config: dict[str, Any], out_dir: str) -> dict[str, Any]:
    """Job: one full training run of ``config`` (a :meth:`TrainConfig.to_dict`) in
    ``out_dir``, going on from what an earlier attempt of this job left there
    (:func:`~vc_gym.training.train.continue_run`); returns its figures (timings
    under ``"timing"``)."""
    cfg = TrainConfig.from_dict(config)
    summary = continue_run(cfg, out_dir, progress=False)
    figures = {
        "episodes": summary["episodes"],
        "recent_success_rate": summary["recent_success_rate"],
        "recent_mean_stop_error_m": None
        if summary["recent_mean_stop_error_m"] is None
        else round(summary["recent_mean_stop_error_m"], 4),
        **_evaluation_figures(Path(out_dir)),
    }
    return {
        **figures,
        "timing": {
            "duration_s": summary["duration_s"],
            "decisions_per_s": summary["decisions_per_s"],
        },
    }


def _mean_std(values: Sequence[float | None]) -> dict[str, float | None]:
    v = np.array([x for x in values if x is not None], dtype=np.float64)
    if v.size == 0:
        return {"mean": None, "std": None, "n": 0}
    # the sample std (ddof 1), as every other spread over seeds; 0 for one seed
    std = float(v.std(ddof=1)) if v.size > 1 else 0.0
    return {"mean": round(float(v.mean()), 4), "std": round(std, 4), "n": int(v.size)}


def run_train_sweep(
    out_dir: str | os.PathLike,
    config: TrainConfig,
    seeds: Sequence[int],
    backend: Any,
    progress: bool = True,
) -> dict[str, Any]:
    """Train ``config`` once per seed (``DIR/seed-<s>``) and summarise over the seeds.

    Returns the results written to ``results.json``: ``runs`` (each seed's figures)
    and ``over_seeds`` (mean ± sample std of every :data:`FIGURES` entry).
    """
    seeds = [int(s) for s in seeds]
    if not seeds or len(set(seeds)) != len(seeds) or min(seeds) < 0:
        raise ValueError(f"seeds must be distinct ints >= 0, got {seeds}")
    out = Path(out_dir)
    if not (out / "jobs" / "settings.json").is_file() and run_files(out):
        # a single run's folder, not a sweep's: the sweep would write beside that run
        raise ValueError(
            f"--out {out}: holds a training run ({', '.join(run_files(out))}), not a sweep; "
            "choose another --out"
        )
    settings = {"config": {**config.to_dict(), "seed": None}, "seeds": seeds}
    run = ExperimentRun(out, "train-sweep", backend, settings, progress=progress)
    jobs = [
        Job(
            f"seed-{s}",
            f"{__name__}:train_job",
            {"config": replace(config, seed=s).to_dict(), "out_dir": str(out / f"seed-{s}")},
        )
        for s in seeds
    ]
    outputs = run.run("train", jobs)
    runs = {
        f"seed-{s}": {
            **{k: v for k, v in o.items() if k != "timing"},
            **_goal_figures(out / f"seed-{s}"),
        }
        for s, o in zip(seeds, outputs, strict=True)
        if o is not None
    }
    over = {f: _mean_std([r.get(f) for r in runs.values()]) for f in FIGURES}
    return run.finish({"runs": runs, "over_seeds": over})
