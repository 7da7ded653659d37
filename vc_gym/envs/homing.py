"""``vc_gym/Homing-v0``: the homing task as a learned agent sees it.

:class:`HomingEnv` is ``vc_gym/LearnThenHome-v0`` seen through
:class:`~vc_gym.envs.CompassObservation` (image dropped, any tracker) →
:class:`HomingFeatures` (one scaled feature vector) → :class:`StopAction` (walk, turn,
stop) [→ :class:`PreviousAction`]: one env class, whose ``unwrapped`` is itself, with
the feature vector and the three actions as its spaces. ``gym.make("vc_gym/Homing-v0",
**kwargs)``, ``gym.make_vec`` and stable-baselines3's ``make_vec_env`` all build exactly
what ``vc-gym train`` trains on.
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from vc_gym.envs.learn_then_home import LearnThenHomeEnv
from vc_gym.envs.learning import HEAD_SCAN_DEG
from vc_gym.envs.wrappers.compass_observation import CompassObservation
from vc_gym.localization import TrackerSpec
from vc_gym.validation import (
    MAX_HOMING_S,
    check_action,
    finite_real,
    flag,
    nonnegative_float,
    nonnegative_float_at_most,
    positive_float,
)

__all__ = [
    "LEARNED_CONFIRM_STOP_M",
    "MAX_HOME_OFFSET_M",
    "STOP_THRESHOLD",
    "HomingEnv",
    "HomingFeatures",
    "PreviousAction",
    "StopAction",
    "goal_vector",
    "home_offset",
    "make_homing_env",
]

STOP_THRESHOLD = 0.5
#: How far (metres) a learned agent's stop may be from where the tracker put home while it
#: stands for the task's stop time before its walk resumes: :class:`StopAction`'s
#: ``confirm_stop_m`` in training and in every evaluation, as the scripted agent checks
#: its own stops (``rearm_factor × home_tolerance_m`` = 0.25 m).
LEARNED_CONFIRM_STOP_M = 0.25
#: Largest ``home_offset_m`` accepted (metres): a correction of the tracker's home, not
#: another goal (the success radius is 0.3 m).
MAX_HOME_OFFSET_M = 1.0


def home_offset(value: Any) -> tuple[float, float]:
    """``home_offset_m`` checked: two finite numbers within :data:`MAX_HOME_OFFSET_M`."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 2:
        raise ValueError(f"home_offset_m must be two numbers (x, y) in metres, got {value!r}")
    x, y = (finite_real("home_offset_m", v) for v in value)
    if math.hypot(x, y) > MAX_HOME_OFFSET_M:
        raise ValueError(
            f"home_offset_m must be within {MAX_HOME_OFFSET_M} m of home, got ({x}, {y})"
        )
    return x, y


def goal_vector(
    home_vector: Any, heading: Any, offset_m: tuple[float, float]
) -> tuple[float, float]:
    """The robot-frame ``(forward, left)`` vector to the point ``offset_m`` (world frame)
    from home, given the home vector and the heading as ``(cos θ̂, sin θ̂)`` — the
    observation keys of :class:`~vc_gym.envs.CompassObservation`. A heading of
    ``(0, 0)`` (no atlas yet) leaves the home vector as it is."""
    c, s = (float(v) for v in heading)
    ox, oy = offset_m
    # home_vector + world_to_body(offset), written with cos/sin instead of an angle
    fwd, left = float(home_vector[0]), float(home_vector[1])
    return fwd + (ox * c + oy * s), left + (-ox * s + oy * c)


