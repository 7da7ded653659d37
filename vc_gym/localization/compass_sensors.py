"""The compass and the atlas as sensor models for the filters (paper eq. 22).

The adapters between the two layers below: they satisfy the structural protocols of
:mod:`vc_gym.filters.sensor_protocol`, so the filters never import the compass and the
compass never imports the filters. A :class:`CompassHeadingSensor` is a heading
sensor (and a heading-only pose sensor), an :class:`AtlasPoseSensor` a pose sensor.
The observation of both is a camera image.
"""

from __future__ import annotations

import math

import numpy as np

from vc_gym.angles import interp_circular
from vc_gym.compass import AtlasEstimate, Camera, CompassAtlas, ImageCompass
from vc_gym.filters.sensor_protocol import check_pose_query
from vc_gym.validation import positive_float

__all__ = [
    "AtlasPoseSensor",
    "CompassHeadingSensor",
    "best_spot_heading_log_likelihood",
    "tempered_distribution",
]


def best_spot_heading_log_likelihood(
    atlas: CompassAtlas, estimate: AtlasEstimate, headings_deg: np.ndarray
) -> np.ndarray:
    """Heading log-likelihood (eq. 16) of the spot that fits an image best (eq. 28).

    Parameters
    ----------
    atlas : CompassAtlas
        The atlas that produced ``estimate``.
    estimate : AtlasEstimate
        ``atlas.estimate_position(image, camera)`` for one image.
    headings_deg : numpy.ndarray
        Camera headings to evaluate (body heading plus head pan), degrees.

    Returns
    -------
    numpy.ndarray
        The best spot's log-likelihood interpolated at ``headings_deg``.
    """
    best = max(estimate.goodness, key=estimate.goodness.get)
    step = atlas.compasses[0].config.heading_step_deg
    return interp_circular(estimate.estimates[best].log_likelihood, step, headings_deg)


def tempered_distribution(log_likelihood: np.ndarray, temperature: float) -> np.ndarray | None:
    """``softmax(log_likelihood / temperature)``: a likelihood turned into probabilities.

    The raw eq. 16 product is far sharper than the compass is right; dividing its log
    by a temperature before normalising widens it (a uniform prior otherwise).

    Returns
    -------
    numpy.ndarray or None
        Probabilities summing to 1, or ``None`` if every entry is ``-inf`` (the
        sensor rules out every state: no information).
    """
    ll = np.asarray(log_likelihood, dtype=np.float64) / temperature
    top = ll.max()
    if not np.isfinite(top):
        return None
    p = np.exp(ll - top)
    return p / p.sum()


class CompassHeadingSensor:
    """An image compass seen by a filter: images in, heading log-likelihoods out.

    Parameters
    ----------
    compass : ImageCompass
        A learned :class:`~vc_gym.compass.VisualCompass`, a baseline compass
        (:mod:`vc_gym.heading_sensors`) or anything else with the
        :class:`~vc_gym.compass.ImageCompass` surface.
    camera : Camera
        Intrinsics and pitch of the camera that takes the observations (its yaw is
        ignored). With a turnable head, pass ``head_pan_deg`` to the call instead.
    """

    def __init__(self, compass: ImageCompass, camera: Camera | None = None):
        if not isinstance(compass, ImageCompass):
            raise ValueError(
                "compass must be an image compass (a VisualCompass or a baseline: "
                f"headings_deg, learn, log_likelihood, estimate), got {type(compass).__name__}"
            )
        self.compass = compass
        self.camera = Camera() if camera is None else camera
        if not isinstance(self.camera, Camera):
            raise ValueError(f"camera must be a Camera, got {type(self.camera).__name__}")

    def heading_log_likelihood(
        self, observation: np.ndarray, headings_deg: np.ndarray, head_pan_deg: float = 0.0
    ) -> np.ndarray:
        """Log-likelihood of every body heading for one camera image.

        The compass answers for the camera's heading; with the head panned by
        ``head_pan_deg`` (left positive) the body heading is the camera heading minus
        the pan. Headings between the compass grid points are interpolated.
        """
        if not math.isfinite(head_pan_deg):
            raise ValueError(f"head_pan_deg must be finite, got {head_pan_deg!r}")
        ll = self.compass.log_likelihood(observation, self.camera)
        step = 360.0 / self.compass.headings_deg.size
        return interp_circular(ll, step, np.asarray(headings_deg) + head_pan_deg)

    def pose_log_likelihood(self, observation: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """Heading-only pose likelihood: depends on the ``θ`` column of ``poses`` alone."""
        return self.heading_log_likelihood(observation, np.asarray(poses)[:, 2])


class AtlasPoseSensor:
    """A :class:`CompassAtlas` as a pose sensor: position from eq. 30, heading from eq. 16.

    The log-likelihood of a pose ``(x, y, θ)`` is
    ``-|(x, y) - τ̂|² / (2 σ²)`` for the atlas position ``τ̂`` plus the best-fitting
    spot's heading log-likelihood at ``θ``, divided by ``heading_temperature``.

    Parameters
    ----------
    atlas : CompassAtlas
        Learned and normalised atlas.
    camera : Camera
        The camera that takes the observations.
    position_noise_m : float
        σ of the position reading (the atlas position is coarse: ~0.3 m, paper 5.2).
    heading_temperature : float
        Divides the heading log-likelihood; the raw product of eq. 16 is very peaked.
    """

    def __init__(
        self,
        atlas: CompassAtlas,
        camera: Camera | None = None,
        position_noise_m: float = 0.3,
        heading_temperature: float = 1.0,
    ):
        if not isinstance(atlas, CompassAtlas):
            raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
        for name, v in (
            ("position_noise_m", position_noise_m),
            ("heading_temperature", heading_temperature),
        ):
            positive_float(name, v)
        self.atlas = atlas
        self.camera = Camera() if camera is None else camera
        self.position_noise_m = float(position_noise_m)
        self.heading_temperature = float(heading_temperature)

    def pose_log_likelihood(
        self,
        observation: np.ndarray | AtlasEstimate,
        poses: np.ndarray,
        head_pan_deg: float = 0.0,
    ) -> np.ndarray:
        """Log-likelihood of every row ``(x, y, θ)`` of ``poses`` for one frame.

        Parameters
        ----------
        observation : numpy.ndarray or AtlasEstimate
            The camera image, or ``atlas.estimate_position(image, camera)`` already
            computed for it (a tracker that needs the estimate anyway passes it, so the
            atlas runs once per frame).
        poses : numpy.ndarray
            ``(N, 3)`` body poses ``x`` (m), ``y`` (m), ``θ`` (deg).
        head_pan_deg : float
            Head pan when the frame was taken (left positive): the camera looked at
            ``θ + head_pan_deg``.
        """
        p, head_pan_deg = check_pose_query(poses, head_pan_deg)
        if isinstance(observation, AtlasEstimate):
            est = observation
        else:
            est = self.atlas.estimate_position(observation, self.camera)
        d2 = (p[:, 0] - est.position[0]) ** 2 + (p[:, 1] - est.position[1]) ** 2
        heading = best_spot_heading_log_likelihood(self.atlas, est, p[:, 2] + head_pan_deg)
        heading = heading / self.heading_temperature
        return heading - 0.5 * d2 / self.position_noise_m**2
