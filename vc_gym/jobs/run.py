"""A run: an experiment's output folder, its jobs saved as they finish, resumable.

:class:`ExperimentRun` owns an experiment's output folder: every finished job is written
to ``DIR/jobs/<stage>/<key>.json`` at once (:mod:`vc_gym.jobs.job`), so an interrupted
run resumes where it stopped (no finished job is redone, none is lost). A job that
raises, or whose worker dies, is retried once and then reported in ``results.json``
(``failed_jobs``), never dropped. :meth:`ExperimentRun.finish` writes ``results.json``
(figures only: the same seed gives the same bytes) and ``run.json`` (timings, jobs per
second, backend, package versions, and every stage of the run with the keys of the jobs
loaded from saved files, including a stage whose jobs were all saved already and which
the experiment therefore skipped).
"""

from __future__ import annotations

import json
import math
import os
import platform
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from tqdm import tqdm

from vc_gym.config_files import read_settings
from vc_gym.jobs.backends import LocalBackend, RayBackend
from vc_gym.jobs.job import Job, JobOutcome, job_record, read_job_file, saved_outcome
from vc_gym.jobs.output import check_out_dir, write_json

__all__ = ["TIMING", "ExperimentRun", "package_versions"]

#: Key of a job's output that holds wall-clock figures: kept in ``run.json``, never in
#: ``results.json``.
TIMING = "timing"


