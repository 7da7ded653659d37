"""What every experiment shares: sizes, seeds, the run folder, progress, checked
scenes and trackers, and the old places of moved names."""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from vc_gym.experiments.options import check_folder
from vc_gym.jobs.backends import LocalBackend, RayBackend, make_backend
from vc_gym.jobs.run import ExperimentRun
from vc_gym.localization import make_tracker

__all__ = [
    "SIZES",
    "ExperimentOptions",
    "check_scenes",
    "check_tracker_spec",
    "median_timings",
    "one_scene",
    "open_run",
    "pick_size",
    "safe_name",
    "scene_field_bounds",
]

#: ``quick``: the size the tests use (seconds to a minute); ``paper``: the size of the
#: ``paper`` report (all experiments in < 20 min on 2 cores); ``full``: the default.
SIZES = ("quick", "paper", "full")


@dataclass(frozen=True)
class ExperimentOptions:
    """Options every experiment takes (the CLI's common flags).

    Attributes
    ----------
    seed : int
        Base seed: learning seeds, kidnappings and view poses all derive from it.
    size : str
        ``"quick"``, ``"paper"`` or ``"full"`` (:data:`SIZES`).
    backend : LocalBackend or RayBackend, optional
        Who runs the jobs (default: a local pool of 2 workers).
    atlas_dir : path-like, optional
        A folder of saved atlases to reuse (``--atlas DIR``).
    video : int
        Write the first N homing episodes as MP4.
    progress : bool
        Show progress bars.
    """

    seed: int = 0
    size: str = "full"
    backend: LocalBackend | RayBackend | None = None
    atlas_dir: str | os.PathLike | None = None
    video: int = 0
    progress: bool = True

    def __post_init__(self) -> None:
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ValueError(f"seed must be an int >= 0, got {self.seed!r}")
        if self.size not in SIZES:
            raise ValueError(f"size must be one of {SIZES}, got {self.size!r}")
        if isinstance(self.video, bool) or not isinstance(self.video, int) or self.video < 0:
            raise ValueError(f"video must be an int >= 0, got {self.video!r}")
        if self.atlas_dir is not None:
            check_folder("--atlas", self.atlas_dir)


def pick_size(table: Mapping[str, Mapping[str, Any]], size: str) -> dict[str, Any]:
    """The entry of ``table`` for ``size`` (every experiment has one per size)."""
    return dict(table[size])


def open_run(
    out_dir: str | os.PathLike, name: str, opts: ExperimentOptions, settings: Mapping[str, Any]
) -> ExperimentRun:
    """The run folder of experiment ``name`` with its settings recorded."""
    backend = opts.backend if opts.backend is not None else make_backend("local")
    return ExperimentRun(
        out_dir,
        name,
        backend,
        {"seed": opts.seed, "size": opts.size, **settings},
        progress=opts.progress,
        owns_backend=opts.backend is None,
    )


def scene_field_bounds(scene: str) -> tuple[float, float, float, float]:
    """``(x0, x1, y0, y1)`` of a registered scene's field (builds the scene once)."""
    from vc_gym.sim.aibo_room import AiboRoomEnv
    from vc_gym.sim.scenes import check_scene_name

    check_scene_name(scene)
    room = AiboRoomEnv(scene=scene)
    try:
        room.reset(seed=0)
        return tuple(float(v) for v in room.scene.field_bounds)  # type: ignore[return-value]
    finally:
        room.close()


def median_timings(timings: Iterable[Mapping[str, float]]) -> dict[str, float]:
    """Per name, the median over jobs of their ``timing`` entries (ms), rounded."""
    per: dict[str, list[float]] = {}
    for timing in timings:
        for name, ms in timing.items():
            per.setdefault(name, []).append(ms)
    return {n: round(float(np.median(v)), 3) for n, v in per.items()}


def one_scene(scenes: Sequence[str] | None, experiment: str) -> str:
    """The one scene of an experiment that runs in a single scene (default robolab)."""
    scenes = list(scenes or ["robolab"])
    if len(scenes) != 1:
        raise ValueError(f"the {experiment} runs in one scene, got {scenes}")
    return scenes[0]


def check_scenes(scenes: Sequence[str]) -> list[str]:
    """Registered scene names, each once (a clear error otherwise)."""
    from vc_gym.sim.scenes import check_scene_name

    out = [check_scene_name(s) for s in scenes]
    if len(set(out)) != len(out):
        raise ValueError(f"scenes given twice: {out}")
    return out


def safe_name(name: str) -> str:
    """``name`` as part of a job key or file name: letters, digits, ``-_.`` (others
    become ``_``), at most 40 characters (``"tracker"`` if nothing is left)."""
    keep = "".join(c if c.isalnum() or c in "-_." else "_" for c in name)
    return keep[:40] or "tracker"


def check_tracker_spec(tracker: Any) -> Any:
    """A tracker that can travel to a worker: a name, ``"module:factory"`` or a dict."""
    if not (isinstance(tracker, str) or (isinstance(tracker, Mapping) and "type" in tracker)):
        raise ValueError(
            "an experiment's tracker must be a name, 'package.module:factory' or a "
            f'{{"type": ...}} dict (the jobs run in other processes), got {tracker!r}'
        )
    make_tracker(tracker)  # an unknown tracker fails here, not in a worker
    return json.loads(json.dumps(tracker))
