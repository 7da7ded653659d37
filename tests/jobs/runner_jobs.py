"""Small job functions for the runner tests (importable by worker processes)."""

from __future__ import annotations

import os
import time
from pathlib import Path


def square(
    x: float, log: str | None = None, sleep_s: float = 0.0, started: str | None = None
) -> dict:
    """Figures of ``x``; creates ``started/x`` when it starts (so that a test can wait for
    busy workers by polling) and appends ``x`` to ``log`` when done (to count executions)."""
    if started is not None:
        Path(started, f"{x}").touch()
    time.sleep(sleep_s)
    if log is not None:
        with open(log, "a") as fh:
            fh.write(f"{x}\n")
    return {"x": x, "square": x * x, "timing": {"pid": os.getpid()}}


def flaky(marker: str) -> dict:
    """Fails the first time (creating ``marker``), succeeds after."""
    path = Path(marker)
    if not path.exists():
        path.write_text("failed once")
        raise RuntimeError("transient failure")
    return {"ok": True}


def broken(reason: str) -> dict:
    raise ValueError(reason)


def die() -> dict:
    """The worker process dies at once, as if killed by the OOM killer."""
    os._exit(9)
