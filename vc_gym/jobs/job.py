"""A job: one independent piece of an experiment, how it runs, and its saved file.

A :class:`Job` names a top-level function (``"package.module:function"``) and its JSON
keyword arguments, and returns a JSON object of figures. Its result must depend only on
its arguments (seeds and the paths of saved atlases), never on which worker ran what
before it, so the same seed gives the same figures whatever backend or worker count ran
the jobs.

A finished job is saved as one JSON record (:func:`job_record`); a run that resumes
reads it back (:func:`read_job_file`) and takes it as done only if it was written by the
same function with the same arguments (:func:`saved_outcome`). A record that cannot be
trusted (torn, foreign, larger than :data:`MAX_JOB_FILE_BYTES`, not a regular file)
counts as not saved: its job runs again.
"""

from __future__ import annotations

import importlib
import json
import time
import traceback
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from vc_gym.jobs.output import read_json

__all__ = [
    "MAX_JOB_FILE_BYTES",
    "Job",
    "JobOutcome",
    "attempt_job",
    "call_job",
    "job_record",
    "read_job_file",
    "saved_outcome",
]

#: Largest saved job file read when a run resumes (bytes); a larger one is not
#: trusted and its job runs again. Job outputs are figures, kilobytes each.
MAX_JOB_FILE_BYTES = 64 * 2**20


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


def attempt_job(fn: str, kwargs: Mapping[str, Any]) -> tuple[bool, Any, float]:
    """One attempt at a job, as a worker runs it: ``(ok, output or error, seconds)``.

    Never raises but for ``KeyboardInterrupt``: a job's failure is data, returned as
    ``{"error": one line, "traceback": the full text}`` for the run to report.
    """
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


def job_record(job: Job, outcome: JobOutcome, traceback_text: str | None = None) -> dict[str, Any]:
    """The JSON record a finished job is saved as (with the error and its traceback
    when it failed)."""
    rec = {
        "key": job.key,
        "fn": job.fn,
        "kwargs": dict(job.kwargs),
        "ok": outcome.ok,
        "attempts": outcome.attempts,
        "seconds": outcome.seconds if outcome.seconds == outcome.seconds else None,  # NaN: None
        "output": outcome.output,
    }
    if not outcome.ok:
        rec["error"] = outcome.error
        rec["traceback"] = traceback_text
    return rec


def read_job_file(path: Path) -> dict[str, Any] | None:
    """A saved job's record, or None where there is none to trust: no regular file (a
    FIFO or device is never opened), one larger than :data:`MAX_JOB_FILE_BYTES`, a torn
    or foreign file, or a record without an output object."""
    if not path.is_file():
        return None
    try:
        rec = read_json(path, MAX_JOB_FILE_BYTES)
    except ValueError:
        return None  # its job runs again and replaces it
    if not isinstance(rec, dict) or (rec.get("ok") and not isinstance(rec.get("output"), dict)):
        return None
    return rec


def saved_outcome(job: Job, path: Path) -> JobOutcome | None:
    """The outcome of ``job`` saved at ``path`` by an earlier attempt of the run, or None
    if it must run (no record to trust, or the job failed there).

    Raises
    ------
    ValueError
        The record was written by another function or other arguments: the folder
        belongs to another run.
    """
    rec = read_job_file(path)
    if rec is None or not rec.get("ok"):
        return None  # failed last time: try again
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
