"""How fast the experiment backends run the homing experiment's jobs, side by side.

The homing experiment's episodes (one kidnapping per job, the atlas learned once and
loaded by every job) run with one local worker, with ``workers`` local workers and,
when Ray is installed, on a local Ray instance with ``workers`` CPUs, one after the
other in one process. Reported: jobs per second of the episode stage for each, their
ratios to one local worker, and whether every backend wrote byte-identical
``results.json`` files.
"""

from __future__ import annotations

import importlib.util
import tempfile
from pathlib import Path
from typing import Any

from vc_gym.experiments.studies.common import ExperimentOptions
from vc_gym.experiments.studies.homing import run_homing
from vc_gym.jobs.backends import LocalBackend, RayBackend
from vc_gym.jobs.output import read_json
from vc_gym.jobs.workers import check_workers
from vc_gym.validation import MAX_EPISODES, check_seed, int_in_range, positive_float

__all__ = ["bench_backends"]


def bench_backends(
    episodes: int = 12,
    workers: int = 2,
    seed: int = 0,
    learn_time_s: float = 5.0,
    max_homing_s: float = 60.0,
    progress: bool = True,
) -> dict[str, Any]:
    """Jobs per second of the homing episodes on each backend, measured in one run.

    Parameters
    ----------
    episodes : int
        Kidnappings (jobs) per backend; the same ones on every backend (1 to
        :data:`~vc_gym.validation.MAX_EPISODES`).
    workers : int
        Workers of the parallel backends (2 to
        :func:`~vc_gym.jobs.workers.max_workers`).
    seed : int
        Learning seed (the atlas is learned once, before any timing).
    learn_time_s, max_homing_s : float
        The task's learning time per direction and homing limit.
    progress : bool
        Progress bars.

    Returns
    -------
    dict
        ``{"runs": {name: {"jobs_per_s", "wall_s", ...}}, "speedup": {name: ratio},
        "identical_results": bool, ...}``.
    """
    int_in_range("episodes", episodes, 1, MAX_EPISODES)
    check_workers(workers, "workers", minimum=2)
    check_seed("seed", seed)
    positive_float("learn_time_s", learn_time_s)
    positive_float("max_homing_s", max_homing_s)
    backends: list[tuple[str, Any]] = [
        ("local-1", lambda: LocalBackend(1)),
        (f"local-{workers}", lambda: LocalBackend(workers)),
    ]
    if importlib.util.find_spec("ray") is not None:
        backends.append((f"ray-{workers}", lambda: RayBackend(workers=workers)))
    task = {"episodes": episodes, "learn_time_s": learn_time_s, "max_homing_s": max_homing_s}
    with tempfile.TemporaryDirectory(prefix="vc_gym_bench_") as tmp:
        root = Path(tmp)
        # the atlas, learned once and shared by every run (not timed)
        with LocalBackend(1) as backend:
            opts = ExperimentOptions(seed=seed, backend=backend, progress=progress)
            run_homing(root / "learn", opts, field=False, **{**task, "episodes": 1})
        atlases = root / "learn" / "atlases"
        runs: dict[str, dict[str, Any]] = {}
        texts = {}
        for name, make in backends:
            with make() as backend:
                opts = ExperimentOptions(
                    seed=seed, backend=backend, atlas_dir=atlases, progress=progress
                )
                run_homing(root / name, opts, field=False, **task)
            stage = read_json(root / name / "run.json")["stages"]["episodes"]
            runs[name] = {
                "jobs": stage["jobs"],
                "jobs_per_s": stage["jobs_per_s"],
                "wall_s": stage["wall_s"],
                "job_s_median": stage["job_s_median"],
            }
            texts[name] = (root / name / "results.json").read_bytes()
    base = runs["local-1"]["jobs_per_s"]
    return {
        "episodes": episodes,
        "workers": workers,
        "runs": runs,
        "speedup_vs_one_local_worker": {
            n: round(r["jobs_per_s"] / base, 3) for n, r in runs.items() if n != "local-1"
        },
        "identical_results": len(set(texts.values())) == 1,
        "ray": "ray-" + str(workers) in runs,
    }
