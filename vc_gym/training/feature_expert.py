"""The scripted homing behaviour on ``vc_gym/Homing-v0``'s features and actions.

:class:`HomingFeatureExpert` is :class:`~vc_gym.agents.ScriptedHomingPolicy`'s paper
behaviour (5.2) re-expressed for the env a learned agent sees: it reads the
:class:`~vc_gym.envs.HomingFeatures` vector and answers with
:class:`~vc_gym.envs.StopAction`'s ``(walk, turn, stop)``. Its decisions are the
demonstrations a learned agent is warm-started from (behaviour cloning, ``vc-gym train
--demo-episodes``). It keeps no memory, like the MLP policy that clones it; with
``previous_action=True`` it reads its last action from the vector
(:class:`~vc_gym.envs.PreviousAction`) and keeps a turn going while home is behind.
"""

from __future__ import annotations

import math

import numpy as np

from vc_gym.envs.homing import HomingFeatures, PreviousAction
from vc_gym.validation import flag, positive_float

__all__ = ["HomingFeatureExpert"]


class HomingFeatureExpert:
    """The paper's homing rule on Homing-v0 feature vectors (a memoryless expert).

    While the heading belief is wider than ``max_spread_deg`` it does not walk; once the
    estimated home is within ``home_tolerance_m`` it stops; otherwise it turns towards
    the estimated home (rate ``2.5 × bearing``, as the scripted agent) and walks when
    the bearing is within 30°, slower when close (``min(max_speed_m_s, 0.8 d)`` m/s).
    With ``max_position_std_m`` (on feature vectors with the position's spread,
    ``vc_gym/Homing-v0(position_std=True)``) it does not stop while the stated spread
    (the mean of the two axes) is wider: it turns in place, its head scanning, until the
    tracker is sure enough.

    Parameters
    ----------
    max_forward : float
        Walking speed (m/s) of a full walk action (the env's ``max_forward``).
    max_turn_deg_s : float
        Turn rate (deg/s) of a full turn action (the env's ``max_turn_deg_s``).
    home_tolerance_m : float
        Stop when the estimated home is this close.
    max_spread_deg : float
        Do not walk while the heading spread is wider than this.
    previous_action : bool
        The vectors end with the last action (``vc_gym/Homing-v0(previous_action=True)``):
        while the estimated home lies more than ``BEHIND_DEG`` off the heading, a turn of
        at least half the full rate goes on at the full rate in the same direction,
        instead of following the bearing's sign, which flips as the bearing crosses 180°.
    max_speed_m_s : float
        Fastest walk (m/s), at most ``max_forward``. Default 0.25, the scripted agent's.
    max_position_std_m : float, optional
        Do not stop while the position's stated spread is wider (the vectors must carry
        it: ``position_std=True``). Default ``None``: stop on the estimate alone.
    """

    #: Bearing (deg) beyond which home counts as behind (``previous_action``).
    BEHIND_DEG = 90.0

    def __init__(
        self,
        max_forward: float = 0.4,
        max_turn_deg_s: float = 60.0,
        home_tolerance_m: float = 0.1,
        max_spread_deg: float = 30.0,
        previous_action: bool = False,
        max_speed_m_s: float = 0.25,
        max_position_std_m: float | None = None,
    ):
        self.max_forward = positive_float("max_forward", max_forward)
        self.max_turn_deg_s = positive_float("max_turn_deg_s", max_turn_deg_s)
        self.home_tolerance_m = positive_float("home_tolerance_m", home_tolerance_m)
        self.max_spread_deg = positive_float("max_spread_deg", max_spread_deg)
        self.previous_action = flag("previous_action", previous_action)
        self.max_speed_m_s = positive_float("max_speed_m_s", max_speed_m_s)
        if self.max_speed_m_s > self.max_forward:
            raise ValueError(
                f"max_speed_m_s ({self.max_speed_m_s}) must be at most max_forward "
                f"({self.max_forward}), the speed of a full walk action"
            )
        self.max_position_std_m = (
            None
            if max_position_std_m is None
            else positive_float("max_position_std_m", max_position_std_m)
        )

    def predict(self, features: np.ndarray) -> np.ndarray:
        """``(walk, turn, stop)`` in ``[-1, 1]`` for one feature vector, or one row each
        for a batch ``(n, d)``."""
        f = np.asarray(features, dtype=np.float64)
        if f.ndim == 2:
            return np.stack([self.predict(row) for row in f]).astype(np.float32)
        shortest = HomingFeatures.GOODNESS_START + (
            PreviousAction.WIDTH if self.previous_action else 0
        )
        if f.ndim != 1 or f.shape[0] <= shortest or not np.all(np.isfinite(f)):
            raise ValueError(f"expected one finite Homing-v0 feature vector, got shape {f.shape}")
        fwd, left = f[HomingFeatures.HOME_VECTOR] * HomingFeatures.METRES_SCALE
        spread = f[HomingFeatures.SPREAD] * HomingFeatures.SPREAD_SCALE_DEG
        dist = math.hypot(fwd, left)
        if spread > self.max_spread_deg:
            return np.array([-1.0, 0.0, -1.0], np.float32)  # let the filters settle
        if dist <= self.home_tolerance_m:
            if self._unsure(f):  # turn in place, the head scanning, until it is sure
                return np.array([-1.0, 0.5, -1.0], np.float32)
            return np.array([-1.0, 0.0, 1.0], np.float32)
        bearing = math.degrees(math.atan2(left, fwd))
        turn = float(np.clip(2.5 * bearing, -60.0, 60.0)) / self.max_turn_deg_s
        if self.previous_action and abs(bearing) > self.BEHIND_DEG:
            last_turn = float(f[PreviousAction.PREVIOUS_ACTION][1])
            if abs(last_turn) >= 0.5:  # keep turning the way it was turning
                turn = math.copysign(60.0 / self.max_turn_deg_s, last_turn)
        speed = 0.0 if abs(bearing) > 30 else min(self.max_speed_m_s, 0.8 * dist)
        walk = speed / self.max_forward if speed > 0 else -1.0  # StopAction: max(a, 0)
        return np.array([np.clip(walk, -1, 1), np.clip(turn, -1, 1), -1.0], np.float32)

    def _unsure(self, f: np.ndarray) -> bool:
        """With ``max_position_std_m``: the vector's position spread is wider than that."""
        if self.max_position_std_m is None:
            return False
        # [features (8 + n_spots), spread (2), previous action (3)?]
        n_spots = f.shape[0] - HomingFeatures.GOODNESS_START - 1 - HomingFeatures.POSITION_STD_WIDTH
        n_spots -= PreviousAction.WIDTH if self.previous_action else 0
        if n_spots < 1:
            raise ValueError(
                "max_position_std_m needs feature vectors with the position's spread "
                f"(vc_gym/Homing-v0(position_std=True)); got {f.shape[0]} features"
            )
        spread = f[HomingFeatures.position_std_slice(n_spots)] * HomingFeatures.POSITION_STD_SCALE_M
        return float(np.mean(spread)) > self.max_position_std_m
