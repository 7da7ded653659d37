"""Learned places kept on disk: learn a place once, load it in every later env and run.

The scripted learning phase of ``vc_gym/LearnThenHome-v0`` and ``vc_gym/Homing-v0`` is
the expensive part of their first reset (about 50 s for the paper's four spots at
``learn_time_s=5``). Everything that shapes the learned place is known before it is
learned: the scene and the room's settings, the learning settings (spot distance, time per
direction, the compass' configuration), the learner, and the seed the room is reset with
for the learning phase. :class:`PlaceCache` hashes those settings into a file name in a
cache folder; the first env that needs a place learns it (a progress bar on stderr) and
writes it there, atomically; every later env, in this process, in another worker of a
vector env or in a later run, loads it instead. Envs that need the same place at the same
time take a lock beside the file (``NAME.npz.lock``): one learns, the others wait and
load.

A place loaded from the cache gives the same episodes, bit for bit, as one learned anew:
the file also keeps the state of the room's random generator after the learning phase,
which is all the learning leaves behind that the episode after it reads (the kidnapping
resets the robot and the physics).

The folder is ``$VC_GYM_CACHE`` if that is set, else ``$XDG_CACHE_HOME/vc_gym/places``
(``~/.cache/vc_gym/places`` without ``XDG_CACHE_HOME``). ``place_cache=False`` (or
``None``) turns the cache off for one env; :meth:`PlaceCache.clear` (``vc_gym.envs.
PlaceCache().clear()``) deletes the cached places.

A cached file is a :meth:`~vc_gym.compass.CompassAtlas.save` file: it is read without
unpickling and with bounded sizes (:func:`vc_gym.persistence.load_npz_checked`). One that
cannot be read, or that holds another place than its name says, is reported with a
warning, deleted and learned again; it is never trusted.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import math
import os
import re
import warnings
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

import vc_gym
from vc_gym.compass import CompassAtlas
from vc_gym.compass.atlas import ATLAS_SCHEMA_VERSION
from vc_gym.envs.learning import (
    Learner,
    LearningConfig,
    LearningResult,
    ScriptedLearner,
    ScriptedLearning,
)
from vc_gym.errors import MapFileError

try:  # POSIX: envs that need the same place wait for the first one to learn it
    import fcntl
except ImportError:  # pragma: no cover - Windows: each env may learn it once
    fcntl = None

__all__ = [
    "CACHE_ENV_VAR",
    "PLACE_CACHE_SCHEMA",
    "CachedLearner",
    "PlaceCache",
    "default_cache_dir",
    "file_lock",
    "place_key_value",
]

#: The environment variable that names the cache folder.
CACHE_ENV_VAR = "VC_GYM_CACHE"
#: Version of what a cache key means; part of every key (with the package's version and
#: the atlas file's schema version), so that a change of either starts a new cache entry
#: instead of loading an old one.
PLACE_CACHE_SCHEMA = 1
#: Name of a cached place: the first 32 hex digits of the key's SHA-256.
_NAME = re.compile(r"^[0-9a-f]{32}\.npz$")
#: Largest integer of a saved generator state (PCG64: 128-bit state and increment).
_STATE_LIMIT = 2**128


def default_cache_dir() -> Path:
    """The cache folder: ``$VC_GYM_CACHE``, else ``$XDG_CACHE_HOME/vc_gym/places``, else
    ``~/.cache/vc_gym/places``."""
    given = os.environ.get(CACHE_ENV_VAR)
    if given:
        return Path(given).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base).expanduser() / "vc_gym" / "places"


def place_key_value(value: Any) -> Any:
    """``value`` as plain JSON data for a cache key, or raise :class:`TypeError`.

    Numbers, text, booleans and ``None`` stay as they are (floats as their ``repr``, so
    that ``-0.0`` and ``0.0`` differ as they may in a simulation), sequences become
    lists, mappings dicts with text keys, dataclasses their type name and fields.
    Anything else has no description that is the same in every run, so it cannot key a
    cached place.
    """
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
        return {"type": type(value).__qualname__, **place_key_value(fields)}
    if isinstance(value, Mapping):
        return {
            str(k): place_key_value(v) for k, v in sorted(value.items(), key=lambda kv: str(kv[0]))
        }
    if isinstance(value, (list, tuple, np.ndarray)):
        return [place_key_value(v) for v in value]
    raise TypeError(f"{type(value).__name__} values cannot key a cached place")


@contextlib.contextmanager
def file_lock(path: Path) -> Iterator[None]:
    """Hold an exclusive ``flock`` on ``path`` (created if missing) while in the block.

    The lock file is left in place: deleting it while another process waits on it would
    let a third one lock a new file of the same name at the same time.
    """
    if fcntl is None:  # pragma: no cover
        yield
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _finite_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _generator_state(room: Any) -> dict[str, Any]:
    state = room.np_random.bit_generator.state
    return json.loads(json.dumps(state))


def _restore_generator(room: Any, state: Any, path: Path) -> None:
    """Set the room's generator to a saved state, refusing anything but a PCG64 state of
    the room's own kind."""
    current = room.np_random.bit_generator.state
    ok = (
        isinstance(state, dict)
        and set(state) == set(current)
        and state.get("bit_generator") == current["bit_generator"]
        and isinstance(state.get("state"), dict)
        and set(state["state"]) == set(current["state"])
        and all(
            isinstance(v, int) and not isinstance(v, bool) and 0 <= v < _STATE_LIMIT
            for v in state["state"].values()
        )
        and all(
            isinstance(state[k], int) and not isinstance(state[k], bool) and 0 <= state[k] < 2**32
            for k in state
            if k not in ("bit_generator", "state")
        )
    )
    if not ok:
        raise MapFileError(f"{path}: 'room_generator' is not a {current['bit_generator']} state")
    room.np_random.bit_generator.state = state


