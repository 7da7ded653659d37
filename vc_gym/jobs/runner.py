"""Experiments as independent jobs, run by a backend and saved as they finish.

An experiment splits its work into :class:`Job` s (one kidnapping, one grid position, one
parameter value): a job names a top-level function (``"package.module:function"``) and its
JSON keyword arguments, and returns a JSON object of figures. Its result must depend only
on its arguments (seeds and the paths of saved atlases), never on which worker ran what
before it, so the same seed gives the same figures whatever backend or worker count ran
the jobs.

:class:`ExperimentRun` owns an experiment's output folder: every finished job is written
to ``DIR/jobs/<stage>/<key>.json`` at once, so an interrupted run resumes where it stopped
(no finished job is redone, none is lost). A saved job file that cannot be trusted (torn,
foreign, larger than :data:`MAX_JOB_FILE_BYTES`, not a regular file) counts as not saved:
its job runs again. A job that raises, or whose worker dies, is retried once and then
reported in ``results.json`` (``failed_jobs``), never dropped.
:meth:`ExperimentRun.finish` writes ``results.json`` (figures only: the same seed gives the
same bytes) and ``run.json`` (timings, jobs per second, backend, package versions, and
every stage of the run with the keys of the jobs loaded from saved files, including a
stage whose jobs were all saved before and which the experiment therefore skipped).

Backends: :class:`LocalBackend` (a process pool; one worker runs the jobs in this
process) and :class:`RayBackend` (Ray: a local instance, or an existing cluster by
address). Both keep their workers' numeric libraries single-threaded: the workers are
the parallelism (docs/design.md). Both take at most :func:`max_workers` workers
(:data:`MAX_WORKERS_PER_CPU` per CPU, at most :data:`MAX_WORKERS`).
"""

from __future__ import annotations

import concurrent.futures as cf
import importlib
import json
import math
import multiprocessing as mp
import os
import platform
import signal
import threading
import time
import traceback
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tqdm import tqdm

from vc_gym.config_files import read_settings
from vc_gym.jobs.output import check_out_dir, read_json, write_json

__all__ = [
    "BACKENDS",
    "MAX_JOB_FILE_BYTES",
    "MAX_WORKERS",
    "MAX_WORKERS_PER_CPU",
    "Job",
    "JobOutcome",
    "ExperimentRun",
    "LocalBackend",
    "RayBackend",
    "call_job",
    "check_out_dir",
    "check_workers",
    "make_backend",
    "max_workers",
    "worker_cache",
]

#: Key of a job's output that holds wall-clock figures: kept in ``run.json``, never in
#: ``results.json``.
TIMING = "timing"
BACKENDS = ("local", "ray")
#: Most workers per CPU of this machine a local pool or a local Ray instance may have:
#: more only queue for the same cores, each holding its own simulator (~1 GB).
MAX_WORKERS_PER_CPU = 4
#: Most workers of a backend on any machine.
MAX_WORKERS = 256
#: Largest saved job file read when a run resumes (bytes); a larger one is not
#: trusted and its job runs again. Job outputs are figures, kilobytes each.
MAX_JOB_FILE_BYTES = 64 * 2**20
#: Environment of every worker: one thread per numeric library.
SINGLE_THREADED = {
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENCV_FOR_THREADS_NUM": "1",
}


@dataclass(frozen=True)
class Job:
    """One independent piece of an experiment.

    Attributes
    ----------
    key : str
        Unique within its stage and safe as a file name (``"episode-0007"``).
    fn : str
        The function to call, ``"package.module:function"`` (top level, importable by
        every worker).
    kwargs : mapping
        Its keyword arguments (JSON values only, so that a job can be saved and
        compared when a run resumes).
    """

    key: str
    fn: str
    kwargs: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.key or any(c in self.key for c in '/\\:*?"<>|') or self.key[0] == ".":
            raise ValueError(f"job key {self.key!r} is not a safe file name")
        if ":" not in self.fn:
            raise ValueError(f"job fn must be 'package.module:function', got {self.fn!r}")
        try:
            json.dumps(dict(self.kwargs), allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"job {self.key!r}: kwargs must be JSON values ({exc})") from None


