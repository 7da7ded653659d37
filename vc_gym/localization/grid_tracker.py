"""The paper's trackers: a heading grid filter and a translational filter (4.2, 5.2)."""

from __future__ import annotations

import numpy as np

from vc_gym.compass import Camera, CompassAtlas, ImageCompass
from vc_gym.filters import HeadingGridFilter
from vc_gym.localization.compass_sensors import (
    CompassHeadingSensor,
    best_spot_heading_log_likelihood,
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

__all__ = ["GridTracker"]


class GridTracker:
    """Heading grid filter (eq. 23-27) and translational filter (eq. 30-32) on the atlas.

    Every frame, with the head pan and the odometry since the previous frame, moves
    both filters by the odometry and updates them with the atlas: the heading filter
    by the paper's mixing rule (eq. 24) with the heading likelihood of the spot that
    fits the frame best (eq. 16, 28), the translational filter with the
    goodness-weighted spot position (eq. 30). This is the paper's robot.

    ``position_std_m`` is the spread of the spots under the eq. 30 weights (see
    :class:`~vc_gym.localization.position.AtlasPositionFilter`).

    Parameters
    ----------
    half_life_s : float
        Half of each filter's belief is replaced by readings after this time (paper
        4.2: 0.3 s).
    heading_resolution_deg : float
        Bin width of the heading grid.
    motion_noise_deg : float
        Heading blur per frame, plus ``turn_noise`` times the odometry turn.
    turn_noise : float
        Fraction of each odometry turn added to the heading blur.
    rule : str
        ``"mixing"`` (paper eq. 24) or ``"bayes"`` (the proper product).
    shortlist, rescore_every : int
        Score every spot only every ``rescore_every`` frames and, in between, the
        ``shortlist`` spots that fitted best (:class:`SpotShortlist`). The default
        ``shortlist=None`` (the paper) scores every spot every frame.
    heading_sensor : ImageCompass, optional
        Another learned heading sensor (a baseline of :mod:`vc_gym.heading_sensors`, or a
        visual compass of its own) whose log-likelihood updates the heading filter
        instead of the atlas' best spot; position still comes from the atlas (eq. 30).
        Its headings are world headings, like the atlas'.
    """

    def __init__(
        self,
        half_life_s: float = 0.3,
        heading_resolution_deg: float = 1.0,
        motion_noise_deg: float = 0.5,
        turn_noise: float = 0.1,
        rule: str = "mixing",
        shortlist: int | None = None,
        rescore_every: int = 4,
        heading_sensor: ImageCompass | None = None,
    ):
        self.half_life_s = positive_float("half_life_s", half_life_s)
        self.heading_resolution_deg = positive_float(
            "heading_resolution_deg", heading_resolution_deg
        )
        self.motion_noise_deg = nonnegative_float("motion_noise_deg", motion_noise_deg)
        self.turn_noise = nonnegative_float("turn_noise", turn_noise)
        self.rule = rule
        self.spots = SpotShortlist(shortlist, rescore_every)
        # fail now, not at the first reset
        HeadingGridFilter(self.heading_resolution_deg, rule=rule, half_life_s=self.half_life_s)
        if heading_sensor is not None and not isinstance(heading_sensor, ImageCompass):
            raise ValueError(
                "heading_sensor must be an image compass (headings_deg, learn, "
                f"log_likelihood, estimate), got {type(heading_sensor).__name__}"
            )
        self.heading_sensor = heading_sensor
        self._heading_reader: CompassHeadingSensor | None = None
        self.atlas: CompassAtlas | None = None

    def reset(self, atlas: CompassAtlas, camera: Camera, dt_s: float) -> None:
        """Uniform heading belief, position at the spots' centroid."""
        dt = check_reset_inputs(atlas, camera, dt_s)
        self.atlas, self.camera = atlas, camera
        self.heading_filter = HeadingGridFilter(
            self.heading_resolution_deg, rule=self.rule, half_life_s=self.half_life_s, dt_s=dt
        )
        self.position_filter = AtlasPositionFilter(atlas, self.half_life_s, dt)
        self.spots.reset()
        if self.heading_sensor is not None:
            self._heading_reader = CompassHeadingSensor(self.heading_sensor, camera)

    def update(
        self, image: np.ndarray, head_pan_deg: float, odometry: np.ndarray | tuple
    ) -> TrackerState:
        """Motion update by ``odometry``, then sensor update by ``image``."""
        pan, fwd, left, turn = check_frame_inputs(
            head_pan_deg, odometry, ready=self.atlas is not None
        )
        hf, pf = self.heading_filter, self.position_filter
        hf.predict(turn, noise_deg=self.motion_noise_deg + self.turn_noise * abs(turn))
        est = self.spots.estimate(self.atlas, image, self.camera)
        if self._heading_reader is not None:
            ll = self._heading_reader.heading_log_likelihood(image, hf.headings_deg, pan)
        else:
            ll = best_spot_heading_log_likelihood(self.atlas, est, hf.headings_deg + pan)
        hf.update_log_likelihood(ll)
        heading = hf.estimate()
        pf.predict(fwd, left, heading.heading_deg)
        pf.update(est)
        return atlas_tracker_state(
            self.atlas,
            est,
            heading_deg=float(heading.heading_deg),
            heading_spread_deg=float(heading.spread_deg),
            position=pf.position,
            position_std_m=pf.std_m,
            belief=hf.belief,
        )
