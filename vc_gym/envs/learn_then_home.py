"""The paper's task: learn a place, be kidnapped, walk back home (sections 4.3, 5.2)."""

from __future__ import annotations

import inspect
import math
import os
import warnings
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from vc_gym import ENV_SPECS, MAX_HOMING_S, MAX_LEARNING_S, time_limit_steps
from vc_gym.compass import Camera, CompassAtlas, CompassConfig, VisualCompass
from vc_gym.envs.atlas_file import AtlasFile
from vc_gym.envs.learning import (
    HOME,
    Learner,
    LearningConfig,
    LearningResult,
    RobotFell,
    ScriptedLearning,
    kidnap_pose,
    paper_spots,
    scripted_atlas_size,
)
from vc_gym.envs.place_cache import CachedLearner, PlaceCache, place_key_value
from vc_gym.poses import compose
from vc_gym.sim.aibo_room import RESET_OPTIONS, AiboRoomEnv
from vc_gym.validation import MAX_HOMING_S as LONGEST_HOMING_S
from vc_gym.validation import (
    MAX_LEARNING_PHASE_S,
    check_action,
    check_reset_options,
    flag,
    int_at_least,
    nonnegative_float,
    positive_float,
    positive_float_at_most,
)

__all__ = ["EpisodeLimitWarning", "LearnThenHomeEnv", "LEARNING_MODES", "make_task"]

LEARNING_MODES = ("scripted", "agent")
RELEARN_MODES = ("scene", "episode")


class EpisodeLimitWarning(UserWarning):
    """``gym.make`` of a task whose episodes can outlast the registered
    ``max_episode_steps``: its ``TimeLimit`` would end them early."""


