"""The landmarks' bearings as a pose sensor: where each one should appear, against where
the frame shows a change of its colour pair.

A candidate pose ``(x, y, θ)`` with the head panned by ``pan`` looks along
``ψ = θ + pan``; a landmark at ``L`` then appears at the offset
``atan2(L - (x, y)) - ψ`` from the optical axis, if that lies inside the field of view.
Each change the frame shows (:func:`~vc_gym.compass.bearings.frame_bearings`) is explained
by the landmark of its colour pair whose predicted offset is nearest, with a Gaussian
error of the sub-pixel column's noise and the landmark's own position uncertainty seen
from that distance; or by nothing (a door, a person, a change no turn learned) with the
probability ``outlier``, so that one stray change cannot wipe out the right pose. The
log-likelihood of a pose is the sum over the frame's changes (the outlier-robust
product of the paper's sensor model, eq. 16, with bearings instead of sector
histograms). It is a :class:`~vc_gym.filters.sensor_protocol.PoseSensor`.
"""

from __future__ import annotations

import math

import numpy as np

from vc_gym.compass.bearings import FrameBearings, bands_bearings
from vc_gym.compass.camera import Camera
from vc_gym.compass.colors import ColorClasses
from vc_gym.compass.landmarks import LandmarkMap, eye_positions
from vc_gym.filters.sensor_protocol import check_pose_query
from vc_gym.validation import finite_float, open_fraction, positive_float

__all__ = ["BearingSensor"]


class BearingSensor:
    """Pose log-likelihood of a frame from the bearings of learned landmarks.

    Parameters
    ----------
    landmarks : LandmarkMap
        The learned landmarks.
    colors : ColorClasses
        The colour classes the landmarks were learned with.
    camera : Camera, optional
        The camera that takes the frames (default: the Aibo head camera).
    noise_deg : float
        σ of an observed change's bearing (sub-pixel column, edge blur), degrees.
    outlier : float
        Probability density floor, relative to a perfect match, for a change that no
        landmark explains, in ``(0, 1)``.
    eye_forward_m : float, optional
        How far ahead of the body's centre, along its heading, the camera sits (a
        pose is the body's; the bearings are seen from the camera); default the
        landmarks' own (:attr:`LandmarkMap.eye_forward_m`).
    """

    def __init__(
        self,
        landmarks: LandmarkMap,
        colors: ColorClasses,
        camera: Camera | None = None,
        noise_deg: float = 0.5,
        outlier: float = 0.05,
        eye_forward_m: float | None = None,
    ):
        if not isinstance(landmarks, LandmarkMap):
            raise ValueError(f"landmarks must be a LandmarkMap, got {type(landmarks).__name__}")
        if landmarks.n_colors != colors.n_colors:
            raise ValueError(
                f"the landmarks use {landmarks.n_colors} colour classes, the colours "
                f"{colors.n_colors}"
            )
        self.landmarks = landmarks
        self.colors = colors
        self.camera = Camera() if camera is None else camera
        self.noise_deg = positive_float("noise_deg", noise_deg)
        self.outlier = open_fraction("outlier", outlier)
        if eye_forward_m is None:
            eye_forward_m = landmarks.eye_forward_m
        self.eye_forward_m = finite_float("eye_forward_m", eye_forward_m)

    def bearings(self, image: np.ndarray, gain: float = 1.0) -> FrameBearings:
        """The changes of one frame in the landmarks' bands (what
        :meth:`pose_log_likelihood` reads), its linear light times ``gain``."""
        return bands_bearings(image, self.camera, self.colors, self.landmarks.bands, gain=gain)

    def pose_log_likelihood(
        self,
        observation: np.ndarray | FrameBearings,
        poses: np.ndarray,
        head_pan_deg: float = 0.0,
        noise_deg: float | None = None,
    ) -> np.ndarray:
        """``log p(frame | pose)`` up to a constant, for every row of ``poses``.

        Parameters
        ----------
        observation : numpy.ndarray or FrameBearings
            The camera image, or its :meth:`bearings` already computed.
        poses : numpy.ndarray
            ``(N, 3)`` body poses ``x`` (m), ``y`` (m), ``θ`` (deg).
        head_pan_deg : float
            Head pan when the frame was taken (left positive).
        noise_deg : float, optional
            σ of a bearing for this call (e.g. widened while a belief is still broad);
            default the sensor's.

        Returns
        -------
        numpy.ndarray
            ``(N,)`` log-likelihoods; 0 for every pose when the frame shows no change.
        """
        p, head_pan_deg = check_pose_query(poses, head_pan_deg)
        obs = observation if isinstance(observation, FrameBearings) else self.bearings(observation)
        theta = np.radians(p[:, 2])
        eye = eye_positions(p[:, :2], theta, self.eye_forward_m)
        camera_yaw = theta + math.radians(head_pan_deg)
        noise = self.noise_deg if noise_deg is None else positive_float("noise_deg", noise_deg)
        return self.landmarks.log_likelihood(
            obs, eye, camera_yaw, math.radians(noise), self.outlier
        )
