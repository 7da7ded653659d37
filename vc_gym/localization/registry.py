"""Trackers chosen by a name, a ``{"type": name, **kwargs}`` dict or a callable."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from vc_gym.localization.bearing_tracker import BearingTracker
from vc_gym.localization.grid_tracker import GridTracker
from vc_gym.localization.home_switch_tracker import HomeSwitchTracker
from vc_gym.localization.kalman_tracker import KalmanTracker
from vc_gym.localization.particle_tracker import ParticleTracker
from vc_gym.localization.pose_tracker import PoseTracker
from vc_gym.localization.tracker_protocol import Tracker
from vc_gym.plugins import make_plugin, register_plugin

__all__ = ["TRACKERS", "TrackerSpec", "make_tracker", "register_tracker", "tracker_label"]

#: Tracker classes by name (``register_tracker`` adds to it).
TRACKERS: dict[str, Callable[..., Tracker]] = {
    "grid": GridTracker,
    "particle": ParticleTracker,
    "kalman": KalmanTracker,
    "pose": PoseTracker,
    "pose-grid": HomeSwitchTracker,
    "bearings": BearingTracker,
}

TrackerSpec = str | Mapping[str, Any] | Callable[[], Tracker] | Tracker | None


def register_tracker(name: str, factory: Callable[..., Tracker], overwrite: bool = False) -> None:
    """Make ``factory(**kwargs)`` available as ``make_tracker(name)`` / ``{"type": name}``."""
    register_plugin(TRACKERS, "tracker", name, factory, overwrite)


def tracker_label(spec: TrackerSpec) -> str:
    """A short name of ``spec`` for titles and summaries: the name, a dict's ``type``,
    else ``"custom"`` (a callable or a built tracker)."""
    if isinstance(spec, str):
        return spec
    if isinstance(spec, Mapping) and isinstance(spec.get("type"), str):
        return spec["type"]
    return "custom"


def make_tracker(spec: TrackerSpec = "grid") -> Tracker:
    """Build a tracker the HighwayEnv way.

    Parameters
    ----------
    spec : str, dict, callable or Tracker
        ``"grid"`` (the paper's filters, default), ``"particle"``, ``"kalman"``,
        ``"pose"`` (a pose belief over the whole field on re-drawn maps),
        ``"pose-grid"`` (the pose belief away from home, the paper's filters near it),
        ``"bearings"`` (the pose belief weighed also by the landmarks' bearings) or any
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
    return make_plugin(
        spec,
        TRACKERS,
        "tracker",
        lambda obj: isinstance(obj, Tracker),
        "reset(atlas, camera, dt_s) and update(image, head_pan_deg, odometry)",
    )
