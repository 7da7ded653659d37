"""The paper's scripted homing behaviour (section 5.2), acting on a tracker's estimates.

:class:`ScriptedHomingPolicy` reads only the robot's own observation: what
:class:`~vc_gym.envs.CompassObservation` adds (the estimated home vector, heading and
heading spread) and the odometry; it never sees the true pose. The learning phase that comes
before homing belongs to the task (:mod:`vc_gym.envs.learning`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from vc_gym.envs.homing import goal_vector, home_offset
from vc_gym.envs.learning import HEAD_SCAN_DEG
from vc_gym.poses import body_to_world, world_to_body
from vc_gym.validation import head_pans, nonnegative_float, positive_float

__all__ = ["ScriptedHomingAgent", "ScriptedHomingPolicy"]


class ScriptedHomingPolicy:
    """The paper's homing behaviour on :class:`~vc_gym.envs.CompassObservation` outputs.

    First stand still (head scanning) for ``settle_time_s`` and until the heading
    spread is below ``max_spread_deg``, so the filters settle; then turn towards the
    estimated home and walk (slower when close); stand still, scanning with the head,
    once the estimate is within ``home_tolerance_m`` of home. Uses only
    ``home_vector`` and ``heading_spread`` of the observation, and with
    ``verify_home`` also ``heading`` and ``odometry``.

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
    walk_scan_deg : tuple of float, optional
        Head pans cycled while walking too (beyond the paper, whose head looks ahead):
        a tracker that sees both sides of the room on the way home is not fooled by one
        side fitting a pose nearby. Default ``None``: head straight while walking.
    look_std_m : float, optional
        Beyond the paper: while the tracker's position standard deviation (the larger
        axis of ``position_std``) exceeds this after settling, the robot neither walks
        nor stands but turns on the spot at ``look_turn_deg_s``, scanning with the head:
        an unsure belief gets new views instead of leading the robot astray, and the
        task does not take the wait for a stop. Default ``None``: never.
    look_turn_deg_s : float
        Turn rate while looking.
    settle_time_s : float
        Time to stand still at the start of homing.
    max_spread_deg : float
        Stand still while the heading belief is wider than this.
    rearm_factor : float
        Once within ``home_tolerance_m``, walk again only when the estimate leaves
        ``rearm_factor × home_tolerance_m`` (the estimate jitters by ~0.1 m as the head
        scans; without this hysteresis the robot shuffles around home and never stops).
    verify_home : bool
        Beyond the paper: before stopping, check that this is home. The eq. 30
        position of a single view can alias: from some spots 1–2 m away, one heading
        looks exactly like home (every spot's goodness ≈ 1), and the paper's robot
        stops there. A place aliases at some headings, not at all of them, so when the
        estimate says "home" the robot turns a full circle on the spot (head
        straight) and averages the home offset ``R(θ̂)·home_vector`` over the turn. If
        that average is within ``verify_tolerance_m`` it stops; otherwise it walks
        ``verify_gain`` times the averaged offset by dead reckoning (odometry only,
        since the view it would correct with is the one that aliases) and checks again,
        at most ``max_verifications`` times. The full-turn average points towards home
        everywhere on the robolab field but shrinks with distance (about half the
        distance at 1–2 m), hence the gain above 1.
    verify_tolerance_m : float
        The full-turn home offset that counts as home.
    verify_gain : float
        Multiplier of the averaged offset walked after a failed check.
    max_verifications : int
        Full turns at most per episode; after the last one the robot stops.
    verify_turn_deg_s : float
        Turn rate of the checking turn.
    sure_std_m : float, optional
        With ``verify_home``: when the estimate says home and the tracker's position
        standard deviation (``position_std`` of the observation, the larger axis) is at
        most this, the belief is sure and the robot stops without the checking turn.
        Meant for a tracker whose position belief is honest (the ``pose`` tracker);
        default ``None``: always check.
    home_offset_m : (float, float)
        The goal, relative to the tracker's home (world frame, metres): the policy walks
        to and stops where the estimate reads this. Default ``(0, 0)``, the paper's. A
        learned agent's training measures one (``home_offset_m`` of its
        ``config.json``, :mod:`vc_gym.training.home_offset`); giving the scripted
        agent the same shows what the goal alone is worth.
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
        verify_home: bool = False,
        verify_tolerance_m: float = 0.15,
        verify_gain: float = 1.5,
        max_verifications: int = 4,
        verify_turn_deg_s: float = 60.0,
        home_offset_m: tuple[float, float] = (0.0, 0.0),
        sure_std_m: float | None = None,
        walk_scan_deg: tuple[float, ...] | None = None,
        look_std_m: float | None = None,
        look_turn_deg_s: float = 45.0,
    ):
        if not callable(velocity_action):
            raise ValueError(f"velocity_action must be callable, got {velocity_action!r}")
        for name, v in (
            ("dt_s", dt_s),
            ("home_tolerance_m", home_tolerance_m),
            ("max_spread_deg", max_spread_deg),
            ("rearm_factor", rearm_factor),
            ("verify_tolerance_m", verify_tolerance_m),
            ("verify_gain", verify_gain),
            ("verify_turn_deg_s", verify_turn_deg_s),
            ("look_turn_deg_s", look_turn_deg_s),
        ):
            positive_float(name, v)
        nonnegative_float("settle_time_s", settle_time_s)
        self.velocity_action = velocity_action
        self.dt_s = float(dt_s)
        self.home_tolerance_m = float(home_tolerance_m)
        self.head_scan_deg = head_pans("head_scan_deg", head_scan_deg)
        self.walk_scan_deg = (
            None if walk_scan_deg is None else head_pans("walk_scan_deg", walk_scan_deg)
        )
        self.settle_time_s = float(settle_time_s)
        self.max_spread_deg = float(max_spread_deg)
        self.rearm_factor = float(rearm_factor)
        if self.rearm_factor < 1:
            raise ValueError(f"rearm_factor must be >= 1, got {rearm_factor!r}")
        if not isinstance(verify_home, bool):
            raise ValueError(f"verify_home must be a bool, got {verify_home!r}")
        if (
            isinstance(max_verifications, bool)
            or not isinstance(max_verifications, int)
            or (max_verifications < 1)
        ):
            raise ValueError(f"max_verifications must be an int >= 1, got {max_verifications!r}")
        self.verify_home = verify_home
        self.verify_tolerance_m = float(verify_tolerance_m)
        self.verify_gain = float(verify_gain)
        self.max_verifications = max_verifications
        self.verify_turn_deg_s = float(verify_turn_deg_s)
        self.home_offset_m = home_offset(home_offset_m)
        self.sure_std_m = None if sure_std_m is None else positive_float("sure_std_m", sure_std_m)
        self.look_std_m = None if look_std_m is None else positive_float("look_std_m", look_std_m)
        self.look_turn_deg_s = float(look_turn_deg_s)
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
        #: "walk" (the paper's behaviour), "verify" (checking turn), "correct" (dead
        #: reckoning to the checked offset) or "done"
        self.phase = "walk"
        #: world-frame home offset (m) averaged over each checking turn, in order
        self.checks: list[tuple[float, float]] = []
        self._turned_deg = 0.0
        self._offsets: list[tuple[float, float]] = []
        self._target = (0.0, 0.0)

    def predict(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        """The action (``Box(-1, 1, (5,))`` of the env) for one observation."""
        if self.verify_home and self.phase != "walk":
            return self._verifying(obs)
        fwd_home, left_home = self._home_vector(obs)
        spread = float(obs["heading_spread"][0])
        settled = self._t * self.dt_s >= self.settle_time_s
        settling = not settled or spread > self.max_spread_deg
        self._t += 1
        if settled and self._unsure(obs):
            pan = self._next_pan(self.head_scan_deg)
            return self.velocity_action(turn_deg_s=self.look_turn_deg_s, pan_deg=pan)
        dist = math.hypot(fwd_home, left_home)
        # hysteresis: once arrived, only a clearly wrong estimate makes the robot move
        tol = self.home_tolerance_m
        self._arrived = dist <= (self.rearm_factor if self._arrived else 1.0) * tol
        if self.verify_home and not settling and self._arrived:
            if self._sure(obs):
                self.phase = "done"
                return self._verifying(None)
            return self._start_verification()
        forward, turn = 0.0, 0.0
        if not settling and not self._arrived:
            forward, turn = self._walk_towards(fwd_home, left_home)
        pan = self._next_pan(self.head_scan_deg if forward == 0.0 else self.walk_scan_deg)
        return self.velocity_action(forward_m_s=forward, turn_deg_s=turn, pan_deg=pan)

    def _next_pan(self, pans: tuple[float, ...] | None) -> float:
        """The next head pan of the scan ``pans`` (``None``: straight ahead)."""
        if pans is None:
            return 0.0
        self._scan_i = (self._scan_i + 1) % len(pans)
        return pans[self._scan_i]

    def _unsure(self, obs: dict[str, np.ndarray]) -> bool:
        """The position belief is too wide to walk on (``look_std_m``)."""
        if self.look_std_m is None:
            return False
        return float(np.max(obs["position_std"])) > self.look_std_m

    def _sure(self, obs: dict[str, np.ndarray]) -> bool:
        """The position belief is sure enough to stop without checking (``sure_std_m``)."""
        if self.sure_std_m is None:
            return False
        return float(np.max(obs["position_std"])) <= self.sure_std_m

    def _home_vector(self, obs: dict[str, np.ndarray]) -> tuple[float, float]:
        """The goal in the robot's frame: the home vector moved by ``home_offset_m``."""
        if self.home_offset_m == (0.0, 0.0):
            fwd, left = (float(v) for v in obs["home_vector"])
            return fwd, left
        return goal_vector(obs["home_vector"], obs["heading"], self.home_offset_m)

    def _walk_towards(self, fwd: float, left: float) -> tuple[float, float]:
        """Forward speed and turn rate towards a robot-frame point (the paper's gait)."""
        err = math.degrees(math.atan2(left, fwd))
        turn = float(np.clip(2.5 * err, -60.0, 60.0))
        forward = 0.0 if abs(err) > 30 else min(0.25, 0.8 * math.hypot(fwd, left))
        return forward, turn

    def _start_verification(self) -> np.ndarray:
        if len(self.checks) >= self.max_verifications:
            self.phase = "done"
        else:
            self.phase, self._turned_deg, self._offsets = "verify", 0.0, []
        return self._verifying(None)

    def _verifying(self, obs: dict[str, np.ndarray] | None) -> np.ndarray:
        if self.phase == "verify":
            if obs is not None:
                self._turned_deg += abs(float(obs["odometry"][2]))
                c, s = (float(v) for v in obs["heading"])
                heading = math.degrees(math.atan2(s, c))
                self._offsets.append(body_to_world(*self._home_vector(obs), heading))
            if self._turned_deg < 360.0:
                return self.velocity_action(turn_deg_s=self.verify_turn_deg_s, pan_deg=0.0)
            # the turn is complete only after an observation, so ``heading`` is this one's
            dx, dy = (float(v) for v in np.mean(self._offsets, axis=0))
            self.checks.append((dx, dy))
            if math.hypot(dx, dy) <= self.verify_tolerance_m:
                self.phase = "done"
            else:
                g = self.verify_gain
                self._target = world_to_body(g * dx, g * dy, heading)
                self.phase = "correct"
                return self._verifying(None)
        if self.phase == "correct":
            if obs is not None:
                fwd, left, turn = (float(v) for v in obs["odometry"])
                tf, tl = self._target
                self._target = world_to_body(tf - fwd, tl - left, turn)
            if math.hypot(*self._target) <= 0.5 * self.home_tolerance_m:
                return self._start_verification()
            forward, turn = self._walk_towards(*self._target)
            return self.velocity_action(forward_m_s=forward, turn_deg_s=turn, pan_deg=0.0)
        return self.velocity_action(pan_deg=0.0)  # done: stand still until the task ends

    @staticmethod
    def is_still(action: np.ndarray, threshold: float = 0.05) -> bool:
        """No body motion commanded (the head may move)."""
        return bool(np.all(np.abs(np.asarray(action)[:3]) <= threshold))


class ScriptedHomingAgent:
    """The scripted homing behaviour as an agent: the env it acts in and its policy.

    It acts in ``vc_gym/LearnThenHome-v0`` (:attr:`env_id`) seen through
    :class:`~vc_gym.envs.CompassObservation` (:attr:`observation` ``"compass"``); whoever
    runs it builds that env and asks for :meth:`policy`.

    Parameters
    ----------
    **policy_kwargs
        Keyword arguments of :class:`ScriptedHomingPolicy`.
    """

    #: The registered env the agent acts in.
    env_id: ClassVar[str] = "vc_gym/LearnThenHome-v0"
    #: What it observes: the task's observation with what ``CompassObservation`` adds.
    observation: ClassVar[str] = "compass"

    def __init__(self, **policy_kwargs: Any) -> None:
        self.policy_kwargs = dict(policy_kwargs)
        #: Its own settings of the env (none: the task's).
        self.env_kwargs: dict[str, Any] = {}

    def policy(self, env: Any) -> ScriptedHomingPolicy:
        """A fresh :class:`ScriptedHomingPolicy` driving ``env``."""
        return ScriptedHomingPolicy.for_env(env, **self.policy_kwargs)
