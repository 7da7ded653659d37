"""The worker processes that run jobs: how many, how they start, what they keep.

Every backend keeps its workers' numeric libraries single-threaded
(:data:`SINGLE_THREADED`): the workers are the parallelism (docs/design.md). A backend
has at most :func:`max_workers` workers (:data:`MAX_WORKERS_PER_CPU` per CPU, at most
:data:`MAX_WORKERS`). A worker may keep something expensive to build for its next jobs
(:func:`worker_cache`).
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Callable
from typing import Any

from tqdm import tqdm

__all__ = [
    "MAX_WORKERS",
    "MAX_WORKERS_PER_CPU",
    "SINGLE_THREADED",
    "check_workers",
    "init_worker",
    "max_workers",
    "worker_cache",
]

#: Most workers per CPU of this machine a local pool or a local Ray instance may have:
#: more only queue for the same cores, each holding its own simulator (~1 GB).
MAX_WORKERS_PER_CPU = 4
#: Most workers of a backend on any machine.
MAX_WORKERS = 256
#: Environment of every worker: one thread per numeric library.
SINGLE_THREADED = {
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENCV_FOR_THREADS_NUM": "1",
}

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


def init_worker(quiet: bool = False, parent_pid: int | None = None) -> None:
    """Set up this process as a worker: single-threaded numeric libraries.

    Parameters
    ----------
    quiet : bool
        Send the process' own stdout to ``/dev/null``.
    parent_pid : int, optional
        The process that started this pool worker: Ctrl-C is left to it, and the worker
        exits once it is gone.
    """
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
