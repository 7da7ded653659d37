"""Two trackers, one answer: a pose belief far from home, the paper's filters near it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vc_gym.compass import Camera, CompassAtlas
from vc_gym.compass.pose_maps import around_groups
from vc_gym.localization.grid_tracker import GridTracker
from vc_gym.localization.pose_tracker import PoseTracker
from vc_gym.localization.tracker_protocol import Tracker, TrackerState, check_reset_inputs
from vc_gym.validation import MAX_ABS_METRES, positive_float

__all__ = ["HomeSwitchTracker"]


class HomeSwitchTracker:
    """The state of ``far`` while it places the robot more than ``switch_m`` from home,
    else the state of ``near`` (beyond the paper).

    Both trackers get every frame, so each keeps its own belief and the switch costs
    nothing but the two updates. The goodness and the eq. 30 atlas position of the
    state are always ``near``'s (the frame's own measurements). ``near`` tracks on the
    atlas' spots without the turns learned around them
    (:func:`~vc_gym.compass.pose_maps.around_groups`; :meth:`CompassAtlas.subset`): eq.
    30 over the spots themselves, at the cost of those spots' maps a frame; the turns'
    goodness reads 0.

    The defaults pair the trackers by what each does best in the homing task: the
    ``pose`` tracker (:class:`PoseTracker`) keeps a position over the whole field and
    does not get stuck where one spot's view aliases with home, but tells a position
    only to ~0.2 m; the paper's filters (:class:`GridTracker`, eq. 23-32) on an atlas
    normalised at the true home answer home exactly there (eq. 30: every spot fits
    equally at the place it was normalised), but shrink a position 1-2 m away towards
    home.

    Parameters
    ----------
    far : Tracker, optional
        The tracker answering away from home (default :class:`PoseTracker`).
    near : Tracker, optional
        The tracker answering near home (default :class:`GridTracker`).
    switch_m : float
        Distance from home, by ``far``'s position, below which ``near`` answers.
    """

    def __init__(
        self, far: Tracker | None = None, near: Tracker | None = None, switch_m: float = 0.5
    ):
        self.far = PoseTracker() if far is None else far
        self.near = GridTracker() if near is None else near
        for name, t in (("far", self.far), ("near", self.near)):
            if not isinstance(t, Tracker):
                raise ValueError(f"{name} must be a tracker, got {type(t).__name__}")
        self.switch_m = positive_float("switch_m", switch_m)
        if self.switch_m > MAX_ABS_METRES:
            raise ValueError(f"switch_m must be at most {MAX_ABS_METRES:g} m, got {switch_m!r}")
        self.home: tuple[float, float] | None = None
        #: Whether the last update answered with ``near``'s state.
        self.near_home = False

    def reset(self, atlas: CompassAtlas, camera: Camera, dt_s: float) -> None:
        """Reset both trackers for ``atlas``."""
        check_reset_inputs(atlas, camera, dt_s)
        self.far.reset(atlas, camera, dt_s)
        spots = list(around_groups(atlas.names))
        self.near.reset(atlas if len(spots) == len(atlas) else atlas.subset(spots), camera, dt_s)
        #: Where each of ``near``'s spots sits in ``atlas.names``.
        self._spot_index = np.array([atlas.names.index(n) for n in spots])
        self._n = len(atlas)
        self.home = tuple(float(v) for v in atlas.home_position)
        self.near_home = False

    def update(
        self, image: np.ndarray, head_pan_deg: float, odometry: np.ndarray | tuple
    ) -> TrackerState:
        """Update both trackers with the frame; the state of the one that answers."""
        if self.home is None:
            raise RuntimeError("call reset(atlas, camera, dt_s) before update()")
        far = self.far.update(image, head_pan_deg, odometry)
        near = self.near.update(image, head_pan_deg, odometry)
        x, y = far.position
        self.near_home = math.hypot(x - self.home[0], y - self.home[1]) <= self.switch_m
        goodness = np.zeros(self._n)
        goodness[self._spot_index] = near.goodness
        # the frame's own measurements (goodness, eq. 30) are ``near``'s either way
        return dataclasses.replace(
            near if self.near_home else far,
            goodness=goodness,
            atlas_position=near.atlas_position,
        )
