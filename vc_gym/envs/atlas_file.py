"""Learning phases saved to a file: learn once, load everywhere (no robot motion).

The learning phase is the expensive part of the learn-then-home task (~40 s of simulation
for the paper's four spots). Parallel training workers, evaluation jobs and repeated runs
need the same place learned the same way, so a learner can read its result from an atlas
file instead (:class:`SavedAtlas`), or learn it once and write it for the others
(:class:`AtlasFile`, what ``vc_gym/LearnThenHome-v0``'s ``atlas_file=`` uses).
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from vc_gym.compass import CompassAtlas
from vc_gym.envs.learning import Learner, LearningConfig, LearningResult
from vc_gym.envs.place_cache import default_cache_dir, file_lock
from vc_gym.errors import MapFileError

__all__ = ["AtlasFile", "SavedAtlas"]


def _result_of(atlas: CompassAtlas, meta: Mapping[str, Any]) -> LearningResult:
    spots = {n: tuple(map(float, p)) for n, p in zip(atlas.names, atlas.positions, strict=True)}
    return LearningResult(
        atlas, spots, odometry_turn_scale=float(meta.get("odometry_turn_scale", 1.0))
    )


class SavedAtlas:
    """A task learner that loads a saved atlas instead of learning (no robot motion).

    Parameters
    ----------
    path : path-like
        An atlas written by :meth:`CompassAtlas.save`.
    """

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)

    def __repr__(self) -> str:
        return f"SavedAtlas({str(self.path)!r})"

    def __call__(self, room, config: LearningConfig) -> LearningResult:
        atlas, meta = CompassAtlas.load_with_metadata(self.path)
        if atlas.compasses[0].config != config.compass:
            raise MapFileError(
                f"{self.path}: learned with {atlas.compasses[0].config}, the task expects "
                f"{config.compass}"
            )
        return _result_of(atlas, meta)


class AtlasFile:
    """Run ``learner`` once and keep its atlas in ``path``; later calls load the file.

    The file's metadata holds ``spec`` (everything that shapes the learning: scene,
    learning settings, learner, seed, room options); a file learned with another spec
    is refused with a :class:`~vc_gym.errors.MapFileError` rather than silently used.
    Processes that share ``path`` take a lock (POSIX), so one learns while the others
    wait and then load. The lock file lies in the place cache's folder
    (:func:`~vc_gym.envs.place_cache.default_cache_dir`, ``locks/``, named by the
    hash of ``path``'s absolute form), so that a run leaves nothing but the atlas in
    the folder of ``path`` (often the working folder).

    Parameters
    ----------
    path : path-like
        The atlas file (``.npz``), created if missing (written atomically).
    learner : callable
        ``learner(room, config) -> LearningResult``, run when the file is missing.
    spec : mapping
        JSON values that identify the learning (compared with the file's).
    """

    def __init__(self, path: str | os.PathLike, learner: Learner, spec: Mapping[str, Any]):
        self.path = Path(path)
        if self.path.suffix != ".npz":
            raise ValueError(f"atlas_file must end in .npz, got {str(self.path)!r}")
        if self.path.is_dir():
            raise ValueError(f"atlas_file {str(self.path)!r} is a folder")
        if not self.path.parent.is_dir():
            raise ValueError(f"atlas_file {str(self.path)!r}: its folder does not exist")
        self.learner = learner
        self.spec = json.loads(json.dumps(dict(spec), sort_keys=True))
        #: Whether the last call wrote the file (learned, or from a place cache: True) or
        #: loaded it (False).
        self.learned = False

    def __repr__(self) -> str:
        return f"AtlasFile({str(self.path)!r}, {self.learner!r})"

    def _load(self) -> LearningResult:
        atlas, meta = CompassAtlas.load_with_metadata(self.path)
        if meta.get("spec") != self.spec:
            raise MapFileError(
                f"{self.path}: learned with {meta.get('spec')!r}, this task learns with "
                f"{self.spec!r}; delete the file or choose another atlas_file"
            )
        return _result_of(atlas, meta)

    @property
    def lock_path(self) -> Path:
        """The lock file of ``path``: in the place cache's folder, never beside ``path``."""
        name = hashlib.sha256(str(self.path.resolve()).encode()).hexdigest()[:32]
        return default_cache_dir() / "locks" / f"{name}.npz.lock"

    def __call__(
        self, room, config: LearningConfig, learner: Learner | None = None
    ) -> LearningResult:
        """Load the file, or run ``learner`` (default: the file's own learner, e.g. a
        place cache's learner standing in for it) and write the file."""
        with file_lock(self.lock_path):
            if self.path.exists():
                self.learned = False
                return self._load()
            result = (learner or self.learner)(room, config)
            if not isinstance(result, LearningResult):
                return result  # the task env reports a learner that returns the wrong type
            result.atlas.save(
                self.path,
                metadata={
                    "spec": self.spec,
                    "spots": {n: list(p) for n, p in result.spots.items()},
                    "odometry_turn_scale": float(result.odometry_turn_scale),
                },
            )
            self.learned = True
            return result