def make_task(env_id: str, **kwargs: Any) -> gym.Env:
    """``gym.make(env_id, **kwargs)`` of a task that ends its episodes itself (its own
    ``max_homing_s``), without Gymnasium's ``TimeLimit``: what the episode runner and
    training use, whose time limits may exceed the registered horizon."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", EpisodeLimitWarning)
        return gym.make(env_id, max_episode_steps=-1, **kwargs)


@dataclass
class _Frame:
    image: np.ndarray
    x: float
    y: float
    camera_yaw_deg: float


class LearnThenHomeEnv(gym.Env):
    """Learn the panorama around home, get kidnapped, walk back home.

    ## Description

    The homing experiment of Sturm & Visser (5.2) on ``vc_gym/AiboRoom-v0``. Home is the
    world origin (robolab: the centre of the kickoff circle); the robot starts there
    facing 0°. In the **learning phase** it learns the panorama at spots around home:
    either by a learner run inside :meth:`reset` (``learning="scripted"``; by default
    the paper's behaviour, :class:`~vc_gym.envs.learning.ScriptedLearning`: a full
    turn at home, four spots 1 m away, 8 × 45° each for ``learn_time_s``,
    normalisation at home) or by the agent itself (``learning="agent"``: the
    agent walks and marks frames to learn, see the action space). Then it is
    **kidnapped** to a random pose on the field (``kidnap_margin_m`` inside its edges)
    with a random heading, and **homes**. The learned :class:`CompassAtlas` is the
    ``atlas`` attribute; wrap the env in :class:`~vc_gym.envs.CompassObservation` to
    give the agent the compass' and filters' estimates.

    ## Action Space

    ``Box(-1, 1, (5,), float32)`` as in ``vc_gym/AiboRoom-v0`` (forward, sideways,
    turn, head pan, head tilt). With ``learning="agent"`` it is ``Box(-1, 1, (7,))``:
    the two extra entries are *learn* (> 0: learn this frame at the spot the robot
    believes it is at) and *finish* (> 0: end the learning phase); both are ignored
    while homing.

    ## Observation Space

    ``Dict`` of ``vc_gym/AiboRoom-v0`` (``image``, ``head``, ``odometry``) plus
    ``phase``: ``Box(0, 1, (1,))``, 0 while learning, 1 while homing. Never the true pose.

    ## Rewards

    While homing, each step earns ``progress_reward × (d_before − d_after)``, where
    ``d`` is the true distance from home in metres (walking 1 m closer earns
    ``progress_reward``, 10 by default). Stopping (standing still for ``stop_time_s``)
    within ``success_radius_m`` of home adds ``success_bonus`` (10) and
    ``closeness_bonus × (1 − d / success_radius_m)`` (default 0: a stop at home earns the
    whole ``closeness_bonus``, one at the radius nothing); falling costs
    ``fall_penalty`` (10). The learning phase earns nothing; an agent that learned no
    frame ends the episode with ``-fall_penalty``.

    ## Starting State

    The returned observation is the first homing frame (scripted learning) or the
    robot at home facing 0° (agent learning). ``options={"pose": (x, y, yaw)}`` sets
    the kidnapping pose.

    ## Episode End

    Terminated when the robot has stood still (``|forward|``, ``|sideways|`` and
    ``|turn|`` actions all ≤ ``still_threshold``; the head may move) for ``stop_time_s``
    while homing (paper: 5 s), or falls; truncated after ``max_homing_s`` of homing
    (:attr:`max_episode_steps` steps: 600 at the defaults, the registered
    ``max_episode_steps``, so Gymnasium's ``TimeLimit`` truncates on the same step as
    the env). With ``learning="agent"`` the learning phase ends after ``max_learning_s``
    as if the agent had finished it, and an episode can last ``max_learning_s +
    max_homing_s``: pass ``max_episode_steps=env.unwrapped.max_episode_steps`` to
    ``gym.make`` (it warns otherwise), as for any ``max_homing_s`` above the default.

    ## Arguments

    ``gym.make("vc_gym/LearnThenHome-v0", learning="scripted", relearn="scene",
    learn_time_s=5.0, spot_distance_m=1.0, stop_time_s=5.0, success_radius_m=0.3,
    max_homing_s=60.0, ...)`` — see ``__init__``; other keyword arguments (``scene``,
    ``randomize``, ``locomotion``, ``illumination``, ``control_dt``,
    ``odometry_noise``, ``camera``, ...) go to ``vc_gym/AiboRoom-v0``. The times are
    bounded (:mod:`vc_gym.validation`): ``learn_time_s`` to 60 s
    (``MAX_LEARN_TIME_S``, checked by :class:`~vc_gym.envs.learning.LearningConfig`),
    ``stop_time_s`` and ``max_homing_s`` to an hour (``MAX_HOMING_S``),
    ``max_learning_s`` to an hour (``MAX_LEARNING_PHASE_S``); a larger value is a
    ``ValueError`` naming the argument and its bound, raised before a world is built.
    ``relearn="scene"`` learns once per scene and reuses the atlas in later episodes
    (the paper learned once and kidnapped many times); ``"episode"`` learns anew in
    every reset. ``learner`` is any callable ``learner(room, config) ->
    LearningResult`` (``room``: the ``AiboRoomEnv`` just reset at home facing 0°,
    ``config``: the :class:`~vc_gym.envs.learning.LearningConfig` built from the
    arguments); the result is kept as ``learning_result``. ``normalise_at="return"``
    (the paper) normalises the spots after walking back home by odometry;
    ``"start"`` uses the frames of the first turn, taken at the true home (the stops
    then lose the offset of the walk back's odometry drift). ``around_m > 0`` also
    learns turns ``around_m`` around home and every spot, kept as atlas entries of their
    own (:class:`~vc_gym.envs.learning.LearningConfig`; the atlas then has 25 entries):
    the input of the ``pose`` tracker. ``landmarks=True`` also places the colour changes
    the learned turns saw in the room (the atlas' ``landmarks``), the input of a bearing
    tracker. ``learning_seed`` seeds the
    room for the learning phase on its own (default: drawn from the reset seed), so that
    envs reset with different seeds learn the same place the same way.
    ``atlas_file="place.npz"`` keeps the learning phase's atlas in that file: the first
    env to need it learns and writes it, every later one (other workers too, under a
    lock) loads it instead of learning; a file learned with other settings is refused.
    With an ``atlas_file``, episodes do not depend on whether this env learned or
    loaded the atlas. The scripted learning phase is kept in the place
    cache (``place_cache=True``, default; :mod:`vc_gym.envs.place_cache`): a place is
    learned once per set of settings and learning seed, by the first env that needs it
    (a progress bar on stderr), and loaded by every later env, in this run or another,
    with bit-identical episodes. ``place_cache`` may also be a folder or a
    :class:`~vc_gym.envs.place_cache.PlaceCache`; ``False`` (or ``None``) learns in
    every env. Only the default learner is cached, and only when the learning seed is
    known (``learning_seed``, or a seeded first reset). A missing ``atlas_file`` is
    written from the cache when the cache has the place.

    ## Info

    Everything ``vc_gym/AiboRoom-v0`` reports (``pose`` is the true pose: for
    evaluation, not for agents), ``phase`` (``"learning"``/``"homing"``),
    ``home_error_m`` (true distance from home), ``still_time_s``; at the end of an
    episode also ``stop_position`` (true x, y), ``stop_error_m``, ``stopped``,
    ``success`` and ``is_success`` (stopped within ``success_radius_m``).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        render_mode: str | None = None,
        learning: str = "scripted",
        relearn: str = "scene",
        learn_time_s: float = 5.0,
        spot_distance_m: float = 1.0,
        stop_time_s: float = 5.0,
        success_radius_m: float = 0.3,
        max_homing_s: float = MAX_HOMING_S,
        max_learning_s: float = MAX_LEARNING_S,
        kidnap_margin_m: float = 0.5,
        still_threshold: float = 0.05,
        progress_reward: float = 10.0,
        success_bonus: float = 10.0,
        closeness_bonus: float = 0.0,
        fall_penalty: float = 10.0,
        max_spots: int = 8,
        spot_radius_m: float = 0.25,
        compass: CompassConfig | None = None,
        learner: Learner | None = None,
        normalise_at: str = "return",
        around_m: float = 0.0,
        landmarks: bool = False,
        learning_seed: int | None = None,
        atlas_file: str | os.PathLike | None = None,
        place_cache: bool | str | os.PathLike | PlaceCache | None = True,
        **room_kwargs: Any,
    ):
        if learning not in LEARNING_MODES:
            raise ValueError(f"learning must be one of {LEARNING_MODES}, got {learning!r}")
        if relearn not in RELEARN_MODES:
            raise ValueError(f"relearn must be one of {RELEARN_MODES}, got {relearn!r}")
        for name, v in (
            ("learn_time_s", learn_time_s),
            ("spot_distance_m", spot_distance_m),
            ("success_radius_m", success_radius_m),
            ("spot_radius_m", spot_radius_m),
        ):
            positive_float(name, v)
        # learn_time_s is bounded by LearningConfig, built below before the room
        for name, v, longest in (
            ("stop_time_s", stop_time_s, LONGEST_HOMING_S),
            ("max_homing_s", max_homing_s, LONGEST_HOMING_S),
            ("max_learning_s", max_learning_s, MAX_LEARNING_PHASE_S),
        ):
            positive_float_at_most(name, v, longest, "seconds")
        for name, v in (
            ("kidnap_margin_m", kidnap_margin_m),
            ("still_threshold", still_threshold),
            ("progress_reward", progress_reward),
            ("success_bonus", success_bonus),
            ("closeness_bonus", closeness_bonus),
            ("fall_penalty", fall_penalty),
        ):
            nonnegative_float(name, v)
        if still_threshold >= 1:
            raise ValueError(f"still_threshold must be < 1, got {still_threshold}")
        if not (isinstance(max_spots, int) and max_spots >= 1):
            raise ValueError(f"max_spots must be an int >= 1, got {max_spots!r}")
        if compass is not None and not isinstance(compass, CompassConfig):
            raise ValueError(f"compass must be a CompassConfig, got {type(compass).__name__}")
        if learner is not None and not callable(learner):
            raise ValueError(f"learner must be callable(room, config), got {learner!r}")

        if learning_seed is not None:
            int_at_least("learning_seed", learning_seed, 0)
        if around_m and learning != "scripted":
            raise ValueError("around_m needs learning='scripted' (the agent learns its own)")
        if flag("landmarks", landmarks) and learning != "scripted":
            raise ValueError("landmarks needs learning='scripted' (the agent learns its own)")
        if atlas_file is not None and learning != "scripted":
            raise ValueError("atlas_file needs learning='scripted' (the agent learns its own)")
        if atlas_file is not None and room_kwargs.get("randomize"):
            raise ValueError("atlas_file cannot be shared by randomised scenes (each differs)")
        if place_cache is None or isinstance(place_cache, bool):
            cache = PlaceCache() if place_cache else None
        elif isinstance(place_cache, PlaceCache):
            cache = place_cache
        elif isinstance(place_cache, (str, os.PathLike)):
            cache = PlaceCache(place_cache)
        else:
            raise ValueError(
                "place_cache must be True, False, None, a folder or a PlaceCache, "
                f"got {place_cache!r}"
            )
        self.learn_config = LearningConfig(
            spot_distance_m=float(spot_distance_m),
            learn_time_s=float(learn_time_s),
            compass=compass if compass is not None else CompassConfig(),
            normalise_at=normalise_at,
            around_m=nonnegative_float("around_m", around_m),
            landmarks=bool(landmarks),
        )
        self.room = AiboRoomEnv(render_mode=render_mode, **room_kwargs)
        self.render_mode = render_mode
        self.learning = learning
        self.relearn = relearn
        self.learner = learner if learner is not None else ScriptedLearning()
        self.learning_seed = learning_seed
        self.atlas_file = atlas_file
        self.stop_time_s = float(stop_time_s)
        self.success_radius_m = float(success_radius_m)
        self.max_homing_s = float(max_homing_s)
        self.max_learning_s = float(max_learning_s)
        #: Steps of homing, and of the agent's learning, after which the phase ends.
        self.homing_steps = time_limit_steps(self.max_homing_s, self.room.control_dt)
        self.learning_steps = time_limit_steps(self.max_learning_s, self.room.control_dt)
        self.kidnap_margin_m = float(kidnap_margin_m)
        self.still_threshold = float(still_threshold)
        self.progress_reward = float(progress_reward)
        self.success_bonus = float(success_bonus)
        self.closeness_bonus = float(closeness_bonus)
        self.fall_penalty = float(fall_penalty)
        #: The learner that runs the learning phase when neither the atlas file nor the
        #: place cache has the place.
        self.place_learner = self.learner
        if atlas_file is not None:
            spec = {
                "scene": self.room.scene_name,
                "learner": repr(self.learner),
                "learning": self.learn_config.to_key(),
                "learning_seed": learning_seed,
                "room": {k: repr(v) for k, v in sorted(room_kwargs.items())},
            }
            self.learner = AtlasFile(atlas_file, self.learner, spec)
        #: The place cache the scripted learning phase uses (``None``: off); with an
        #: ``atlas_file``, a missing file is filled from it.
        self.place_cache = (
            cache
            if cache is not None
            and learning == "scripted"
            and type(self.place_learner) is ScriptedLearning
            else None
        )
        #: The place cache's learner of the last learning phase (``learned``: whether it
        #: learned the place or loaded it), ``None`` if that phase was not cached.
        self.cached_learner: CachedLearner | None = None
        self._room_kwargs = dict(room_kwargs)
        self._seeded = learning_seed is not None
        self.max_spots = (
            scripted_atlas_size(self.learn_config) if learning == "scripted" else int(max_spots)
        )
        self.spot_radius_m = float(spot_radius_m)
        self.control_dt = self.room.control_dt
        self.camera = self.room.camera

        n_act = 5 if learning == "scripted" else 7
        self.action_space = spaces.Box(-1.0, 1.0, (n_act,), np.float32)
        self.observation_space = spaces.Dict(
            {**self.room.observation_space.spaces, "phase": spaces.Box(0.0, 1.0, (1,), np.float32)}
        )
        #: The task's own spaces (an env built on the task, such as ``vc_gym/Homing-v0``,
        #: shows others as ``observation_space`` and ``action_space``).
        self.task_observation_space = self.observation_space
        self.task_action_space = self.action_space

        self.home = HOME  # where the robot must return (the world origin)
        self.atlas: CompassAtlas | None = None
        self.learning_result: LearningResult | None = None
        self._atlas_key: tuple | None = None
        self._phase: str | None = None
        self._frames: list[_Frame] = []
        self._belief = np.zeros(3)  # dead-reckoned pose while the agent learns
        self._phase_steps = 0
        self._still_steps = 0
        self._distance = 0.0
        self._pending_options: dict[str, Any] = {}

    # ------------------------------------------------------------------ helpers
    @property
    def phase(self) -> str | None:
        """``"learning"``, ``"homing"`` or ``None`` before the first reset / after the end."""
        return self._phase

    @property
    def max_episode_steps(self) -> int:
        """The most steps an episode can take: :attr:`homing_steps`, plus
        :attr:`learning_steps` with ``learning="agent"``. At the default settings this is
        the registered ``max_episode_steps``."""
        if self.learning == "agent":
            return self.learning_steps + self.homing_steps
        return self.homing_steps

    @property
    def spec(self):
        """The ``EnvSpec`` that ``gym.make`` gives the env (``None`` if built directly)."""
        return self.__dict__.get("_spec")

    @spec.setter
    def spec(self, value) -> None:
        self.__dict__["_spec"] = value
        registered = ENV_SPECS.get(getattr(value, "id", None), (None, None))[1]
        if registered is not None and self.max_episode_steps > registered:
            warnings.warn(
                f"{value.id} registers max_episode_steps={registered}, but this env's "
                f"episodes can last {self.max_episode_steps} steps: unless you passed "
                f"max_episode_steps={self.max_episode_steps} (or -1) to gym.make, its "
                "TimeLimit ends them early",
                EpisodeLimitWarning,
                stacklevel=3,
            )

    def _cached_learner(self, learn_seed: int) -> CachedLearner | None:
        """The place cache's learner of this learning phase, or ``None`` when the place
        cannot be cached (no cache, another learner, an unknown learning seed, or room
        settings with no description that is the same in every run)."""
        if self.place_cache is None or not self._seeded:
            return None
        room = inspect.signature(AiboRoomEnv).bind(**self._room_kwargs)
        room.apply_defaults()  # the same key whether a default is passed or left out
        room = {k: v for k, v in room.arguments.items() if k != "render_mode"}
        try:
            key = {
                "scene": self.room.scene_name,
                "learner": repr(self.place_learner),
                "learning": self.learn_config.to_key(),
                "learning_seed": int(learn_seed),
                "room": place_key_value(room),
            }
            return self.place_cache.learner(self.place_learner, key)
        except TypeError:
            return None

    def _home_distance(self, info: dict[str, Any]) -> float:
        x, y = info["pose"][:2]
        return math.hypot(x - HOME[0], y - HOME[1])

    def _obs(self, obs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        phase = 1.0 if self._phase == "homing" else 0.0
        return {**obs, "phase": np.array([phase], np.float32)}

    def _info(self, info: dict[str, Any]) -> dict[str, Any]:
        return {
            **info,
            "phase": self._phase,
            "home_error_m": self._home_distance(info),
            "still_time_s": self._still_steps * self.control_dt,
        }

    def is_still(self, action: np.ndarray) -> bool:
        """Whether ``action`` commands no body motion (``|forward|``, ``|sideways|``,
        ``|turn|`` all ≤ ``still_threshold``; the head may move): the stop rule counts
        such steps."""
        return bool(np.all(np.abs(np.asarray(action)[:3]) <= self.still_threshold))

    def velocity_action(self, **velocities: float) -> np.ndarray:
        """The room's :meth:`~vc_gym.sim.AiboRoomEnv.velocity_action` (``Box(5)``)."""
        return self.room.velocity_action(**velocities)

    def _kidnap(self, options: dict[str, Any], seed: int | None = None) -> tuple[dict, dict]:
        if "pose" in options:
            pose = options["pose"]
        else:
            pose = kidnap_pose(self.np_random, self.room.scene.field_bounds, self.kidnap_margin_m)
        obs, info = self.room.reset(seed=seed, options={"pose": pose})
        self._phase = "homing"
        self._phase_steps = 0
        self._still_steps = 0
        self._distance = self._home_distance(info)
        return obs, info

    def _check_fits_scene(self) -> None:
        """Refuse settings the scene cannot hold, before any learning is done."""
        fx0, fx1, fy0, fy1 = self.room.scene.field_bounds
        m, side = self.kidnap_margin_m, min(fx1 - fx0, fy1 - fy0)
        if 2 * m >= side:
            raise ValueError(
                f"kidnap_margin_m={m} leaves no room on the {fx1 - fx0:g} x {fy1 - fy0:g} m "
                f"field of {self.room.scene_name!r} (it must be < {side / 2:g})"
            )
        if self.learning == "scripted":
            d = self.learn_config.spot_distance_m
            if not all(self.room.inside_walls(x, y) for x, y in paper_spots(d).values()):
                raise ValueError(
                    f"spot_distance_m={d} puts the learning spots outside the walls of "
                    f"{self.room.scene_name!r} ({self.room.walls_text()})"
                )

    # ------------------------------------------------------------------ gym API
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        self.room._check_open()
        options = check_reset_options(options, RESET_OPTIONS)
        if seed is not None:
            self._seeded = True
        elif self._np_random is None:  # seeded from the OS: the learning seed is unknown
            self._seeded = self.learning_seed is not None
        super().reset(seed=seed)
        room_seed = int(self.np_random.integers(2**31))
        self._still_steps = 0
        self._phase_steps = 0
        if (
            self.learning == "scripted"
            and self.atlas is not None
            and self.relearn == "scene"
            and not self.room.randomize  # a randomised scene may change with the seed
        ):  # the place is known: straight to the kidnapping
            obs, info = self._kidnap(options, seed=room_seed)
            return self._obs(obs), self._info(info)
        learn_seed = room_seed if self.learning_seed is None else self.learning_seed
        obs, info = self.room.reset(seed=learn_seed, options={"pose": (*HOME, 0.0)})
        self._check_fits_scene()
        if self.learning == "agent":
            self.atlas = self.learning_result = None
            self._frames = []
            self._belief = np.zeros(3)
            self._phase = "learning"
            self._pending_options = options
            return self._obs(obs), self._info(info)
        key = self.room.scene_key
        if self.atlas is None or self.relearn == "episode" or key != self._atlas_key:
            self.atlas = self.learning_result = None
            self.cached_learner = self._cached_learner(learn_seed)
            try:
                if isinstance(self.learner, AtlasFile):  # a missing file comes from the cache
                    result = self.learner(self.room, self.learn_config, self.cached_learner)
                else:
                    result = (self.cached_learner or self.learner)(self.room, self.learn_config)
            except RobotFell as exc:
                raise RuntimeError(
                    "the robot fell during the scripted learning phase; use "
                    "locomotion='constraint' (the default) for this task"
                ) from exc
            if not isinstance(result, LearningResult):
                raise TypeError(
                    f"the learner must return a LearningResult, got {type(result).__name__}"
                )
            self.learning_result, self.atlas = result, result.atlas
            self._atlas_key = key
        # with a shared atlas file the room is reseeded, so that whether this env learned
        # or loaded the atlas does not change its episodes
        obs, info = self._kidnap(options, seed=room_seed if self.atlas_file else None)
        return self._obs(obs), self._info(info)

    def step(
        self, action: np.ndarray
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        if self._phase is None:
            self.room._check_open()
            raise RuntimeError("call reset() before step() (the episode has ended or not begun)")
        a = np.clip(check_action(action, self.task_action_space.shape), -1.0, 1.0)
        if self._phase == "learning":
            return self._learning_step(a)
        obs, _, fell, _, info = self.room.step(a[:5])
        self._phase_steps += 1
        d = self._home_distance(info)
        reward = self.progress_reward * (self._distance - d)
        self._distance = d
        self._still_steps = self._still_steps + 1 if self.is_still(a) else 0
        stopped = self._still_steps * self.control_dt >= self.stop_time_s - 1e-9
        terminated = fell or stopped
        truncated = not terminated and self._phase_steps >= self.homing_steps
        info = self._info(info)
        if fell:
            reward -= self.fall_penalty
        if terminated or truncated:
            success = stopped and not fell and d <= self.success_radius_m
            if success:
                reward += self.success_bonus + self.closeness_bonus * (
                    1.0 - d / self.success_radius_m
                )
            info.update(
                stop_position=np.asarray(info["pose"][:2], np.float64),
                stop_error_m=d,
                stopped=stopped and not fell,
                success=success,
                is_success=success,
            )
            self._phase = None
        return self._obs(obs), float(reward), terminated, truncated, info

    def _learning_step(self, a: np.ndarray):
        obs, _, fell, _, info = self.room.step(a[:5])
        self._phase_steps += 1
        odometry = tuple(float(v) for v in obs["odometry"])
        self._belief = np.array(compose(tuple(self._belief), odometry))
        if a[5] > 0:
            pan = float(obs["head"][0])
            self._frames.append(
                _Frame(obs["image"], self._belief[0], self._belief[1], self._belief[2] + pan)
            )
        if fell:
            self._phase = None
            info = self._info(info)
            info.update(stopped=False, success=False, is_success=False)
            return self._obs(obs), -self.fall_penalty, True, False, info
        if a[6] > 0 or self._phase_steps >= self.learning_steps:
            self.atlas = self._atlas_from_frames()
            self.learning_result = None
            if self.atlas is not None:
                spots = dict(zip(self.atlas.names, map(tuple, self.atlas.positions), strict=True))
                self.learning_result = LearningResult(self.atlas, spots)
            if self.atlas is None:
                self._phase = None
                info = self._info(info)
                info.update(stopped=False, success=False, is_success=False, learned=False)
                return self._obs(obs), -self.fall_penalty, True, False, info
            obs, info = self._kidnap(self._pending_options)
        return self._obs(obs), 0.0, False, False, self._info(info)

    def _atlas_from_frames(self) -> CompassAtlas | None:
        """Spots from the frames the agent marked: frames closer than ``spot_radius_m``
        (by odometry) to a spot's first frame join it; at most ``max_spots`` spots."""
        frames = self._frames
        if not frames:
            return None
        cfg = self.learn_config.compass
        pick = np.linspace(0, len(frames) - 1, min(len(frames), 24)).round().astype(int)
        colors = VisualCompass(cfg).fit_colors([frames[i].image for i in pick]).colors
        anchors: list[tuple[float, float]] = []
        members: list[list[_Frame]] = []
        for f in frames:
            d = [math.hypot(f.x - ax, f.y - ay) for ax, ay in anchors]
            if d and (min(d) <= self.spot_radius_m or len(anchors) >= self.max_spots):
                members[int(np.argmin(d))].append(f)
            else:
                anchors.append((f.x, f.y))
                members.append([f])
        camera = Camera(hfov_deg=self.camera.hfov_deg)
        spots = {}
        for i, group in enumerate(members):
            vc = VisualCompass(cfg, colors)
            for f in group:
                vc.learn(f.image, camera.replace(yaw_deg=f.camera_yaw_deg))
            xy = (float(np.mean([f.x for f in group])), float(np.mean([f.y for f in group])))
            spots[f"spot{i}"] = (xy, vc)
        atlas = CompassAtlas(spots, home="home", home_position=HOME)
        at_home = [f for f in frames if math.hypot(f.x, f.y) <= self.spot_radius_m]
        if not at_home:  # normalise with the frames of the spot closest to home
            nearest = int(np.argmin([math.hypot(*xy) for xy, _ in spots.values()]))
            at_home = members[nearest]
        atlas.normalize([f.image for f in at_home], camera)
        return atlas

    def render(self) -> np.ndarray | None:
        """The room's ``rgb_array`` view: top view with the robot and its camera frame."""
        return self.room.render()

    def close(self) -> None:
        self.room.close()
        self._phase = None
