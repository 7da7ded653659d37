"""Which spots a tracker scores each frame: all of them, or a shortlist (eq. 28-30).

Scoring a frame against every spot's map costs one map's likelihood per spot, so an
atlas on a grid of a dozen spots costs several times the paper's single compass. Most
of those maps fit badly and carry no weight in eq. 30. A :class:`SpotShortlist`
scores every spot now and then and, in between, only the few that fitted best.

It also holds what a tracker's frames share beyond one frame: with an atlas learned
with ``CompassConfig(exposure="session")`` it keeps the session's light
(:class:`~vc_gym.exposure.SessionLight` of the frames' gains) and scores every frame
at that light.
"""

from __future__ import annotations

import numpy as np

from vc_gym.compass import AtlasEstimate, Camera, CompassAtlas
from vc_gym.exposure import SessionLight
from vc_gym.validation import int_at_least

__all__ = ["SpotShortlist"]


class SpotShortlist:
    """Eq. 28-30 on every spot, or on the spots that fitted best at the last full scoring.

    Parameters
    ----------
    size : int, optional
        How many spots to score between full scorings. ``None`` (the paper) scores
        every spot every frame.
    rescore_every : int
        Every spot is scored on the first frame after :meth:`reset` and then every
        ``rescore_every`` frames; a frame costs on average
        ``(M + (rescore_every - 1) · size) / rescore_every`` maps for ``M`` spots.
    light_window : int or None
        Frames the session's light is the median of (an ``exposure="session"`` atlas;
        :class:`~vc_gym.exposure.SessionLight`).
    """

    def __init__(
        self, size: int | None = None, rescore_every: int = 4, light_window: int | None = 100
    ):
        self.size = None if size is None else int_at_least("shortlist", size, 1)
        self.rescore_every = int_at_least("rescore_every", rescore_every, 1)
        self.light = SessionLight(light_window)
        self.reset()

    def reset(self) -> None:
        """Score every spot on the next frame; forget the session's light."""
        self.light.reset()
        self._frame = 0
        self._spots: np.ndarray | None = None

    def estimate(self, atlas: CompassAtlas, image: np.ndarray, camera: Camera) -> AtlasEstimate:
        """:meth:`CompassAtlas.estimate_position` on this frame's spots.

        Spots left out are absent from the estimate's dictionaries (eq. 30 gives them
        no weight, and a tracker reports their goodness as 0).
        """
        gain = None
        if atlas.compasses[0].config.exposure == "session":
            gain = self.light.update(atlas.frame_gain(image, camera))
        k = self.size
        full = k is None or k >= len(atlas) or self._frame % self.rescore_every == 0
        self._frame += 1
        if not full:
            return atlas.estimate_position(image, camera, self._spots, gain=gain)
        est = atlas.estimate_position(image, camera, gain=gain)
        if k is not None:
            goodness = np.array([est.goodness[n] for n in atlas.names])
            self._spots = np.sort(np.argsort(-goodness, kind="stable")[:k])
        return est