@dataclass
class JobOutcome:
    """What became of a job: its output, or the error of its last attempt."""

    key: str
    ok: bool
    output: dict[str, Any] | None
    error: str | None
    attempts: int
    seconds: float | None
    resumed: bool = False


def _resolve(fn: str) -> Callable[..., Any]:
    module, _, name = fn.partition(":")
    obj: Any = importlib.import_module(module)
    for part in name.split("."):
        obj = getattr(obj, part)
    if not callable(obj):
        raise TypeError(f"{fn} is not callable")
    return obj


def call_job(fn: str, kwargs: Mapping[str, Any]) -> dict[str, Any]:
    """Run a job's function in this process and return its output, JSON-normalised.

    The output is passed through JSON so that a fresh result and one read back from a
    saved job file are the same Python values (lists, floats, ...).
    """
    out = _resolve(fn)(**dict(kwargs))
    if not isinstance(out, Mapping):
        raise TypeError(f"{fn} returned {type(out).__name__}, expected a dict of figures")
    return json.loads(json.dumps(dict(out), allow_nan=True))


def _execute(fn: str, kwargs: Mapping[str, Any]) -> tuple[bool, Any, float]:
    """Worker side: ``(ok, output or error text, seconds)``; never raises."""
    t0 = time.perf_counter()
    try:
        out = call_job(fn, kwargs)
        return True, out, time.perf_counter() - t0
    except BaseException as exc:  # noqa: BLE001 - a job's failure is data, reported
        if isinstance(exc, KeyboardInterrupt):
            raise
        text = "".join(traceback.format_exception_only(type(exc), exc)).strip()
        detail = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
        return False, {"error": text, "traceback": detail}, time.perf_counter() - t0


_CACHE: dict[Any, Any] = {}


def worker_cache(key: Any, make: Callable[[], Any], limit: int = 4) -> Any:
    """Something expensive to build (an env, a loaded atlas), kept for the worker's next jobs.

    Only for things whose use does not depend on what was done with them before (an
    env whose ``reset(seed=...)`` fully determines the episode); the oldest entries
    are closed (if they have ``close``) when more than ``limit`` are kept.
    """
    if key in _CACHE:
        return _CACHE[key]
    while len(_CACHE) >= limit:
        old = _CACHE.pop(next(iter(_CACHE)))
        close = getattr(old, "close", None)
        if callable(close):
            close()
    _CACHE[key] = value = make()
    return value


def max_workers() -> int:
    """Most workers a backend may have on this machine: :data:`MAX_WORKERS_PER_CPU` per
    CPU, at most :data:`MAX_WORKERS`."""
    return min(MAX_WORKERS, MAX_WORKERS_PER_CPU * (os.cpu_count() or 1))


def check_workers(workers: object, name: str = "workers", minimum: int = 1) -> int:
    """``workers`` as an int in ``minimum..max_workers()``, else a ``ValueError`` naming
    ``name`` (e.g. ``"--workers"``) and the range."""
    limit = max_workers()
    if (
        isinstance(workers, bool)
        or not isinstance(workers, int)
        or not (minimum <= workers <= limit)
    ):
        raise ValueError(
            f"{name} must be an int in {minimum}..{limit} ({MAX_WORKERS_PER_CPU} per CPU; "
            f"this machine has {os.cpu_count() or 1}; never more than {MAX_WORKERS}), "
            f"got {workers!r}"
        )
    return workers


