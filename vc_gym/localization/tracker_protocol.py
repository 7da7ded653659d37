"""What every tracker promises: the :class:`Tracker` protocol and its :class:`TrackerState`.

A tracker is what a robot that learned a place knows about its pose. It is reset with
the learned :class:`~vc_gym.compass.CompassAtlas`, the head camera's intrinsics and the
time between frames, and then fed, frame by frame, the head-camera image, the head pan
and the odometry since the previous frame. The grid, particle and Kalman trackers of
this package, and any tracker a user writes, satisfy the same protocol; the
``CompassObservation`` wrapper and the agents only ever see a :class:`TrackerState`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from vc_gym.compass import AtlasEstimate, Camera, CompassAtlas
from vc_gym.validation import positive_float

__all__ = [
    "Tracker",
    "TrackerState",
    "atlas_tracker_state",
    "check_frame_inputs",
    "check_reset_inputs",
]


@dataclass(frozen=True)
class TrackerState:
    """A tracker's belief after one frame (world frame of the atlas).

    Attributes
    ----------
    heading_deg : float
        Estimated body heading in ``[0, 360)`` degrees (paper eq. 25-26).
    heading_spread_deg : float
        Circular standard deviation of the heading belief (eq. 27), degrees.
    position : tuple of float
        Estimated position ``(x, y)`` in metres (eq. 32 for the grid tracker).
    position_std_m : tuple of float
        Uncertainty of ``position`` per axis, metres. What it measures depends on the
        tracker (see its docstring); larger always means less sure.
    goodness : numpy.ndarray
        Normalised goodness ``L̂_i`` of each spot for this frame (eq. 28), in
        ``atlas.names`` order; 0 for a spot the tracker did not score this frame.
    belief : numpy.ndarray
        The heading belief on a uniform circular grid starting at 0° (``belief[k]``
        is the probability of heading ``k * 360 / belief.size``); sums to 1.
    atlas_position : tuple of float
        This frame's unfiltered atlas position (eq. 30).
    """

    heading_deg: float
    heading_spread_deg: float
    position: tuple[float, float]
    position_std_m: tuple[float, float]
    goodness: np.ndarray
    belief: np.ndarray
    atlas_position: tuple[float, float]

    def belief_sectors(self, n: int) -> np.ndarray:
        """The heading belief summed into ``n`` equal sectors, the first starting at 0°.

        A grid heading belongs to the sector its value falls in (heading 0 to sector
        0, heading ``360 / n`` to sector 1, ...).
        """
        n = int(n)
        if n < 1:
            raise ValueError(f"the number of sectors must be >= 1, got {n}")
        m = self.belief.size
        sector = (np.arange(m) * n) // m
        return np.bincount(sector, weights=self.belief, minlength=n)


@runtime_checkable
class Tracker(Protocol):
    """Anything that turns head-camera frames and odometry into a pose belief."""

    def reset(self, atlas: CompassAtlas, camera: Camera, dt_s: float) -> None:
        """Start a new episode: forget the pose, (re)build the filters for ``atlas``.

        Parameters
        ----------
        atlas : CompassAtlas
            The learned, normalised atlas of the place.
        camera : Camera
            Intrinsics and pitch of the head camera (its yaw is ignored: the body
            heading plus the head pan is the camera heading).
        dt_s : float
            Time between frames, seconds.
        """
        ...

    def update(self, image: np.ndarray, head_pan_deg: float, odometry: np.ndarray) -> TrackerState:
        """Motion update by ``odometry`` (forward m, left m, turn deg since the last
        frame, robot frame), then sensor update by ``image`` taken with the head
        panned by ``head_pan_deg`` (left positive)."""
        ...


def check_frame_inputs(
    head_pan_deg: float, odometry: np.ndarray | tuple, ready: bool = True
) -> tuple[float, float, float, float]:
    """Validate one frame's head pan and odometry (and that the tracker was reset).

    Returns
    -------
    tuple of float
        ``(head_pan_deg, forward, left, turn)``.

    Raises
    ------
    RuntimeError
        If not ``ready`` (pass ``False`` when the tracker was never reset).
    ValueError
        On a non-finite pan, or odometry that is not three finite numbers.
    """
    if not ready:
        raise RuntimeError("call reset(atlas, camera, dt_s) before update()")
    odo = np.asarray(odometry, dtype=np.float64)
    if odo.shape != (3,) or not np.all(np.isfinite(odo)):
        raise ValueError(f"odometry must be 3 finite numbers, got {odometry!r}")
    try:
        pan = float(head_pan_deg)
    except (TypeError, ValueError):
        raise ValueError(f"head_pan_deg must be a number, got {head_pan_deg!r}") from None
    if not math.isfinite(pan):
        raise ValueError(f"head_pan_deg must be finite, got {head_pan_deg!r}")
    return pan, float(odo[0]), float(odo[1]), float(odo[2])


def atlas_tracker_state(
    atlas: CompassAtlas,
    estimate: AtlasEstimate,
    heading_deg: float,
    heading_spread_deg: float,
    position: tuple[float, float],
    position_std_m: tuple[float, float],
    belief: np.ndarray,
) -> TrackerState:
    """A :class:`TrackerState` whose goodness and atlas position come from ``estimate``
    (a spot the estimate did not score reports goodness 0)."""
    return TrackerState(
        heading_deg=float(heading_deg),
        heading_spread_deg=float(min(heading_spread_deg, 180.0)),
        position=(float(position[0]), float(position[1])),
        position_std_m=(float(position_std_m[0]), float(position_std_m[1])),
        goodness=np.array([estimate.goodness.get(n, 0.0) for n in atlas.names]),
        belief=belief,
        atlas_position=(float(estimate.position[0]), float(estimate.position[1])),
    )


def check_reset_inputs(atlas: object, camera: object, dt_s: object) -> float:
    """Validate the arguments of :meth:`Tracker.reset`; returns ``dt_s`` as a float."""
    if not isinstance(atlas, CompassAtlas):
        raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
    return positive_float("dt_s", dt_s)
