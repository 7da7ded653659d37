"""The paper's translational filter fed by the atlas, with a spread (eq. 30-32)."""

from __future__ import annotations

import numpy as np

from vc_gym.compass import AtlasEstimate, CompassAtlas
from vc_gym.filters import TranslationalFilter, mixing_lambda
from vc_gym.poses import body_to_world

__all__ = ["AtlasPositionFilter"]


class AtlasPositionFilter:
    """Position from the atlas (eq. 30) smoothed by the translational filter (eq. 31-32).

    Besides the position it keeps a spread: the per-axis variance of the spot
    positions under this frame's eq. 30 weights, smoothed with the same mixing weight
    λ as the position. It is small when one spot dominates the goodness and about the
    spots' own spread when every spot fits alike. It measures how much the atlas
    hesitates between its spots, not the distance to the true position: eq. 30 can
    only answer points inside the spots' hull.

    Parameters
    ----------
    atlas : CompassAtlas
        The atlas whose spots are the filter's measurement points.
    half_life_s, dt_s : float
        Mixing half-life and frame period (λ of eq. 24 and 32).
    """

    def __init__(self, atlas: CompassAtlas, half_life_s: float, dt_s: float):
        self.spots = atlas.positions
        self.names = atlas.names
        self.filter = TranslationalFilter(self.spots, half_life_s, dt_s)
        self.lam = mixing_lambda(half_life_s, dt_s)
        self.reset()

    def reset(self) -> None:
        """Position at the spots' centroid, spread that of the spots."""
        self.filter.reset()
        self._var = self.spots.var(axis=0)

    def predict(self, forward: float, left: float, heading_deg: float) -> None:
        """Odometry in the robot frame, rotated by the estimated heading (eq. 31)."""
        self.filter.predict(*body_to_world(forward, left, heading_deg))

    def update(self, estimate: AtlasEstimate) -> None:
        """Mix in the frame's atlas position (eq. 32) and its weighted spread (spots the
        estimate did not score weigh nothing)."""
        self.filter.update_position(estimate.position)
        w = np.array([estimate.weights.get(n, 0.0) for n in self.names])
        var = w @ (self.spots - np.asarray(estimate.position)) ** 2
        self._var = self.lam * var + (1.0 - self.lam) * self._var

    @property
    def position(self) -> tuple[float, float]:
        """The filtered position ``τ̂`` (eq. 32)."""
        return self.filter.position

    @property
    def std_m(self) -> tuple[float, float]:
        """Smoothed per-axis spread of the eq. 30 evidence, metres."""
        s = np.sqrt(np.maximum(self._var, 0.0))
        return float(s[0]), float(s[1])
