"""What every image compass offers: the visual compass and the baselines alike.

A tracker's heading sensor (:class:`~vc_gym.localization.compass_sensors.CompassHeadingSensor`),
the experiments and a user's own code need only this surface, so a baseline compass
(:mod:`vc_gym.heading_sensors`) or a user's own model plugs in wherever the visual compass does.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from vc_gym.compass.camera import Camera

__all__ = ["ImageCompass"]


@runtime_checkable
class ImageCompass(Protocol):
    """A heading sensor learned from camera images at one spot.

    ``headings_deg`` is the circular grid of candidate headings (``k * step``) the
    log-likelihoods are given on; ``learn`` adds a frame whose camera yaw is known;
    ``log_likelihood`` answers ``log p(image | heading)`` up to a constant for every
    grid heading; ``estimate`` gives the best heading, its spread and a goodness of fit
    (:class:`~vc_gym.compass.CompassEstimate`).
    """

    @property
    def headings_deg(self) -> np.ndarray: ...

    def learn(self, image: np.ndarray, camera: Camera) -> object: ...

    def log_likelihood(self, image: np.ndarray, camera: Camera) -> np.ndarray: ...

    def estimate(self, image: np.ndarray, camera: Camera) -> object: ...
