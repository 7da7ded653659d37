"""The paper's scripted homing behaviour (section 5.2), acting on a tracker's estimates.

:class:`ScriptedHomingPolicy` reads only what
:class:`~vc_gym.envs.CompassObservation` adds to the observation (the estimated home
vector and heading spread): it never sees the true pose. The learning phase that comes
before homing belongs to the task (:mod:`vc_gym.envs.learning`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from vc_gym.envs.learning import HEAD_SCAN_DEG
from vc_gym.validation import nonnegative_float, positive_float

__all__ = ["ScriptedHomingPolicy"]

class ScriptedHomingPolicy:
    """The paper's homing behaviour on :class:`~vc_gym.envs.CompassObservation` outputs.

    First stand still (head scanning) for ``settle_time_s`` and until the heading
    spread is below ``max_spread_deg``, so the filters settle; then turn towards the
    estimated home and walk (slower when close); stand still, scanning with the head,
    once the estimate is within ``home_tolerance_m`` of home. Uses only
    ``home_vector`` and ``heading_spread`` of the observation.

    Parameters
    ----------
    velocity_action : callable
        ``velocity_action(forward_m_s=, turn_deg_s=, pan_deg=) -> action``: the env's
        own scaling (``env.unwrapped.velocity_action`` of ``vc_gym/AiboRoom-v0`` and
        ``vc_gym/LearnThenHome-v0``). :meth:`for_env` takes it from an env.
    dt_s : float
        Control period of the env (seconds per step).
    home_tolerance_m : float
        The robot stops when its position estimate is this close to home.
    head_scan_deg : tuple of float
        Head pans cycled while standing.
    settle_time_s : float
        Time to stand still at the start of homing.
    max_spread_deg : float
        Stand still while the heading belief is wider than this.
    rearm_factor : float
        Once within ``home_tolerance_m``, walk again only when the estimate leaves
        ``rearm_factor × home_tolerance_m`` (the estimate jitters by ~0.1 m as the head
        scans; without this hysteresis the robot shuffles around home and never stops).
    """

    def __init__(
        self,
        velocity_action: Callable[..., np.ndarray],
        dt_s: float = 0.1,
        home_tolerance_m: float = 0.1,
        head_scan_deg: tuple[float, ...] = HEAD_SCAN_DEG,
        settle_time_s: float = 2.0,
        max_spread_deg: float = 30.0,
        rearm_factor: float = 2.5,
    ):
        if not callable(velocity_action):
            raise ValueError(f"velocity_action must be callable, got {velocity_action!r}")
        for name, v in (
            ("dt_s", dt_s),
            ("home_tolerance_m", home_tolerance_m),
            ("max_spread_deg", max_spread_deg),
            ("rearm_factor", rearm_factor),
        ):
            positive_float(name, v)
        nonnegative_float("settle_time_s", settle_time_s)
        if not head_scan_deg or any(abs(float(p)) > 90 for p in head_scan_deg):
            raise ValueError(
                f"head_scan_deg must be non-empty pans within ±90°, got {head_scan_deg}"
            )
        self.velocity_action = velocity_action
        self.dt_s = float(dt_s)
        self.home_tolerance_m = float(home_tolerance_m)
        self.head_scan_deg = tuple(float(p) for p in head_scan_deg)
        self.settle_time_s = float(settle_time_s)
        self.max_spread_deg = float(max_spread_deg)
        self.rearm_factor = float(rearm_factor)
        if self.rearm_factor < 1:
            raise ValueError(f"rearm_factor must be >= 1, got {rearm_factor!r}")
        self.reset()

    @classmethod
    def for_env(cls, env, **kwargs) -> ScriptedHomingPolicy:
        """The policy for ``env`` (its ``velocity_action`` and ``control_dt``)."""
        u = env.unwrapped
        if not hasattr(u, "velocity_action"):
            raise ValueError(
                f"{type(u).__name__} has no velocity_action(); the scripted policy drives "
                "vc_gym/AiboRoom-v0 or vc_gym/LearnThenHome-v0"
            )
        return cls(u.velocity_action, dt_s=u.control_dt, **kwargs)

    def reset(self) -> None:
        """Start of a homing episode."""
        self._t = 0
        self._scan_i = 0
        self._arrived = False

    def predict(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        """The action (``Box(-1, 1, (5,))`` of the env) for one observation."""
        fwd_home, left_home = (float(v) for v in obs["home_vector"])
        spread = float(obs["heading_spread"][0])
        settling = self._t * self.dt_s < self.settle_time_s or spread > self.max_spread_deg
        self._t += 1
        dist = math.hypot(fwd_home, left_home)
        # hysteresis: once arrived, only a clearly wrong estimate makes the robot move
        tol = self.home_tolerance_m
        self._arrived = dist <= (self.rearm_factor if self._arrived else 1.0) * tol
        forward, turn = 0.0, 0.0
        if not settling and not self._arrived:
            err = math.degrees(math.atan2(left_home, fwd_home))
            turn = float(np.clip(2.5 * err, -60.0, 60.0))
            forward = 0.0 if abs(err) > 30 else min(0.25, 0.8 * dist)
        pan = 0.0
        if forward == 0.0:
            pans = self.head_scan_deg
            self._scan_i = (self._scan_i + 1) % len(pans)
            pan = pans[self._scan_i]
        return self.velocity_action(forward_m_s=forward, turn_deg_s=turn, pan_deg=pan)

    @staticmethod
    def is_still(action: np.ndarray, threshold: float = 0.05) -> bool:
        """No body motion commanded (the head may move)."""
        return bool(np.all(np.abs(np.asarray(action)[:3]) <= threshold))
