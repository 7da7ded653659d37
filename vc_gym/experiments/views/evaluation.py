"""What every tracker believes after a view's frames, and how well each spot fits them
(the heading of paper 5.1, the goodness of eq. 28 and fig. 5 right)."""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence

import numpy as np

from vc_gym.angles import wrap180, wrap360
from vc_gym.compass import Camera, CompassAtlas
from vc_gym.experiments.views.frames import Frame, check_frames
from vc_gym.localization import TrackerSpec, make_tracker
from vc_gym.validation import finite_float, positive_float

__all__ = ["COMPASS", "evaluate_view", "spot_goodness"]

#: Name under which :func:`evaluate_view` reports the single-frame compass.
COMPASS = "compass"


def evaluate_view(
    frames: Sequence[Frame],
    atlas: CompassAtlas,
    camera: Camera,
    dt_s: float,
    true_heading_deg: float,
    trackers: Mapping[str, TrackerSpec],
) -> tuple[dict[str, dict[str, float]], dict[str, float]]:
    """What every tracker believes after a view's frames (the heading of paper 5.1).

    Each tracker is built with :func:`~vc_gym.localization.make_tracker` (a tracker
    instance is used as is), reset with ``atlas``, ``camera`` and ``dt_s``, and fed
    every frame in order; its final heading (eq. 25-26), spread (eq. 27) and error are
    recorded. The single-frame compass is added under the name ``"compass"``
    (:data:`COMPASS`): the estimate of the last frame alone (eq. 16, no filter) by the
    atlas' one spot, or by the spot that fits the frame best (eq. 28) when there are
    several, turned from the camera's heading into the body's by subtracting the head
    pan.

    Parameters
    ----------
    frames : sequence of tuple
        ``(image, head_pan_deg, odometry)`` per frame, e.g. from :func:`frames_at_pose`.
    atlas : CompassAtlas
        The learned, normalised atlas.
    camera : Camera
        Intrinsics and pitch of the head camera (its yaw is ignored).
    dt_s : float
        Time between frames (the room's ``control_dt``).
    true_heading_deg : float
        The robot's true body heading.
    trackers : mapping
        ``{name: spec}`` of trackers (any :data:`~vc_gym.localization.TrackerSpec`).
        ``"compass"`` is reserved.

    Returns
    -------
    figures : dict
        ``{name: {"heading_deg", "heading_error_deg", "heading_spread_deg"}}`` as
        plain floats: heading in ``[0, 360)``, error = estimate − truth wrapped to
        ``[-180, 180)``, spread the circular standard deviation (clipped to
        ``[0, 180]``°).
    timing : dict
        ``{name: milliseconds per frame}`` (tracker update, or one compass estimate):
        kept apart from ``figures`` because it depends on the machine.

    Raises
    ------
    ValueError
        On empty or malformed frames, a bad atlas, camera, ``dt_s`` or heading, a
        tracker named ``"compass"`` or a bad tracker spec.
    """
    fr = check_frames(frames)
    if not isinstance(atlas, CompassAtlas):
        raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
    dt = positive_float("dt_s", dt_s)
    truth = finite_float("true_heading_deg", true_heading_deg)
    if not isinstance(trackers, Mapping):
        raise ValueError(f"trackers must be a mapping {{name: spec}}, got {trackers!r}")
    if COMPASS in trackers:
        raise ValueError(f"the tracker name {COMPASS!r} is reserved for the single-frame compass")

    def record(heading: float, spread: float) -> dict[str, float]:
        heading = float(wrap360(heading))
        return {
            "heading_deg": heading,
            "heading_error_deg": float(wrap180(heading - truth)),
            "heading_spread_deg": float(min(max(spread, 0.0), 180.0)),
        }

    figures: dict[str, dict[str, float]] = {}
    timing: dict[str, float] = {}
    for name, spec in trackers.items():
        tracker = make_tracker(spec)
        tracker.reset(atlas, camera, dt)
        state = None
        t0 = time.perf_counter()
        for image, pan, odo in fr:
            state = tracker.update(image, pan, np.asarray(odo, dtype=np.float64))
        elapsed = time.perf_counter() - t0
        figures[str(name)] = record(state.heading_deg, state.heading_spread_deg)
        timing[str(name)] = 1e3 * elapsed / len(fr)
    image, pan, _ = fr[-1]
    t0 = time.perf_counter()
    if len(atlas) == 1:
        est = atlas.compasses[0].estimate(image, camera)
    else:  # the map that fits the frame best (eq. 28)
        found = atlas.estimate_position(image, camera)
        est = found.estimates[max(found.goodness, key=found.goodness.get)]
    timing[COMPASS] = 1e3 * (time.perf_counter() - t0)
    figures[COMPASS] = record(est.heading_deg - pan, est.spread_deg)
    return figures, timing


def spot_goodness(frames: Sequence[Frame], atlas: CompassAtlas, camera: Camera) -> dict[str, float]:
    """Mean normalised goodness ``L̂_i`` of every spot over the frames (eq. 28, fig. 5 right).

    ``L̂_i = exp(score_i − home_score_i)`` (see
    :meth:`~vc_gym.compass.CompassAtlas.estimate_position`): the geometric-mean
    likelihood per term of the frame under spot ``i``'s map at its best heading,
    relative to frames taken at home; 1 at home after normalisation, smaller where the
    frame fits the spot worse. The head pan plays no part (each spot takes its best
    heading).

    Parameters
    ----------
    frames : sequence of tuple
        ``(image, head_pan_deg, odometry)`` per frame, e.g. from :func:`frames_at_pose`.
    atlas : CompassAtlas
        The learned atlas (normalised, or the goodness is ``exp(score)``).
    camera : Camera
        Intrinsics and pitch of the head camera.

    Returns
    -------
    dict
        ``{spot name: mean L̂_i}`` in ``atlas.names`` order, plain floats.
    """
    fr = check_frames(frames)
    if not isinstance(atlas, CompassAtlas):
        raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
    total = np.zeros(len(atlas.names))
    for image, _, _ in fr:
        g = atlas.estimate_position(image, camera).goodness
        total += [g[n] for n in atlas.names]
    return {n: float(v / len(fr)) for n, v in zip(atlas.names, total, strict=True)}
