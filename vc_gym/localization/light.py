"""The light of a session, for atlases learned with ``CompassConfig(exposure="map")``.

A map learned with ``exposure="map"`` knows how bright each direction was while it
learned. A frame's gain — the factor that brings it back to that light — is then the
learned light of the directions in view over the frame's own light, which needs the
heading: scoring every heading with its own gain costs one classification per
distinct gain (5-15). A tracker knows its heading, and the light changes far more
slowly than the view, so a :class:`SessionLight` takes one frame's gain at the
tracker's heading (no classification) and keeps the median of the last few; only the
first frame of a session, before the tracker has a heading, pays for the full profile.
Every map is then scored with that one gain, sharing the frame's features.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from vc_gym.compass import Camera, VisualCompass
from vc_gym.validation import int_at_least

__all__ = ["SessionLight"]


class SessionLight:
    """Median of the recent frames' light gains (see the module notes).

    Parameters
    ----------
    window : int
        How many of the latest frames' gains the median is taken over.
    """

    def __init__(self, window: int = 9):
        self.window = int_at_least("window", window, 1)
        self.reset()

    def reset(self) -> None:
        """Forget the light (a new session)."""
        self._log2: deque[float] = deque(maxlen=self.window)

    @property
    def gain(self) -> float | None:
        """The session's gain so far, ``None`` before the first frame."""
        if not self._log2:
            return None
        return float(2.0 ** np.median(np.fromiter(self._log2, dtype=np.float64)))

    def observe(
        self,
        compass: VisualCompass,
        image: np.ndarray,
        camera: Camera,
        heading_deg: float | None = None,
    ) -> float:
        """Add this frame's gain under ``compass`` (the map that fits best) and return
        the session's gain.

        ``heading_deg`` is the camera's heading as the tracker believes it before this
        frame. Without it the first frame of a session is profiled over every
        heading and later frames keep the session's gain unchanged.
        """
        if heading_deg is not None:
            self._log2.append(math.log2(compass.light_gain(image, camera, heading_deg)))
        elif not self._log2:
            self._log2.append(math.log2(compass.light_gain(image, camera)))
        gain = self.gain
        assert gain is not None
        return gain
