"""Deprecated import place of the job runner's names (served for one release).

Import them from the module of their concept instead: :mod:`vc_gym.jobs.job` (``Job``,
``JobOutcome``, ``call_job``, ``MAX_JOB_FILE_BYTES``), :mod:`vc_gym.jobs.workers`
(``check_workers``, ``max_workers``, ``worker_cache``, the worker limits),
:mod:`vc_gym.jobs.backends` (``LocalBackend``, ``RayBackend``, ``make_backend``,
``BACKENDS``), :mod:`vc_gym.jobs.run` (``ExperimentRun``, ``package_versions``) and
:mod:`vc_gym.jobs.output` (``check_out_dir``). Each name read from here warns with a
``DeprecationWarning`` and is the same object as at its new place.
"""

from __future__ import annotations

from types import ModuleType

from vc_gym.deprecation import moved_names
from vc_gym.jobs import backends, job, output, run, workers

#: Each name served here and the module that holds it.
MOVED: dict[str, ModuleType] = {
    **{name: job for name in ("MAX_JOB_FILE_BYTES", "Job", "JobOutcome", "call_job")},
    **{
        name: workers
        for name in (
            "MAX_WORKERS",
            "MAX_WORKERS_PER_CPU",
            "SINGLE_THREADED",
            "check_workers",
            "max_workers",
            "worker_cache",
        )
    },
    **{name: backends for name in ("BACKENDS", "LocalBackend", "RayBackend", "make_backend")},
    **{name: run for name in ("TIMING", "ExperimentRun", "package_versions")},
    "check_out_dir": output,
}


__getattr__ = moved_names(__name__, MOVED)
