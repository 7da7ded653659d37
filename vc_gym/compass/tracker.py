"""Pose tracking with a compass atlas: the paper's two filters fed by the compass (4.2, 5.2).

An :class:`AtlasTracker` holds an orientational grid filter (eq. 23-27) and a
translational filter (eq. 30-32). Each camera frame, with the head pan and the
odometry since the previous frame, moves both filters by the odometry and updates them
with the atlas: the heading filter with the best-fitting spot's heading likelihood, the
translational filter with the goodness-weighted spot position. It is what a robot
that learned a place knows about its pose, and what the ``CompassObservation``
wrapper and the scripted homing agent act on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vc_gym.compass.atlas import CompassAtlas
from vc_gym.compass.camera import Camera
from vc_gym.compass.sensors import best_spot_heading_log_likelihood
from vc_gym.filters import HeadingGridFilter, TranslationalFilter
from vc_gym.validation import nonnegative_float

__all__ = ["AtlasTracker", "TrackerState"]


@dataclass(frozen=True)
class TrackerState:
    """The tracker's belief after one frame (world frame of the atlas).

    Attributes
    ----------
    heading_deg : float
        Circular mean of the heading belief (eq. 25), body heading in degrees.
    heading_spread_deg : float
        Circular standard deviation of the heading belief (eq. 26-27).
    position : tuple of float
        Filtered position estimate ``τ̂`` (eq. 32), metres.
    atlas_position : tuple of float
        This frame's unfiltered atlas position (eq. 30).
    goodness : numpy.ndarray
        Normalised goodness ``L̂_i`` of each spot, in ``atlas.names`` order (eq. 28).
    belief : numpy.ndarray
        The heading belief over the filter's grid (sums to 1).
    """

    heading_deg: float
    heading_spread_deg: float
    position: tuple[float, float]
    atlas_position: tuple[float, float]
    goodness: np.ndarray
    belief: np.ndarray


class AtlasTracker:
    """Heading and position filters driven by odometry and a compass atlas.

    Parameters
    ----------
    atlas : CompassAtlas
        Learned and normalised atlas (:meth:`CompassAtlas.normalize`).
    camera : Camera
        Intrinsics and pitch of the head camera (its yaw is ignored: the body heading
        plus the head pan is the camera heading).
    dt_s : float
        Time between frames (the mixing weight λ follows from it and the half-life).
    half_life_s : float
        Half of each filter's belief is replaced by readings after this time (paper: 0.3 s).
    heading_resolution_deg : float
        Bin width of the heading grid.
    motion_noise_deg : float
        Heading blur per frame, plus ``turn_noise`` times the odometry turn.
    turn_noise : float
        Fraction of each odometry turn added to the heading blur.
    """

    def __init__(
        self,
        atlas: CompassAtlas,
        camera: Camera | None = None,
        dt_s: float = 0.1,
        half_life_s: float = 0.3,
        heading_resolution_deg: float = 1.0,
        motion_noise_deg: float = 0.5,
        turn_noise: float = 0.1,
    ):
        if not isinstance(atlas, CompassAtlas):
            raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
        for name, v in (("motion_noise_deg", motion_noise_deg), ("turn_noise", turn_noise)):
            nonnegative_float(name, v)
        self.atlas = atlas
        self.camera = Camera() if camera is None else camera
        if not isinstance(self.camera, Camera):
            raise ValueError(f"camera must be a Camera, got {type(self.camera).__name__}")
        self.heading_filter = HeadingGridFilter(
            heading_resolution_deg, rule="mixing", half_life_s=half_life_s, dt_s=dt_s
        )
        self.position_filter = TranslationalFilter(atlas.positions, half_life_s, dt_s)
        self.motion_noise_deg = float(motion_noise_deg)
        self.turn_noise = float(turn_noise)

    def reset(self) -> None:
        """Forget the pose: uniform heading belief, position at the spots' centroid."""
        self.heading_filter.reset()
        self.position_filter.reset()

    def update(
        self, image: np.ndarray, head_pan_deg: float, odometry: np.ndarray | tuple
    ) -> TrackerState:
        """Motion update by ``odometry`` then sensor update by ``image``.

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W, 3)`` uint8 RGB head-camera frame.
        head_pan_deg : float
            Head pan when the frame was taken (left positive).
        odometry : array_like
            ``(forward m, left m, turn deg)`` since the previous frame, robot frame.

        Returns
        -------
        TrackerState
        """
        odo = np.asarray(odometry, dtype=np.float64)
        if odo.shape != (3,) or not np.all(np.isfinite(odo)):
            raise ValueError(f"odometry must be 3 finite numbers, got {odometry!r}")
        if not math.isfinite(head_pan_deg):
            raise ValueError(f"head_pan_deg must be finite, got {head_pan_deg!r}")
        fwd, left, turn = (float(v) for v in odo)
        hf, tf = self.heading_filter, self.position_filter
        hf.predict(turn, noise_deg=self.motion_noise_deg + self.turn_noise * abs(turn))
        est = self.atlas.estimate_position(image, self.camera)
        hf.update_log_likelihood(
            best_spot_heading_log_likelihood(self.atlas, est, hf.headings_deg + head_pan_deg)
        )
        heading = hf.estimate()
        th = math.radians(heading.heading_deg)
        c, s = math.cos(th), math.sin(th)
        tf.predict(fwd * c - left * s, fwd * s + left * c)
        tf.update_position(est.position)
        return TrackerState(
            heading_deg=float(heading.heading_deg),
            heading_spread_deg=float(heading.spread_deg),
            position=tf.position,
            atlas_position=(float(est.position[0]), float(est.position[1])),
            goodness=np.array([est.goodness[n] for n in self.atlas.names]),
            belief=hf.belief,
        )
