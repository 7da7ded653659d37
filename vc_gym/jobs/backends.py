"""Backends: who runs a run's jobs, a local process pool or Ray.

:class:`LocalBackend` runs jobs in a pool of worker processes on this machine (one
worker runs them in this process); :class:`RayBackend` runs them as Ray tasks, on a
local Ray instance or an existing cluster by address. :func:`make_backend` picks one by
name. Both yield ``(index, ok, output or error, seconds)`` as jobs finish, keep their
workers single-threaded (:mod:`vc_gym.jobs.workers`) and report a job whose worker died
as a failed attempt instead of hanging the run.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import math
import multiprocessing as mp
import os
import signal
import threading
from collections.abc import Iterator, Mapping, Sequence
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from vc_gym.jobs.job import Job, attempt_job
from vc_gym.jobs.workers import SINGLE_THREADED, check_workers, init_worker

__all__ = ["BACKENDS", "LocalBackend", "RayBackend", "make_backend"]

#: Names :func:`make_backend` accepts.
BACKENDS = ("local", "ray")


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
                yield (i, *attempt_job(job.fn, job.kwargs))
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
                    initializer=init_worker,
                    initargs=(True, os.getpid()),
                )
                # start the workers now, while the environment is single-threaded (each
                # submit spawns one), with Ctrl-C ignored: a worker inherits that across
                # exec, so one still starting up never prints a KeyboardInterrupt
                # traceback; its initializer keeps ignoring it and the parent stops it
                with _sigint_ignored():
                    started = [self._executor.submit(_noop, i) for i in range(self.workers)]
                for future in started:
                    future.result()
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
        running[pool.submit(attempt_job, *_call(jobs[i]))] = i
    except BrokenProcessPool:
        return False
    return True


def _noop(_: int) -> None:
    return None


@contextlib.contextmanager
def _sigint_ignored() -> Iterator[None]:
    """SIGINT ignored in this process for the ``with`` block (main thread only: elsewhere
    Python cannot change signal handlers, and the block runs as it is)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


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
        task = ray.remote(num_cpus=1, max_retries=0)(_ray_attempt_job)
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


def _ray_attempt_job(fn: str, kwargs: dict[str, Any]) -> tuple[bool, Any, float]:
    init_worker()
    return attempt_job(fn, kwargs)


def make_backend(
    name: str = "local", workers: int | None = None, address: str | None = None
) -> LocalBackend | RayBackend:
    """A backend by name: ``"local"`` (default 2 workers) or ``"ray"``.

    Raises
    ------
    ValueError
        For an unknown name, an address with the local backend, or ``workers`` outside
        ``1..max_workers()`` (:func:`~vc_gym.jobs.workers.max_workers`); checked before
        any worker starts.
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