class CachedLearner:
    """A learner that loads its place from a :class:`PlaceCache` file, or learns and
    writes it there (what the task env runs when its place is cacheable).

    Parameters
    ----------
    cache : PlaceCache
        Where the place is kept.
    learner : callable
        ``learner(room, config) -> LearningResult``, run when the place is not cached.
    key : mapping
        Plain data (:func:`place_key_value`) naming everything that shapes the place.
    progress : bool
        Show a progress bar (stderr) while the place is learned.
    """

    def __init__(
        self, cache: PlaceCache, learner: Learner, key: Mapping[str, Any], progress: bool = True
    ):
        self.cache = cache
        self.learner = learner
        self.key = cache.full_key(key)
        self.path = cache.path_for(key)
        self.progress = bool(progress)
        #: Whether the last call learned the place (True) or loaded it (False).
        self.learned = False

    def __repr__(self) -> str:
        return f"CachedLearner({str(self.path)!r}, {self.learner!r})"

    def _load(self, room: Any) -> LearningResult:
        atlas, meta = CompassAtlas.load_with_metadata(self.path)
        if meta.get("key") != self.key:
            raise MapFileError(f"{self.path}: holds another place than its name says")
        spots = meta.get("spots")
        if not isinstance(spots, dict) or set(spots) != set(atlas.names):
            raise MapFileError(f"{self.path}: 'spots' does not name the atlas' spots")
        scale = meta.get("odometry_turn_scale")
        if not _finite_number(scale):
            raise MapFileError(f"{self.path}: 'odometry_turn_scale' is not a finite number")
        result_spots = {}
        for name, xy in spots.items():
            if not isinstance(xy, list) or len(xy) != 2 or not all(_finite_number(v) for v in xy):
                raise MapFileError(f"{self.path}: spot {name!r} is not two finite numbers")
            result_spots[name] = (float(xy[0]), float(xy[1]))
        path = meta.get("true_path", [])
        if not isinstance(path, list) or not all(
            isinstance(p, list) and len(p) == 3 and all(_finite_number(v) for v in p) for p in path
        ):
            raise MapFileError(f"{self.path}: 'true_path' is not a list of (x, y, yaw)")
        _restore_generator(room, meta.get("room_generator"), self.path)
        return LearningResult(
            atlas,
            result_spots,
            true_path=[tuple(float(v) for v in p) for p in path],
            odometry_turn_scale=float(scale),
        )

    def _learn(self, room: Any, config: LearningConfig) -> LearningResult:
        if isinstance(self.learner, ScriptedLearning):
            # the scripted learner's own bar counts the frames of the four spots
            return ScriptedLearner(room, config, progress=self.progress).learn()
        with tqdm(total=1, desc="learn the place", unit="place", disable=not self.progress) as bar:
            result = self.learner(room, config)
            bar.update(1)
        return result

    def __call__(self, room: Any, config: LearningConfig) -> LearningResult:
        with file_lock(self.path.with_name(self.path.name + ".lock")):
            if self.path.exists():
                try:
                    result = self._load(room)
                except MapFileError as exc:
                    warnings.warn(
                        f"the cached place {self.path} cannot be used ({exc}); it is "
                        "deleted and learned again",
                        RuntimeWarning,
                        stacklevel=2,
                    )
                    self.path.unlink(missing_ok=True)
                else:
                    self.learned = False
                    return result
            result = self._learn(room, config)
            if not isinstance(result, LearningResult):
                return result  # the task env reports a learner that returns the wrong type
            result.atlas.save(
                self.path,
                metadata={
                    "key": self.key,
                    "spots": {n: [float(v) for v in p] for n, p in result.spots.items()},
                    "odometry_turn_scale": float(result.odometry_turn_scale),
                    "true_path": [[float(v) for v in p] for p in result.true_path],
                    "room_generator": _generator_state(room),
                },
            )
            self.learned = True
            return result


