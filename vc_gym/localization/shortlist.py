"""Which spots a tracker scores each frame: all of them, or a shortlist (eq. 28-30).

Scoring a frame against every spot's map costs one map's likelihood per spot, so an
atlas on a grid of a dozen spots costs several times the paper's single compass. Most
of those maps fit badly and carry no weight in eq. 30. A :class:`SpotShortlist`
scores every spot now and then and, in between, only the few that fitted best. For an
atlas learned with ``exposure="map"`` it also keeps the session's light
(:class:`~vc_gym.localization.light.SessionLight`, read under the best-fitting map).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from vc_gym.compass import AtlasEstimate, Camera, CompassAtlas
from vc_gym.localization.light import SessionLight
from vc_gym.validation import int_at_least

__all__ = ["LIGHT_HEADING_SPREAD_DEG", "SpotShortlist", "light_heading"]

#: A tracker's heading is trusted to read the light of the view once its spread
#: (circular std) is below this.
LIGHT_HEADING_SPREAD_DEG = 30.0


def light_heading(
    atlas: CompassAtlas | None, belief: Callable[[], Any], pan_deg: float
) -> float | None:
    """The camera heading to read an ``exposure="map"`` atlas' light at: the tracker's
    ``belief()`` (an estimate with ``heading_deg`` and ``spread_deg``, read only for
    such atlases) plus the head's pan, or ``None`` while the belief is wider than
    :data:`LIGHT_HEADING_SPREAD_DEG`."""
    if atlas is None or atlas.compasses[0].config.exposure != "map":
        return None
    b = belief()
    return float(b.heading_deg) + pan_deg if b.spread_deg < LIGHT_HEADING_SPREAD_DEG else None


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
    """

    def __init__(self, size: int | None = None, rescore_every: int = 4):
        self.size = None if size is None else int_at_least("shortlist", size, 1)
        self.rescore_every = int_at_least("rescore_every", rescore_every, 1)
        self.light = SessionLight()
        self.reset()

    def reset(self) -> None:
        """Score every spot on the next frame (and forget the session's light)."""
        self._frame = 0
        self._spots: np.ndarray | None = None
        self._best: str | None = None
        self.light.reset()

    def estimate(
        self,
        atlas: CompassAtlas,
        image: np.ndarray,
        camera: Camera,
        heading_deg: float | None = None,
    ) -> AtlasEstimate:
        """:meth:`CompassAtlas.estimate_position` on this frame's spots.

        Spots left out are absent from the estimate's dictionaries (eq. 30 gives them
        no weight, and a tracker reports their goodness as 0). ``heading_deg``: the
        camera heading the tracker believes before this frame, if it has one (used
        only to read the light of ``exposure="map"`` atlases).
        """
        gain = None
        if atlas.compasses[0].config.exposure == "map":
            best = self._best if self._best in atlas.names else atlas.home
            spot = atlas.names.index(best) if best in atlas.names else 0
            gain = self.light.observe(atlas.compasses[spot], image, camera, heading_deg)
        k = self.size
        full = k is None or k >= len(atlas) or self._frame % self.rescore_every == 0
        self._frame += 1
        if not full:
            est = atlas.estimate_position(image, camera, self._spots, gain=gain)
        else:
            est = atlas.estimate_position(image, camera, gain=gain)
            if k is not None:
                goodness = np.array([est.goodness[n] for n in atlas.names])
                self._spots = np.sort(np.argsort(-goodness, kind="stable")[:k])
        self._best = max(est.goodness, key=est.goodness.__getitem__)
        return est