def package_versions() -> dict[str, str]:
    """Versions of Python and the packages whose behaviour the figures depend on."""
    from importlib import metadata

    versions = {"python": platform.python_version()}
    for dist in (
        "vc_gym",
        "numpy",
        "opencv-python-headless",
        "pybullet",
        "gymnasium",
        "filterpy",
        "ray",
    ):
        try:
            versions[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            continue
    return versions


class ExperimentRun:
    """The output folder of one experiment: jobs saved as they finish, resumable.

    Parameters
    ----------
    out_dir : path-like
        The folder (created; checked writable before any work).
    experiment : str
        Its name (recorded in both JSON files).
    backend : LocalBackend or RayBackend
        Who runs the jobs.
    settings : mapping
        The experiment's settings (seed, size, ...): written to ``results.json``; a run
        resumed in the same folder must have the same settings.
    progress : bool
        Show a progress bar per stage.
    retries : int
        Extra attempts of a job that failed (default 1: retried once).
    owns_backend : bool
        Close the backend (stop its workers) in :meth:`finish`.
    """

    def __init__(
        self,
        out_dir: str | os.PathLike,
        experiment: str,
        backend: LocalBackend | RayBackend,
        settings: Mapping[str, Any],
        progress: bool = True,
        retries: int = 1,
        owns_backend: bool = False,
    ):
        self.out = check_out_dir(out_dir)
        self.owns_backend = owns_backend
        self.experiment = experiment
        self.backend = backend
        self.settings = json.loads(json.dumps(dict(settings)))
        self.progress = progress
        self.retries = int(retries)
        self.failures: list[dict[str, Any]] = []
        self.stages: dict[str, dict[str, Any]] = {}
        self._stage_raw: dict[str, dict[str, Any]] = {}
        self.timings: dict[str, dict[str, Any]] = {}
        self._t0 = time.perf_counter()
        self._check_settings()

    def _check_settings(self) -> None:
        marker = self.out / "jobs" / "settings.json"
        mine = {"experiment": self.experiment, **self.settings}
        if marker.exists() or marker.is_symlink():
            try:  # bounded in size and depth (MAX_SETTINGS_BYTES)
                theirs = read_settings(marker)
            except ValueError as exc:
                raise ValueError(
                    f"{self.out} holds jobs whose settings cannot be read ({exc}); choose "
                    "another --out"
                ) from None
            if theirs != mine:
                raise ValueError(
                    f"{self.out} holds the jobs of another run ({theirs}); resume it with the "
                    "same settings or choose another --out"
                )
        else:
            write_json(marker, mine)

    def job_file(self, stage: str, key: str) -> Path:
        """Where the job ``key`` of ``stage`` is saved."""
        return self.out / "jobs" / stage / f"{key}.json"

    def run(self, stage: str, jobs: Sequence[Job]) -> list[dict[str, Any] | None]:
        """Run the jobs of one stage; return their outputs in job order.

        The ``timing`` entry of each output is moved to ``run.json``. A job that failed
        after its retries gives ``None`` and is listed in :attr:`failures`.
        """
        keys = [j.key for j in jobs]
        if len(set(keys)) != len(keys):
            raise ValueError(f"stage {stage!r}: job keys are not unique")
        outcomes: dict[str, JobOutcome] = {}
        todo = []
        for job in jobs:
            saved = saved_outcome(job, self.job_file(stage, job.key))
            if saved is None:
                todo.append(job)
            else:
                outcomes[job.key] = saved
        t0 = time.perf_counter()
        attempts = {j.key: 0 for j in todo}
        retried = 0
        with tqdm(
            total=len(jobs),
            initial=len(outcomes),
            desc=f"{self.experiment}: {stage}",
            unit="job",
            disable=not self.progress or not jobs,
        ) as bar:
            round_jobs = todo
            while round_jobs:
                again = []
                for i, ok, out, seconds in self.backend.run(round_jobs):
                    job = round_jobs[i]
                    attempts[job.key] += 1
                    if ok:
                        outcome = JobOutcome(job.key, True, out, None, attempts[job.key], seconds)
                    elif attempts[job.key] <= self.retries:
                        again.append(job)
                        retried += 1
                        continue
                    else:
                        outcome = JobOutcome(
                            job.key, False, None, out["error"], attempts[job.key], seconds
                        )
                    self._save(stage, job, outcome, out)
                    outcomes[job.key] = outcome
                    bar.update()
                round_jobs = again
        wall = time.perf_counter() - t0
        ran = [o for o in outcomes.values() if not o.resumed]
        self._record_stage(
            stage,
            jobs=len(jobs),
            ran=len(ran),
            failed=sum(not o.ok for o in outcomes.values()),
            retried=retried,
            wall=wall,
            seconds=[o.seconds for o in ran if o.seconds is not None and math.isfinite(o.seconds)],
            resumed_keys=[j.key for j in jobs if outcomes[j.key].resumed],
        )
        results: list[dict[str, Any] | None] = []
        stage_timing: dict[str, Any] = {}
        for job in jobs:
            o = outcomes[job.key]
            if not o.ok:
                self.failures.append(
                    {"stage": stage, "key": job.key, "attempts": o.attempts, "error": o.error}
                )
                results.append(None)
                continue
            out = dict(o.output or {})
            timing = out.pop(TIMING, None)
            if timing is not None:
                stage_timing[job.key] = timing
            results.append(out)
        if stage_timing:
            self.timings.setdefault(stage, {}).update(stage_timing)
        return results

    def _record_stage(self, stage: str, **new: Any) -> None:
        """Add a call's counts to its stage (a stage may run in several calls)."""
        old = self._stage_raw.get(stage)
        if old is not None:
            for k in ("jobs", "ran", "failed", "retried", "wall"):
                new[k] += old[k]
            new["seconds"] = old["seconds"] + new["seconds"]
            new["resumed_keys"] = old["resumed_keys"] + new["resumed_keys"]
        self._stage_raw[stage] = new
        secs = sorted(new["seconds"])
        ran, wall = new["ran"], new["wall"]
        self.stages[stage] = {
            "jobs": new["jobs"],
            "ran": ran,
            "resumed": new["jobs"] - ran,
            "failed": new["failed"],
            "retried": new["retried"],
            "wall_s": round(wall, 3),
            "jobs_per_s": round(ran / wall, 4) if ran and wall > 0 else None,
            "job_s_median": round(secs[len(secs) // 2], 4) if secs else None,
            "resumed_keys": list(new["resumed_keys"]),
        }

    def _record_saved_stages(self) -> None:
        """Record the stages this call never ran whose jobs are saved in the folder.

        An experiment skips a stage whose products are all on disk already (a resumed
        run finds its atlases saved and does not call :meth:`run` for ``learn``); the
        stage still belongs to the run, so it is recorded with every saved job as
        resumed (and their timings), before the stages run in this call.
        """
        root = self.out / "jobs"
        found: list[tuple[float, str, list[str], dict[str, Any]]] = []
        try:
            folders = sorted(p for p in root.iterdir() if p.is_dir())
        except OSError:
            return
        for folder in folders:
            stage = folder.name
            if stage in self.stages or stage.startswith("."):
                continue
            keys, timings, first = [], {}, math.inf
            for path in sorted(folder.glob("*.json")):
                if path.name.startswith("."):  # a temporary file of an interrupted write
                    continue
                rec = read_job_file(path)
                if rec is None or not rec.get("ok"):
                    continue
                keys.append(path.stem)
                timing = rec["output"].get(TIMING)
                if timing is not None:
                    timings[path.stem] = timing
                try:
                    first = min(first, path.stat().st_mtime)
                except OSError:
                    pass
            if keys:
                found.append((first, stage, keys, timings))
        if not found:
            return
        ran_now = dict(self.stages)
        self.stages.clear()
        for _, stage, keys, timings in sorted(found):
            self._record_stage(
                stage,
                jobs=len(keys),
                ran=0,
                failed=0,
                retried=0,
                wall=0.0,
                seconds=[],
                resumed_keys=keys,
            )
            if timings:
                self.timings.setdefault(stage, {}).update(timings)
        self.stages.update(ran_now)

    def _save(self, stage: str, job: Job, outcome: JobOutcome, out: Any) -> None:
        traceback_text = None if outcome.ok else out.get("traceback")
        write_json(self.job_file(stage, job.key), job_record(job, outcome, traceback_text))

    def finish(
        self, results: Mapping[str, Any], run_info: Mapping[str, Any] | None = None
    ) -> dict[str, Any]:
        """Write ``results.json`` (figures + failed jobs) and ``run.json`` (timings).

        Returns the results as written.
        """
        doc = {
            "experiment": self.experiment,
            "settings": self.settings,
            **dict(results),
            "failed_jobs": list(self.failures),
        }
        doc = json.loads(json.dumps(doc, allow_nan=True))
        write_json(self.out / "results.json", doc)
        self._record_saved_stages()
        run = {
            "experiment": self.experiment,
            **self.backend.describe(),
            "duration_s": round(time.perf_counter() - self._t0, 2),
            "stages": self.stages,
            "versions": package_versions(),
            **dict(run_info or {}),
            "job_timings": self.timings,
        }
        write_json(self.out / "run.json", run)
        if self.owns_backend:
            self.backend.close()
        return doc
