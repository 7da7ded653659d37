"""Writing results atomically: a JSON file or a figure appears whole or not at all.

Figures are :class:`matplotlib.figure.Figure` objects made by :func:`new_figure`, never
through ``pyplot``: nothing here switches matplotlib's global backend or keeps figures
alive in pyplot's registry, so the package can plot inside a user's notebook session.
"""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from vc_gym.persistence import write_atomic

__all__ = [
    "check_out_dir",
    "check_out_file",
    "new_figure",
    "new_out_dir",
    "save_figure",
    "write_json",
]


def check_out_dir(path: str | os.PathLike) -> Path:
    """Make sure ``path`` is (or can become) a writable folder, before any work starts.

    Raises
    ------
    ValueError
        ``--out PATH: ...`` for an existing file or a place that cannot be written.
    """
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out}: exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".write-test-{os.getpid()}"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise ValueError(f"--out {out}: cannot write there ({exc.strerror or exc})") from None
    return out


@contextlib.contextmanager
def new_out_dir(path: str | os.PathLike) -> Iterator[Path]:
    """:func:`check_out_dir` for a run: if the run fails before it writes anything, a
    folder this call created is removed again (a refused argument leaves nothing)."""
    existed = Path(path).exists()
    out = check_out_dir(path)
    try:
        yield out
    except BaseException:
        if not existed and out.is_dir() and not any(out.iterdir()):
            out.rmdir()
        raise


def check_out_file(path: str | os.PathLike) -> Path:
    """Make sure a result file can be written at ``path``, before any work starts (its
    folder is created; an existing file there will be replaced).

    Raises
    ------
    ValueError
        ``--out PATH: ...`` for a folder or a place that cannot be written.
    """
    out = Path(path)
    if out.is_dir():
        raise ValueError(f"--out {out}: is a folder; give a file name (e.g. {out / 'bench.json'})")
    check_out_dir(out.parent if str(out.parent) else ".")
    return out


def write_json(path: str | os.PathLike, obj: object) -> None:
    """Write ``obj`` as indented JSON to ``path`` atomically (its folder is created)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(obj, indent=2)
    write_atomic(path, lambda tmp: Path(tmp).write_text(text))


def new_figure(**kwargs: Any) -> Figure:
    """A figure not registered with pyplot (``kwargs`` go to ``Figure``)."""
    return Figure(**kwargs)


def save_figure(fig: Figure, path: str | os.PathLike, dpi: int = 100) -> None:
    """Save a figure as PNG to ``path`` atomically (its folder is created)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=dpi, format="png"))