def _init_worker(quiet: bool = False, parent_pid: int | None = None) -> None:
    os.environ.update(SINGLE_THREADED)
    if parent_pid is not None:
        # a pool worker: Ctrl-C in a terminal reaches the whole process group, and the
        # parent, not each worker, handles it (it stops the workers)
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        threading.Thread(
            target=_exit_with_parent, args=(parent_pid,), name="parent-watch", daemon=True
        ).start()
    if quiet:
        # native libraries print to the process' stdout (PyBullet: "argv[0]=", its build
        # time) and would scribble over the parent's progress bar; jobs return data
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)
    try:
        import cv2

        cv2.setNumThreads(1)
    except ImportError:  # pragma: no cover - OpenCV is a dependency
        pass
    if parent_pid is not None:
        # a job's progress bar would create tqdm's default lock, a multiprocessing
        # semaphore; a worker stopped by Ctrl-C cannot release it and the resource
        # tracker then warns of a leak. One worker's bars need only a thread lock.
        tqdm.set_lock(threading.RLock())


def _exit_with_parent(parent_pid: int, period_s: float = 1.0) -> None:
    """End this pool worker once the process that started it is gone.

    A parent killed outright (SIGKILL, the OOM killer) cannot shut its pool down, and
    its workers would run their jobs to the end, holding the cores, with no one to
    report to. An orphan is re-parented, so its parent id changes.
    """
    while os.getppid() == parent_pid:
        time.sleep(period_s)
    os._exit(1)


# --------------------------------------------------------------------------- backends
class LocalBackend:
    """Jobs in a pool of ``workers`` processes on this machine (1: in this process).

    A worker that dies (killed by the OOM killer, a crash in native code) fails the
    jobs it was running, which are then retried on a fresh pool; it never hangs the run.
    Workers whose parent dies exit within a second or so instead of running on.
    """

    name = "local"

    def __init__(self, workers: int = 2):
        self.workers = check_workers(workers)
        self._executor: cf.ProcessPoolExecutor | None = None

    def describe(self) -> dict[str, Any]:
        return {"backend": self.name, "workers": self.workers}

    def __enter__(self) -> LocalBackend:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, *exc: object) -> None:
        # interrupted (Ctrl-C, SystemExit): stop the running jobs instead of waiting
        # for them; their results are lost, every finished job is saved already
        self.close(stop=exc_type is not None and not issubclass(exc_type, Exception))

    def run(self, jobs: Sequence[Job]) -> Iterator[tuple[int, bool, Any, float]]:
        """Yield ``(index, ok, output or error, seconds)`` as jobs finish."""
        if self.workers == 1:
            for i, job in enumerate(jobs):
                yield (i, *_execute(job.fn, job.kwargs))
            return
        yield from self._pool_run(jobs)

    def _pool(self) -> cf.ProcessPoolExecutor:
        if self._executor is None:
            saved = {k: os.environ.get(k) for k in SINGLE_THREADED}
            os.environ.update(SINGLE_THREADED)  # spawned workers read it when numpy loads
            try:
                self._executor = cf.ProcessPoolExecutor(
                    self.workers,
                    mp_context=mp.get_context("spawn"),
                    initializer=_init_worker,
                    initargs=(True, os.getpid()),
                )
                # start the workers now, while the environment is single-threaded
                list(self._executor.map(_noop, range(self.workers)))
            finally:
                for k, v in saved.items():
                    if v is None:
                        os.environ.pop(k, None)
                    else:
                        os.environ[k] = v
        return self._executor

    def close(self, stop: bool = False) -> None:
        """Stop the worker processes (a later :meth:`run` starts new ones).

        Parameters
        ----------
        stop : bool
            Terminate the workers at once, abandoning the jobs they are running,
            instead of waiting for those jobs to finish.
        """
        if self._executor is None:
            return
        executor, self._executor = self._executor, None
        if not stop:
            executor.shutdown(wait=True, cancel_futures=True)
            return
        processes = list((getattr(executor, "_processes", None) or {}).values())
        for proc in processes:
            proc.terminate()
        for proc in processes:
            proc.join(timeout=5.0)
        # the workers are gone: the pool notices at once and frees its queues
        executor.shutdown(wait=True, cancel_futures=True)

    def _discard_pool(self) -> None:
        """Drop a broken pool; the next :meth:`_pool` starts fresh workers."""
        self._executor.shutdown(wait=False, cancel_futures=True)
        self._executor = None

    def _pool_run(self, jobs: Sequence[Job]) -> Iterator[tuple[int, bool, Any, float]]:
        queue = list(range(len(jobs)))[::-1]
        # Jobs that were running when a worker died: the pool cannot say whose worker
        # it was, so they run again one at a time, and only a job that kills its
        # worker while running alone is charged with the failure.
        suspects: list[int] = []
        isolating: int | None = None
        running: dict[cf.Future, int] = {}
        while queue or running or suspects:
            pool = self._pool()
            # a worker can die between two submissions: the pool then refuses new jobs,
            # which go back where they came from (they never ran)
            refused = False
            if not running and suspects:
                isolating = suspects.pop()
                if not _submit(pool, running, jobs, isolating):
                    suspects.append(isolating)
                    isolating, refused = None, True
            elif isolating is None:
                while queue and len(running) < self.workers:
                    i = queue.pop()
                    if not _submit(pool, running, jobs, i):
                        queue.append(i)
                        refused = True
                        break
            if refused and not running:
                self._discard_pool()
                continue
            done, _ = cf.wait(running, return_when=cf.FIRST_COMPLETED)
            alone = len(running) == 1
            broken: list[int] = []
            for fut in done:
                i = running.pop(fut)
                try:
                    result = fut.result()
                except BrokenProcessPool:
                    broken.append(i)
                    continue
                if i == isolating:
                    isolating = None
                yield (i, *result)
            if broken:
                broken += list(running.values())  # they died with the pool
                running.clear()
                self._discard_pool()
                isolating = None
                if alone:
                    yield broken[0], False, {"error": _DIED, "traceback": _DIED}, math.nan
                else:
                    suspects.extend(broken)