class HomingFeatures(gym.ObservationWrapper):
    """The compass outputs of :class:`~vc_gym.envs.CompassObservation` as one vector.

    ``[home_vector / 2 m (2), cos θ̂, sin θ̂, heading spread / 180°, position / 2 m (2),
    log goodness / 5 (one per spot, clipped to ±5), head pan / 90°]``, and with
    ``position_std=True`` the position's spread per axis / 0.5 m (2) after them: all of
    order 1. The class attributes name the slices and scales (what an agent reading the
    vector uses instead of bare indices; :meth:`position_std_slice` where the spread is).
    The spread lets a policy tell a position it can trust (a tracker with a position
    belief, such as ``pose-grid``, reports a few centimetres at home and metres after a
    kidnapping) from one it cannot.

    ``home_offset_m`` moves the goal the vector describes from the atlas' home to that
    point (world frame, metres from it): the home vector points there and the position
    is measured from there. A learned agent trained with it walks to, and stops at,
    that point of its tracker's estimate, which ``vc-gym train --home-offset-episodes N``
    can measure so that the expert's stops centre on the true home
    (:mod:`vc_gym.training.home_offset`). Default ``(0, 0)``.
    """

    HOME_VECTOR = slice(0, 2)
    HEADING = slice(2, 4)
    SPREAD = 4
    POSITION = slice(5, 7)
    GOODNESS_START = 7
    METRES_SCALE = 2.0
    SPREAD_SCALE_DEG = 180.0
    POSITION_STD_SCALE_M = 0.5
    #: Entries the position's spread adds with ``position_std=True``: ``(x, y)``.
    POSITION_STD_WIDTH = 2

    def __init__(self, env: gym.Env, home_offset_m: Any = (0.0, 0.0), position_std: bool = False):
        super().__init__(env)
        self.home_offset_m = home_offset(home_offset_m)
        self.position_std = flag("position_std", position_std)
        space = env.observation_space
        needed = {"home_vector", "heading", "heading_spread", "position", "goodness", "head"}
        if self.position_std:
            needed.add("position_std")
        if not isinstance(space, spaces.Dict) or not needed <= set(space.spaces):
            raise ValueError(f"HomingFeatures needs a CompassObservation env, got {space}")
        self.n_spots = space["goodness"].shape[0]
        n = 8 + self.n_spots + (self.POSITION_STD_WIDTH if self.position_std else 0)
        self.observation_space = spaces.Box(-10.0, 10.0, (n,), np.float32)

    @classmethod
    def position_std_slice(cls, n_spots: int) -> slice:
        """Where the position's spread lies in a vector of ``n_spots`` spots with
        ``position_std=True``."""
        start = cls.GOODNESS_START + n_spots + 1
        return slice(start, start + cls.POSITION_STD_WIDTH)

    def observation(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        g = np.log(np.maximum(obs["goodness"].astype(np.float64), 1e-12)) / 5.0
        home_vector = obs["home_vector"].astype(np.float64)
        position = obs["position"].astype(np.float64)
        if self.home_offset_m != (0.0, 0.0):
            home_vector = np.array(goal_vector(home_vector, obs["heading"], self.home_offset_m))
            position = position - self.home_offset_m
        f = np.concatenate(
            [
                home_vector / self.METRES_SCALE,
                obs["heading"],
                obs["heading_spread"] / self.SPREAD_SCALE_DEG,
                position / self.METRES_SCALE,
                np.clip(g, -5.0, 5.0),
                obs["head"][:1] / 90.0,
                *(
                    [obs["position_std"].astype(np.float64) / self.POSITION_STD_SCALE_M]
                    if self.position_std
                    else []
                ),
            ]
        )
        return np.clip(f, -10.0, 10.0).astype(np.float32)


class StopAction(gym.Wrapper):
    """``Box(-1, 1, (3,))`` actions: walk (> 0 forward), turn, stop (> 0.5).

    Walking maps ``max(a[0], 0)`` to ``max_forward`` m/s, turning ``a[1]`` to
    ``max_turn_deg_s`` (left positive), through the task env's ``velocity_action``.
    ``a[2] > 0.5`` makes the robot stand still, scanning with its head, until the
    wrapped task ends the episode (it stops after ``stop_time_s``); the rewards of
    those steps are summed into one. Holding a Gaussian policy's motion outputs near
    zero for 50 steps in a row is all but impossible to learn by chance; one stop
    decision is easy. Stop requests in the first ``min_walk_s`` of an episode (at most
    an hour, :data:`~vc_gym.validation.MAX_HOMING_S`) are ignored (the filters are
    still settling, and an untrained policy would otherwise end most episodes within a
    step or two), and so are those before the robot has walked ``min_walk_m`` by its
    own forward commands (default 0): right after a kidnapping 2 m out, one view can
    look exactly like home (README, *Beyond the paper*), and a policy that trusts it
    stops where it was put.

    Only the stop output ends an episode: a walk decision whose command is too small
    to count as moving for the task (``|forward|``, ``|turn|`` ≤ its ``still_threshold``)
    turns at the slowest rate that does count, towards ``a[1]``'s sign. Without this, a
    policy whose walk outputs hover near zero would stand still for the task's
    ``stop_time_s`` and end the episode by accident, which an untrained policy does often
    within its first few decisions.

    A decision that does not walk forward (turning in place, or standing while a stop is
    held) scans with the head, the next pan of ``HEAD_SCAN_DEG`` at each step, as the
    scripted agent does whenever it does not walk: the compass then sees more of the room
    than straight ahead. Without it (``head_scan=False``, what policies trained before
    this option saw) a learned agent kidnapped far from home could turn in place for the
    whole minute: there the tracker's position estimate turns with the robot and keeps
    home behind it (README, *Learned agents*).

    With ``confirm_stop_m`` a stop is checked while the robot stands, as the scripted
    agent checks its own: if at any step of the hold the estimated home (the features'
    home vector) is farther than that, the stop is called off and the step returns, not
    ended, so that the policy decides again. An episode can then end by a stop only
    where the estimate stays within ``confirm_stop_m`` of home for the task's
    ``stop_time_s``. ``None`` (default): a stop is final.

    Every step's ``info`` holds ``task_steps``: how many steps of the task env this
    decision took (1 for a walk, up to the whole stand for a stop), so that a
    decision's cost can be told from the env's step rate.
    """

    def __init__(
        self,
        env: gym.Env,
        max_forward: float = 0.4,
        max_turn_deg_s: float = 60.0,
        min_walk_s: float = 2.0,
        confirm_stop_m: float | None = None,
        head_scan: bool = True,
        min_walk_m: float = 0.0,
    ):
        super().__init__(env)
        inner = env.action_space
        if not isinstance(inner, spaces.Box) or inner.shape[0] < 5:
            raise ValueError(f"StopAction needs the task's Box(5) actions, got {inner}")
        task = env.unwrapped
        if not all(hasattr(task, k) for k in ("velocity_action", "is_still", "still_threshold")):
            raise ValueError(
                "StopAction wraps vc_gym/LearnThenHome-v0 (its velocity_action and stop rule)"
            )
        self.max_forward = positive_float("max_forward", max_forward)
        self.max_turn_deg_s = positive_float("max_turn_deg_s", max_turn_deg_s)
        nonnegative_float_at_most("min_walk_s", min_walk_s, MAX_HOMING_S, "seconds")
        self.min_walk_m = nonnegative_float("min_walk_m", min_walk_m)
        if confirm_stop_m is not None:
            positive_float("confirm_stop_m", confirm_stop_m)
            space = env.observation_space
            if not isinstance(space, spaces.Box) or space.shape[0] <= HomingFeatures.SPREAD:
                raise ValueError(
                    f"confirm_stop_m reads HomingFeatures' home vector; got observations {space}"
                )
        self.confirm_stop_m = confirm_stop_m
        self.head_scan = flag("head_scan", head_scan)
        self._pans = HEAD_SCAN_DEG
        self._scan_i = 0
        self._n = inner.shape[0]
        self.action_space = spaces.Box(-1.0, 1.0, (3,), np.float32)
        self._max_hold = 10**5
        self.min_walk_steps = int(round(min_walk_s / env.unwrapped.control_dt))
        self._full_step_m = self.max_forward * env.unwrapped.control_dt  # a full forward step
        self._t = 0
        self._walked_m = 0.0

    def reset(self, **kwargs):
        self._t = 0
        self._walked_m = 0.0
        self._scan_i = 0
        return self.env.reset(**kwargs)

    def _next_pan(self) -> float:
        """The head pan of the next step that does not walk forward (the scan goes on
        across decisions, as the scripted agent's)."""
        pan = self._pans[self._scan_i % len(self._pans)]
        self._scan_i += 1
        return float(pan)

    def _inner_action(self, forward: float, turn: float, pan_deg: float = 0.0) -> np.ndarray:
        a = np.zeros(self._n, np.float32)
        a[:5] = self.env.unwrapped.velocity_action(
            forward_m_s=forward * self.max_forward,
            turn_deg_s=turn * self.max_turn_deg_s,
            pan_deg=pan_deg,
        )
        return a

    def _walk_action(self, forward: float, turn: float) -> np.ndarray:
        """The task action of a walk decision, never one the task counts as standing still;
        the head scans if it does not walk forward."""
        a = self._inner_action(forward, turn)
        task = self.env.unwrapped
        if self.head_scan and abs(float(a[0])) <= task.still_threshold:
            a = self._inner_action(forward, turn, self._next_pan())
        if task.is_still(a):
            a[2] = np.float32(np.copysign(min(2.0 * task.still_threshold, 1.0), turn))
        return a

    def step(self, action):
        a = np.clip(check_action(action, self.action_space.shape), -1.0, 1.0)
        self._t += 1
        walking = self._t <= self.min_walk_steps or self._walked_m < self.min_walk_m
        if a[2] <= STOP_THRESHOLD or walking:
            forward = max(float(a[0]), 0.0)
            obs, r, terminated, truncated, info = self.env.step(self._walk_action(forward, a[1]))
            self._walked_m += forward * self._full_step_m
            return obs, r, terminated, truncated, {**info, "task_steps": 1}
        total = 0.0
        for i in range(self._max_hold):
            pan = self._next_pan() if self.head_scan else self._pans[i % len(self._pans)]
            obs, r, terminated, truncated, info = self.env.step(self._inner_action(0.0, 0.0, pan))
            total += float(r)
            if terminated or truncated or self._left_home(obs):
                break
        return obs, total, terminated, truncated, {**info, "task_steps": i + 1}

    def _left_home(self, obs: np.ndarray) -> bool:
        """With ``confirm_stop_m``: the estimated home is farther than that (the stop is
        called off and the policy decides again)."""
        if self.confirm_stop_m is None:
            return False
        home = np.asarray(obs[HomingFeatures.HOME_VECTOR], np.float64) * HomingFeatures.METRES_SCALE
        return bool(np.hypot(*home) > self.confirm_stop_m)


class PreviousAction(gym.Wrapper):
    """Append the last action taken (clipped to ``[-1, 1]``; zeros after a reset) to
    :class:`StopAction`'s feature vector: ``[..., walk, turn, stop]``.

    A memoryless policy cannot keep a turn going: with the goal right behind it, its
    turn is a smooth fit of a rule that changes sign at a bearing of 180°, so it is slow
    exactly there, and as the estimated goal moves round with the robot the bearing
    crosses 180° again and again and the turn reverses (README, *Learned agents*,
    turning on the spot). With its last action in view, a policy (and
    :class:`~vc_gym.agents.HomingFeatureExpert` with ``previous_action=True``) can keep
    turning the way it was turning.
    """

    #: Entries the previous action adds: ``(walk, turn, stop)``.
    WIDTH = 3
    #: Where the previous action lies in the vector.
    PREVIOUS_ACTION = slice(-WIDTH, None)

    def __init__(self, env: gym.Env):
        super().__init__(env)
        space = env.observation_space
        if not isinstance(space, spaces.Box) or len(space.shape) != 1:
            raise ValueError(f"PreviousAction needs a feature vector env, got {space}")
        # the same bounds as the features' (what a saved model's space is checked against)
        self.observation_space = spaces.Box(-10.0, 10.0, (space.shape[0] + self.WIDTH,), np.float32)

    def reset(self, **kwargs: Any):
        obs, info = self.env.reset(**kwargs)
        return self._with(obs, np.zeros(self.WIDTH)), info

    def step(self, action):
        a = check_action(action, self.action_space.shape)  # before the step, not after
        obs, r, terminated, truncated, info = self.env.step(action)
        return (
            self._with(obs, np.clip(a, -1.0, 1.0)),
            r,
            terminated,
            truncated,
            info,
        )

    @staticmethod
    def _with(obs: np.ndarray, action: np.ndarray) -> np.ndarray:
        return np.concatenate([obs, action]).astype(np.float32)


class _Task(gym.Env):
    """The learn-then-home task inside a :class:`HomingEnv`, as its wrappers see it.

    Its spaces are the task's, ``reset`` and ``step`` are
    :class:`~vc_gym.envs.LearnThenHomeEnv`'s own, and ``unwrapped`` is the
    :class:`HomingEnv` (the wrappers read the task's attributes from there).
    """

    def __init__(self, env: HomingEnv):
        self._env = env
        self.observation_space = env.task_observation_space
        self.action_space = env.task_action_space
        self.metadata = env.metadata
        self.render_mode = env.render_mode

    @property
    def unwrapped(self) -> HomingEnv:
        return self._env

    @property
    def np_random(self) -> np.random.Generator:
        return self._env.np_random

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        return LearnThenHomeEnv.reset(self._env, seed=seed, options=options)

    def step(self, action: np.ndarray):
        return LearnThenHomeEnv.step(self._env, action)

    def render(self) -> np.ndarray | None:
        return LearnThenHomeEnv.render(self._env)

    def close(self) -> None:
        """Nothing: the :class:`HomingEnv` closes the task."""


class HomingEnv(LearnThenHomeEnv):
    """``vc_gym/Homing-v0``: the homing phase of the learn-then-home task as a learned
    agent sees it.

    ## Description

    The task of :class:`~vc_gym.envs.LearnThenHomeEnv` (scripted learning phase inside
    ``reset``, kidnapping, homing; paper 5.2), observed through the compass and a
    tracker (:class:`~vc_gym.envs.CompassObservation`, eq. 23-32) as one feature vector
    (:class:`HomingFeatures`) and acted on with walk, turn and stop decisions
    (:class:`StopAction`). The env is one class: ``env.unwrapped`` is this env, with
    these spaces and every attribute of the task (``atlas``, ``room``,
    ``learning_result``, ``control_dt``, ...); the wrappers it applies inside are
    :attr:`compass_observation`, :attr:`features`, :attr:`stop_action` (and
    :attr:`previous_action_wrapper`). The settings of those wrappers
    (``min_walk_m``, ``confirm_stop_m``, ``head_scan``, ``n_spots``, ...) are read and
    set through the env, so ``get_wrapper_attr`` and ``set_wrapper_attr`` find them.

    ## Action Space

    ``Box(-1, 1, (3,), float32)``: walk (> 0 forward, scaled to ``max_forward`` m/s),
    turn (left positive, scaled to ``max_turn_deg_s``), stop (> 0.5: stand still,
    scanning with the head, until the task ends the episode). See :class:`StopAction`.

    ## Observation Space

    ``Box(-10, 10, (8 + n_spots,), float32)`` (``n_spots`` = 4 for the paper's spots,
    25 with turns around them, ``around_m``): home vector / 2 m, ``(cos θ̂, sin θ̂)``,
    heading spread / 180°, position / 2 m, log goodness / 5 of each spot, head pan / 90°
    (:class:`HomingFeatures`); with ``position_std=True`` the position's spread / 0.5 m
    follows (2 more entries), and with ``previous_action=True`` the last action taken (3
    more).

    ## Rewards, Starting State, Episode End, Info

    The task's (:class:`~vc_gym.envs.LearnThenHomeEnv`); a stop decision's steps are
    summed into one reward, and ``info["task_steps"]`` says how many task steps a
    decision took. An episode lasts at most :attr:`max_episode_steps` decisions (the
    registered ``max_episode_steps`` at the defaults).

    Parameters
    ----------
    tracker : str, dict or callable
        The tracker of the :class:`~vc_gym.envs.CompassObservation` wrapper.
    max_forward, max_turn_deg_s, min_walk_s : float
        :class:`StopAction` settings (``min_walk_s`` in [0, 3600] seconds).
    confirm_stop_m : float, optional
        :class:`StopAction`'s check of a stop while the robot stands.
    head_scan : bool
        :class:`StopAction` scans with the head in decisions that do not walk forward.
    min_walk_m : float
        :class:`StopAction` ignores stop requests until the robot has walked this far.
    home_offset_m : (float, float)
        :class:`HomingFeatures`' goal, relative to the atlas' home (world frame, m).
    previous_action : bool
        Append the last action to the features (:class:`PreviousAction`). Default False.
    position_std : bool
        The features carry the tracker's position spread (:class:`HomingFeatures`).
        Default False.
    **task_kwargs
        Arguments of ``vc_gym/LearnThenHome-v0`` (``scene``, ``learn_time_s``,
        ``stop_time_s``, ``success_radius_m``, ``max_homing_s``, ``learning_seed``,
        ``place_cache``, ``atlas_file``, ...), with its bounds; its learning is scripted.
    """

    def __init__(
        self,
        tracker: TrackerSpec = "grid",
        max_forward: float = 0.4,
        max_turn_deg_s: float = 60.0,
        min_walk_s: float = 2.0,
        confirm_stop_m: float | None = None,
        head_scan: bool = True,
        min_walk_m: float = 0.0,
        home_offset_m: Any = (0.0, 0.0),
        previous_action: bool = False,
        position_std: bool = False,
        **task_kwargs: Any,
    ):
        home_offset_m = home_offset(home_offset_m)  # refused before a world is built
        self.previous_action = flag("previous_action", previous_action)
        flag("position_std", position_std)
        if task_kwargs.get("learning", "scripted") != "scripted":
            raise ValueError("vc_gym/Homing-v0 learns the place by script (learning='scripted')")
        super().__init__(**task_kwargs)
        try:
            #: The wrappers inside, innermost first.
            self.compass_observation = CompassObservation(
                _Task(self), keep_image=False, tracker=tracker
            )
            self.features = HomingFeatures(self.compass_observation, home_offset_m, position_std)
            self.stop_action = StopAction(
                self.features,
                max_forward,
                max_turn_deg_s,
                min_walk_s,
                confirm_stop_m,
                head_scan,
                min_walk_m,
            )
            self.previous_action_wrapper = (
                PreviousAction(self.stop_action) if self.previous_action else None
            )
        except Exception:
            LearnThenHomeEnv.close(self)
            raise
        self._outer: gym.Env = self.previous_action_wrapper or self.stop_action
        self.observation_space = self._outer.observation_space
        self.action_space = self._outer.action_space
        # outermost first: where an attribute the env lacks is looked up
        self._inner_wrappers = tuple(
            w
            for w in (
                self.previous_action_wrapper,
                self.stop_action,
                self.features,
                self.compass_observation,
            )
            if w is not None
        )

    def _owner(self, name: str) -> gym.Wrapper | None:
        """The inner wrapper that holds ``name`` as its own attribute, outermost first."""
        for w in self.__dict__.get("_inner_wrappers", ()):
            if name in w.__dict__ or isinstance(getattr(type(w), name, None), property):
                return w
        return None

    def __getattr__(self, name: str) -> Any:
        # the settings of the wrappers inside (min_walk_m, confirm_stop_m, head_scan,
        # n_spots, ...), as get_wrapper_attr finds them on a chain of wrappers
        # (private names and a wrapper's own ``env`` stay private: the env is no wrapper)
        owner = None if name.startswith("_") or name == "env" else self._owner(name)
        if owner is None:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        return getattr(owner, name)

    def __setattr__(self, name: str, value: Any) -> None:
        # set_wrapper_attr of a wrapper's setting reaches that wrapper
        if not name.startswith("_") and name not in self.__dict__ and not hasattr(type(self), name):
            owner = self._owner(name)
            if owner is not None:
                setattr(owner, name, value)
                return
        super().__setattr__(name, value)

    # what callers read and set through get_wrapper_attr / set_wrapper_attr
    @property
    def tracker(self) -> Any:
        """The tracker (:attr:`compass_observation`'s)."""
        return self.compass_observation.tracker

    @property
    def last_state(self) -> Any:
        """The tracker's last :class:`~vc_gym.localization.TrackerState`."""
        return self.compass_observation.last_state

    @property
    def tracker_time_s(self) -> float:
        """Wall time spent in the tracker's updates (a benchmark figure)."""
        return self.compass_observation.tracker_time_s

    @property
    def tracker_updates(self) -> int:
        """The tracker's updates so far."""
        return self.compass_observation.tracker_updates

    @property
    def home_offset_m(self) -> tuple[float, float]:
        """:attr:`features`' goal relative to the atlas' home (settable, checked)."""
        return self.features.home_offset_m

    @home_offset_m.setter
    def home_offset_m(self, value: Any) -> None:
        self.features.home_offset_m = home_offset(value)

    @property
    def max_forward(self) -> float:
        """Walking speed of a full walk decision (m/s)."""
        return self.stop_action.max_forward

    @property
    def max_turn_deg_s(self) -> float:
        """Turn rate of a full turn decision (degrees per second)."""
        return self.stop_action.max_turn_deg_s

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        return self._outer.reset(seed=seed, options=options)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        return self._outer.step(action)


def make_homing_env(**kwargs: Any) -> HomingEnv:
    """``HomingEnv(**kwargs)``: ``vc_gym/Homing-v0`` without Gymnasium's checker
    wrappers (kept for code that built the env this way; ``gym.make`` is the usual way)."""
    return HomingEnv(**kwargs)
