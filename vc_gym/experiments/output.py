"""Writing results atomically: a JSON file or a figure appears whole or not at all.

Figures are :class:`matplotlib.figure.Figure` objects made by :func:`new_figure`, never
through ``pyplot``: nothing here switches matplotlib's global backend or keeps figures
alive in pyplot's registry, so the package can plot inside a user's notebook session.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from vc_gym.persistence import write_atomic

__all__ = ["new_figure", "save_figure", "write_json"]


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