_DIED = (
    "the worker process died while running this job (killed, out of memory, or a crash "
    "in native code)"
)


def _call(job: Job) -> tuple[str, Mapping[str, Any]]:
    return job.fn, job.kwargs


def _submit(
    pool: cf.ProcessPoolExecutor, running: dict[cf.Future, int], jobs: Sequence[Job], i: int
) -> bool:
    """Submit job ``i`` to ``pool`` (recorded in ``running``); False if the pool is broken."""
    try:
        running[pool.submit(_execute, *_call(jobs[i]))] = i
    except BrokenProcessPool:
        return False
    return True


def _noop(_: int) -> None:
    return None


class RayBackend:
    """Jobs as Ray tasks: on an existing cluster (``address``) or a local Ray instance.

    Needs the optional ``cluster`` extra (``pip install "vc_gym[cluster]"``). Every
    node must have vc_gym installed (and any module a job names, such as a user's
    tracker factory). A task whose worker dies is reported as a failed attempt.

    Parameters
    ----------
    address : str, optional
        ``"ray://host:10001"``, ``"host:6379"`` or ``"auto"`` to join a running
        cluster; ``None`` starts a local instance with ``workers`` CPUs.
    workers : int, optional
        CPUs of the local instance (default: all of this machine's).
    """

    name = "ray"

    def __init__(self, address: str | None = None, workers: int | None = None):
        try:
            import ray  # noqa: F401
        except ImportError:
            raise ValueError("the ray backend needs Ray: pip install 'vc_gym[cluster]'") from None
        if workers is not None:
            check_workers(workers)
        self.address = address
        self.workers = workers
        self._started = False

    def describe(self) -> dict[str, Any]:
        import ray

        return {
            "backend": self.name,
            "workers": self.workers,
            "cluster": "existing" if self.address else "local",
            "ray": ray.__version__,
        }

    def _start(self) -> None:
        import ray

        if ray.is_initialized():
            return
        kwargs: dict[str, Any] = {
            "include_dashboard": False,
            "logging_level": "ERROR",
            "log_to_driver": False,
            "runtime_env": {"env_vars": dict(SINGLE_THREADED)},
        }
        if self.address:
            ray.init(address=self.address, **kwargs)
        else:
            ray.init(num_cpus=self.workers or os.cpu_count(), **kwargs)
        self._started = True

    def close(self) -> None:
        """Shut Ray down if this backend started it."""
        if self._started:
            import ray

            ray.shutdown()
            self._started = False

    def __enter__(self) -> RayBackend:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def run(self, jobs: Sequence[Job]) -> Iterator[tuple[int, bool, Any, float]]:
        """Yield ``(index, ok, output or error, seconds)`` as jobs finish."""
        import ray

        self._start()
        task = ray.remote(num_cpus=1, max_retries=0)(_ray_execute)
        refs = {task.remote(job.fn, dict(job.kwargs)): i for i, job in enumerate(jobs)}
        pending = list(refs)
        try:
            while pending:
                done, pending = ray.wait(pending, num_returns=1)
                for ref in done:
                    i = refs[ref]
                    try:
                        yield (i, *ray.get(ref))
                    except ray.exceptions.RayError as exc:
                        msg = f"the Ray task failed ({type(exc).__name__}: {exc})"
                        yield i, False, {"error": msg.splitlines()[0], "traceback": msg}, math.nan
        finally:
            for ref in pending:  # interrupted: do not leave tasks running
                ray.cancel(ref, force=True)


