"""An unscented Kalman heading filter and the translational filter on the atlas."""

from __future__ import annotations

import math

import numpy as np

from vc_gym.angles import circular_mean, circular_std, wrap180
from vc_gym.compass import Camera, CompassAtlas
from vc_gym.filters import KalmanHeadingFilter
from vc_gym.localization.compass_sensors import (
    best_spot_heading_log_likelihood,
    tempered_distribution,
)
from vc_gym.localization.position import AtlasPositionFilter
from vc_gym.localization.shortlist import SpotShortlist
from vc_gym.localization.tracker_protocol import (
    TrackerState,
    atlas_tracker_state,
    check_frame_inputs,
    check_reset_inputs,
)
from vc_gym.validation import nonnegative_float, positive_float

__all__ = ["KalmanTracker"]


class KalmanTracker:
    """UKF heading filter (Gaussian belief, eq. 25) + translational filter (eq. 30-32).

    Each frame the best-fitting spot's heading log-likelihood (eq. 16, 28) over a 1°
    grid, divided by ``heading_temperature``, is summarised as a Gaussian measurement
    (circular mean and spread, eq. 26-27, floored at ``min_spread_deg``). A
    measurement whose innovation exceeds ``gate_sigma`` standard deviations of the
    innovation is rejected (a frame that fits a wrong heading); after
    ``max_rejections`` rejections in a row the filter re-initialises on the
    measurement, so a wrong lock is not permanent. Unlike the grid filter it holds one
    hypothesis only. ``position_std_m`` is as in :class:`GridTracker`.

    Parameters
    ----------
    half_life_s : float
        Mixing half-life of the translational filter (paper: 0.3 s).
    motion_noise_deg, turn_noise : float
        Heading noise per frame: ``motion_noise_deg + turn_noise * |turn|``.
    heading_temperature : float
        Divides the compass log-likelihood before it is summarised (the raw eq. 16
        product is much sharper than the compass is right).
    min_spread_deg : float
        Smallest measurement standard deviation.
    gate_sigma : float
        Innovation gate in standard deviations (``inf``: never reject).
    max_rejections : int
        Consecutive rejections after which the filter restarts on the measurement.
    shortlist, rescore_every : int
        Score every spot only every ``rescore_every`` frames and, in between, the
        ``shortlist`` spots that fitted best (:class:`SpotShortlist`). The default
        ``shortlist=None`` (the paper) scores every spot every frame.
    """

    def __init__(
        self,
        half_life_s: float = 0.3,
        motion_noise_deg: float = 0.5,
        turn_noise: float = 0.1,
        heading_temperature: float = 20.0,
        min_spread_deg: float = 2.0,
        gate_sigma: float = 3.0,
        max_rejections: int = 10,
        shortlist: int | None = None,
        rescore_every: int = 4,
    ):
        self.half_life_s = positive_float("half_life_s", half_life_s)
        self.motion_noise_deg = nonnegative_float("motion_noise_deg", motion_noise_deg)
        self.turn_noise = nonnegative_float("turn_noise", turn_noise)
        self.heading_temperature = positive_float("heading_temperature", heading_temperature)
        self.min_spread_deg = positive_float("min_spread_deg", min_spread_deg)
        g = float(gate_sigma)
        if math.isnan(g) or g <= 0:
            raise ValueError(f"gate_sigma must be > 0 (inf: no gate), got {gate_sigma!r}")
        self.gate_sigma = g
        if isinstance(max_rejections, bool) or not isinstance(max_rejections, int):
            raise ValueError(f"max_rejections must be an int >= 1, got {max_rejections!r}")
        if max_rejections < 1:
            raise ValueError(f"max_rejections must be an int >= 1, got {max_rejections!r}")
        self.max_rejections = max_rejections
        self.spots = SpotShortlist(shortlist, rescore_every)
        self.headings_deg = np.arange(360, dtype=np.float64)
        self.atlas: CompassAtlas | None = None

    def reset(self, atlas: CompassAtlas, camera: Camera, dt_s: float) -> None:
        """Heading unknown (spread 180°), position at the spots' centroid."""
        dt = check_reset_inputs(atlas, camera, dt_s)
        self.atlas, self.camera = atlas, camera
        self.heading_filter = KalmanHeadingFilter(0.0, 180.0)
        self.position_filter = AtlasPositionFilter(atlas, self.half_life_s, dt)
        self.spots.reset()
        self.rejections = 0

    def _measurement(self, ll: np.ndarray) -> tuple[float, float] | None:
        p = tempered_distribution(ll, self.heading_temperature)
        if p is None:
            return None  # the compass rules out every heading: no information
        h = self.headings_deg
        return circular_mean(h, p), max(circular_std(h, p), self.min_spread_deg)

    def update(
        self, image: np.ndarray, head_pan_deg: float, odometry: np.ndarray | tuple
    ) -> TrackerState:
        """Motion update by ``odometry``, then sensor update by ``image``."""
        pan, fwd, left, turn = check_frame_inputs(
            head_pan_deg, odometry, ready=self.atlas is not None
        )
        kf, pf = self.heading_filter, self.position_filter
        kf.predict(turn, noise_deg=self.motion_noise_deg + self.turn_noise * abs(turn))
        est = self.spots.estimate(self.atlas, image, self.camera)
        ll = best_spot_heading_log_likelihood(self.atlas, est, self.headings_deg + pan)
        z = self._measurement(ll)
        if z is not None and math.isfinite(z[1]):
            prior = kf.estimate()
            innovation = abs(float(wrap180(z[0] - prior.heading_deg)))
            if innovation <= self.gate_sigma * math.hypot(prior.spread_deg, z[1]):
                kf.update(*z)
                self.rejections = 0
            else:
                self.rejections += 1
                if self.rejections >= self.max_rejections:
                    kf.reset(*z)
                    self.rejections = 0
        heading = kf.estimate()
        pf.predict(fwd, left, heading.heading_deg)
        pf.update(est)
        d = wrap180(self.headings_deg - heading.heading_deg)
        belief = np.exp(-0.5 * (d / max(heading.spread_deg, 0.5)) ** 2)
        return atlas_tracker_state(
            self.atlas,
            est,
            heading_deg=float(heading.heading_deg),
            heading_spread_deg=float(min(heading.spread_deg, 180.0)),
            position=pf.position,
            position_std_m=pf.std_m,
            belief=belief / belief.sum(),
        )
