"""Trackers chosen by a name, a ``{"type": name, **kwargs}`` dict or a callable."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any

from vc_gym.localization.grid import GridTracker
from vc_gym.localization.kalman import KalmanTracker
from vc_gym.localization.particle import ParticleTracker
from vc_gym.localization.protocol import Tracker

__all__ = ["TRACKERS", "TrackerSpec", "make_tracker", "register_tracker"]

#: Tracker classes by name (``register_tracker`` adds to it).
TRACKERS: dict[str, Callable[..., Tracker]] = {
    "grid": GridTracker,
    "particle": ParticleTracker,
    "kalman": KalmanTracker,
}

TrackerSpec = str | Mapping[str, Any] | Callable[[], Tracker] | Tracker | None


def register_tracker(name: str, factory: Callable[..., Tracker], overwrite: bool = False) -> None:
    """Make ``factory(**kwargs)`` available as ``make_tracker(name)`` / ``{"type": name}``."""
    if not isinstance(name, str) or not name:
        raise ValueError(f"a tracker name must be a non-empty string, got {name!r}")
    if not callable(factory):
        raise ValueError(f"factory must be callable, got {factory!r}")
    if name in TRACKERS and not overwrite:
        raise ValueError(f"tracker {name!r} is registered already (pass overwrite=True)")
    TRACKERS[name] = factory


def _check(tracker: object, spec: object) -> Tracker:
    if not isinstance(tracker, Tracker):
        raise ValueError(
            f"tracker spec {spec!r} gave {type(tracker).__name__}, which has no "
            "reset(atlas, camera, dt_s) and update(image, head_pan_deg, odometry)"
        )
    return tracker


def _import_factory(path: str) -> Callable[[], Tracker]:
    module, _, attr = path.partition(":")
    try:
        obj: Any = importlib.import_module(module)
        for part in attr.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError, ValueError) as exc:
        raise ValueError(f"cannot import tracker factory {path!r}: {exc}") from None
    if not callable(obj):
        raise ValueError(f"tracker factory {path!r} is not callable")
    return obj


def make_tracker(spec: TrackerSpec = "grid") -> Tracker:
    """Build a tracker the HighwayEnv way.

    Parameters
    ----------
    spec : str, dict, callable or Tracker
        ``"grid"`` (the paper's filters, default), ``"particle"``, ``"kalman"`` or any
        name given to :func:`register_tracker`; ``"package.module:factory"`` (imported,
        then called with no arguments: a spec that survives pickling into worker
        processes and the command line); a dict ``{"type": name, **kwargs}``
        (the kwargs go to the tracker's constructor); a callable with no arguments
        that returns a tracker (a class, a ``functools.partial``, a lambda); or a
        tracker instance, returned as is. ``None`` means ``"grid"``.

    Returns
    -------
    Tracker

    Raises
    ------
    ValueError
        An unknown name (the message lists the known ones), a dict without ``type``,
        bad constructor arguments, or a callable that returns no tracker.
    """
    if spec is None:
        spec = "grid"
    if isinstance(spec, str) and ":" in spec and spec not in TRACKERS:
        return _check(_import_factory(spec)(), spec)
    if isinstance(spec, str):
        if spec not in TRACKERS:
            raise ValueError(f"unknown tracker {spec!r}; known: {sorted(TRACKERS)}")
        return _check(TRACKERS[spec](), spec)
    if isinstance(spec, Mapping):
        kwargs = dict(spec)
        name = kwargs.pop("type", None)
        if not isinstance(name, str):
            raise ValueError(f"a tracker dict needs a 'type' name, got {spec!r}")
        if name not in TRACKERS:
            raise ValueError(f"unknown tracker {name!r}; known: {sorted(TRACKERS)}")
        try:
            tracker = TRACKERS[name](**kwargs)
        except TypeError as exc:
            raise ValueError(f"bad arguments for tracker {name!r}: {exc}") from None
        return _check(tracker, spec)
    if isinstance(spec, Tracker) and not isinstance(spec, type):
        return spec
    if callable(spec):
        return _check(spec(), spec)
    raise ValueError(
        f"a tracker spec is a name, a {{'type': name, ...}} dict or a callable, got {spec!r}"
    )