def _ray_execute(fn: str, kwargs: dict[str, Any]) -> tuple[bool, Any, float]:
    _init_worker()
    return _execute(fn, kwargs)


def make_backend(
    name: str = "local", workers: int | None = None, address: str | None = None
) -> LocalBackend | RayBackend:
    """A backend by name: ``"local"`` (default 2 workers) or ``"ray"``.

    Raises
    ------
    ValueError
        For an unknown name, an address with the local backend, or ``workers`` outside
        ``1..max_workers()`` (:data:`MAX_WORKERS_PER_CPU` per CPU, at most
        :data:`MAX_WORKERS`); checked before any worker starts.
    """
    if workers is not None:
        check_workers(workers)
    if name == "local":
        if address:
            raise ValueError("--address is for the ray backend")
        return LocalBackend(2 if workers is None else workers)
    if name == "ray":
        return RayBackend(address, workers)
    raise ValueError(f"unknown backend {name!r}; choose from {BACKENDS}")


# --------------------------------------------------------------------------- the run


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
        return self.out / "jobs" / stage / f"{key}.json"

    def _saved(self, stage: str, job: Job) -> JobOutcome | None:
        rec = self._read_job_file(self.job_file(stage, job.key))
        if rec is None or not rec.get("ok"):
            return None  # failed last time: try again
        path = self.job_file(stage, job.key)
        if rec.get("fn") != job.fn or rec.get("kwargs") != json.loads(json.dumps(job.kwargs)):
            raise ValueError(f"{path} was written by a job with other arguments; use another --out")
        return JobOutcome(
            job.key,
            True,
            rec["output"],
            None,
            rec.get("attempts", 1),
            rec.get("seconds"),
            resumed=True,
        )

    @staticmethod
    def _read_job_file(path: Path) -> dict[str, Any] | None:
        """A saved job's record, or None where there is none to trust: no regular file
        (a FIFO or device is never opened), one larger than :data:`MAX_JOB_FILE_BYTES`,
        a torn or foreign file, or a record without an output object."""
        if not path.is_file():
            return None
        try:
            rec = read_json(path, MAX_JOB_FILE_BYTES)
        except ValueError:
            return None  # its job runs again and replaces it
        if not isinstance(rec, dict) or (rec.get("ok") and not isinstance(rec.get("output"), dict)):
            return None
        return rec

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
            saved = self._saved(stage, job)
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
                rec = self._read_job_file(path)
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
        rec = {
            "key": job.key,
            "fn": job.fn,
            "kwargs": dict(job.kwargs),
            "ok": outcome.ok,
            "attempts": outcome.attempts,
            "seconds": outcome.seconds if outcome.seconds == outcome.seconds else None,
            "output": outcome.output,
        }
        if not outcome.ok:
            rec["error"] = outcome.error
            rec["traceback"] = out.get("traceback")
        write_json(self.job_file(stage, job.key), rec)

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