class PlaceCache:
    """A folder of learned places, one ``.npz`` file per set of learning settings.

    Parameters
    ----------
    folder : path-like, optional
        The cache folder (created when a place is first written). Default:
        :func:`default_cache_dir`, read when the cache is made.

    Examples
    --------
    >>> from vc_gym.envs import PlaceCache
    >>> PlaceCache("/tmp/vc_gym_places").clear()  # doctest: +SKIP
    0
    """

    def __init__(self, folder: str | os.PathLike | None = None):
        if folder is not None and not isinstance(folder, (str, os.PathLike)):
            raise ValueError(f"the place cache folder must be a path, got {folder!r}")
        self.folder = Path(folder).expanduser() if folder is not None else default_cache_dir()
        if self.folder.exists() and not self.folder.is_dir():
            raise ValueError(f"the place cache folder {str(self.folder)!r} is a file")

    def __repr__(self) -> str:
        return f"PlaceCache({str(self.folder)!r})"

    @staticmethod
    def full_key(key: Mapping[str, Any]) -> dict[str, Any]:
        """``key`` with the versions that change what a place means (plain JSON data)."""
        return {
            "place_cache_schema": PLACE_CACHE_SCHEMA,
            "atlas_schema_version": ATLAS_SCHEMA_VERSION,
            "vc_gym": vc_gym.__version__,
            **place_key_value(dict(key)),
        }

    def path_for(self, key: Mapping[str, Any]) -> Path:
        """The file of the place ``key`` names (SHA-256 of its canonical JSON)."""
        text = json.dumps(self.full_key(key), sort_keys=True, separators=(",", ":"))
        return self.folder / f"{hashlib.sha256(text.encode()).hexdigest()[:32]}.npz"

    def learner(
        self, learner: Learner, key: Mapping[str, Any], progress: bool = True
    ) -> CachedLearner:
        """A :class:`CachedLearner` for the place ``key`` names, learned by ``learner``."""
        return CachedLearner(self, learner, key, progress)

    def places(self) -> list[Path]:
        """The cached places' files, sorted."""
        if not self.folder.is_dir():
            return []
        return sorted(p for p in self.folder.iterdir() if _NAME.match(p.name) and p.is_file())

    def clear(self) -> int:
        """Delete every cached place (and its lock file); return how many places.

        Only files this cache writes are touched (``<32 hex digits>.npz`` and their
        ``.lock``), so a folder shared with other files keeps them.
        """
        n = 0
        for p in self.places():
            with file_lock(p.with_name(p.name + ".lock")):
                p.unlink(missing_ok=True)
            n += 1
        if self.folder.is_dir():
            for p in self.folder.iterdir():
                if p.name.endswith(".npz.lock") and _NAME.match(p.name[: -len(".lock")]):
                    p.unlink(missing_ok=True)
        return n
