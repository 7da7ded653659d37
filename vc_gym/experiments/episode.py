"""One episode of the homing task, recorded: the single path every experiment runs.

:func:`make_homing_run` builds the task env (``vc_gym/LearnThenHome-v0`` with the
compass and a tracker, or the env a learned agent was trained on) and its policy;
:func:`run_episode` runs one kidnapping with it and returns an :class:`EpisodeRecord`
(true and estimated trajectory, heading error, where and how it ended). The demo,
``vc-gym evaluate`` and the experiments all go through these two functions, so the
same seed gives the same episode everywhere. An optional ``on_step`` hook sees every
step as an :class:`EpisodeStep` (the episode video, :mod:`vc_gym.experiments.video`,
is one) without changing what is recorded.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

from vc_gym.agents.learned import LearnedHomingAgent
from vc_gym.agents.scripted import ScriptedHomingAgent
from vc_gym.angles import wrap180
from vc_gym.envs.homing import LEARNED_CONFIRM_STOP_M
from vc_gym.envs.homing_modes import (
    DEFAULT_HOMING_MODE,
    HOMING_MODES,
    LEARNED_AGENT_MODE,
    HomingMode,
    canonical_homing_mode,
    homing_mode,
    mode_of_task,
)
from vc_gym.envs.learn_then_home import make_task
from vc_gym.envs.wrappers.compass_observation import CompassObservation
from vc_gym.localization import TrackerSpec

__all__ = [
    "DEFAULT_HOMING_MODE",
    "HOMING_MODES",
    "LEARNED_AGENT_MODE",
    "canonical_homing_mode",
    "default_homing_mode",
    "default_tracker",
    "LEARNED_CONFIRM_STOP_M",
    "EpisodeRecord",
    "HomingMode",
    "EpisodeStep",
    "HomingRun",
    "check_agent_env",
    "load_agent",
    "make_agent_env",
    "make_homing_run",
    "homing_mode",
    "mode_of_task",
    "run_episode",
]


@dataclass
class EpisodeRecord:
    """What happened in one homing episode (world frame, metres and degrees).

    ``true`` and ``estimated`` hold one ``(x, y, heading)`` per decision of the agent
    (a step of the scripted agent; a learned agent's stop decision, which holds the
    robot still until the episode ends, is one entry); ``estimated`` is the tracker's
    belief (``NaN`` where it had none) and ``heading_error`` the wrapped difference
    estimated minus true heading.
    """

    seed: int | None
    start_pose: tuple[float, float, float]
    home: tuple[float, float]
    true: list[tuple[float, float, float]] = field(default_factory=list)
    estimated: list[tuple[float, float, float]] = field(default_factory=list)
    heading_error: list[float] = field(default_factory=list)
    stop_position: tuple[float, float] | None = None
    stop_error_m: float = math.nan
    stopped: bool = False
    success: bool = False
    fell: bool = False
    timed_out: bool = False
    decisions: int = 0
    sim_time_s: float = 0.0
    total_return: float = 0.0
    #: time per step (the env's control period), seconds
    dt_s: float = 0.1
    #: wall time in the tracker's updates and their count (not part of :meth:`summary`)
    tracker_time_s: float = 0.0
    tracker_updates: int = 0

    def summary(self) -> dict[str, Any]:
        """The episode's figures as plain JSON-ready values (no timings)."""
        stop = self.stop_position if self.stop_position is not None else (math.nan, math.nan)
        err = np.abs(np.asarray(self.heading_error, np.float64))
        return {
            "seed": self.seed,
            "start_pose": [float(v) for v in self.start_pose],
            "stop_offset_m": [float(stop[0] - self.home[0]), float(stop[1] - self.home[1])],
            "home_error_m": float(self.stop_error_m),
            "stopped": bool(self.stopped),
            "success": bool(self.success),
            "fell": bool(self.fell),
            "timed_out": bool(self.timed_out),
            "decisions": int(self.decisions),
            "sim_time_s": float(self.sim_time_s),
            "return": float(self.total_return),
            "final_heading_error_deg": float(err[-1]) if err.size else None,
            "mean_heading_error_deg": float(err.mean()) if err.size else None,
        }


@dataclass(frozen=True)
class EpisodeStep:
    """One decision of an episode, as :func:`run_episode` hands it to ``on_step``.

    Attributes
    ----------
    index : int
        Decision number, from 0.
    sim_time_s : float
        Homing time after this step (``info["sim_time"]``), seconds.
    observation : Any
        What the policy will see next (a dict for the scripted agent's env, holding
        ``"image"`` when the run was made with ``keep_image=True``; a feature vector for a
        learned agent's env).
    info : dict
        The step's ``info`` (``pose``, ``head``, ``home_error_m``, ...; at the end also
        ``stop_position``, ``stopped``, ``success``).
    true_pose : tuple of float
        True ``(x, y, heading_deg)``; for evaluation and display only.
    estimate : dict or None
        The tracker's belief (``info["estimate"]``: ``heading_deg``,
        ``heading_spread_deg``, ``position``, ``position_std_m``), ``None`` without one.
    """

    index: int
    sim_time_s: float
    observation: Any
    info: dict[str, Any]
    true_pose: tuple[float, float, float]
    estimate: dict[str, Any] | None

    @property
    def image(self) -> np.ndarray | None:
        """The head-camera frame if the observation carries one, else ``None``."""
        obs = self.observation
        return obs.get("image") if isinstance(obs, dict) else None


@dataclass
class HomingRun:
    """A task env and the policy that acts in it.

    Attributes
    ----------
    env : gymnasium.Env
        The wrapped task env (its observations are what ``act`` takes).
    act : callable
        ``act(observation) -> action``.
    reset_policy : callable or None
        Called at the start of every episode (a stateful policy's ``reset``).
    """

    env: gym.Env
    act: Callable[[Any], Any]
    reset_policy: Callable[[], None] | None = None

    def close(self) -> None:
        self.env.close()


def default_homing_mode(agent: Any) -> str:
    """The homing mode for ``agent`` when none is given: :data:`DEFAULT_HOMING_MODE` for
    ``"scripted"``; for a learned agent (a loaded one, or the path of its
    ``model.zip``), the mode its places were learned in (:func:`mode_of_task` of its env
    arguments: a policy is evaluated in places learned the way its training places were).

    Raises
    ------
    ValueError
        For a learned agent whose places were learned in no homing mode (pass ``mode``).
    """
    if isinstance(agent, str):
        if agent == "scripted":
            return DEFAULT_HOMING_MODE
        agent = load_agent(agent)
    if isinstance(agent, ScriptedHomingAgent):
        return DEFAULT_HOMING_MODE
    mode = mode_of_task(agent.env_kwargs)
    if mode is None:
        raise ValueError(
            f"{agent.path}: its env arguments learn places in none of the homing modes "
            f"{list(HOMING_MODES)}; name the mode to evaluate it in"
        )
    return mode


def default_tracker(agent: HomingAgent, mode: str) -> TrackerSpec:
    """The tracker ``agent`` homes on in homing mode ``mode`` unless told: a learned
    agent's own (the one it trained with), else the mode's (:attr:`HomingMode.tracker`)."""
    return agent.env_kwargs.get("tracker", homing_mode(mode).tracker)


def make_homing_run(
    agent: str = "scripted",
    tracker: TrackerSpec | None = None,
    scene: str = "robolab",
    learn_time_s: float = 5.0,
    success_radius_m: float = 0.3,
    relearn: str = "scene",
    max_homing_s: float = 60.0,
    learner: Callable | None = None,
    keep_image: bool = False,
    mode: str | None = None,
    policy: dict[str, Any] | None = None,
    allow_imports: bool = False,
) -> HomingRun:
    """The homing task with the paper's 5 s stop rule, and an agent to run it.

    Parameters
    ----------
    agent : str
        ``"scripted"`` (:class:`~vc_gym.agents.ScriptedHomingPolicy` on
        ``vc_gym/LearnThenHome-v0`` + :class:`~vc_gym.envs.CompassObservation`) or
        the path of a learned agent's ``model.zip`` (it runs on the env it was trained
        on, ``vc_gym/Homing-v0``, with the task's 5 s stop rule, its stops checked while
        it stands: :data:`LEARNED_CONFIRM_STOP_M`).
    tracker : str, dict or callable, optional
        The tracker (see :func:`vc_gym.localization.make_tracker`); default a learned
        agent's own (the one it trained with), else the mode's
        (:attr:`HomingMode.tracker`).
    scene, learn_time_s, success_radius_m, relearn, max_homing_s
        Task arguments (see ``LearnThenHomeEnv``).
    learner : callable, optional
        The task's learner (default: the paper's scripted learning phase).
    keep_image : bool
        Keep the head-camera frame in the scripted agent's observations (for an
        episode video; the policy ignores it, the episode is the same). A learned
        agent's env turns its observation into a feature vector and has no frame to
        keep: this argument does not change it (the video renders the frame from the
        env instead, see :class:`~vc_gym.experiments.video.EpisodeVideo`).
    mode : str
        How the place is learned and how the scripted agent homes
        (:data:`HOMING_MODES`): ``"check-home"``, ``"paper"`` or ``"pose-home"``;
        default :func:`default_homing_mode` (check-home for the scripted agent, the
        mode of its training places for a learned one). With a saved atlas
        (``learner``) only the policy part applies; the atlas brings its own learning.
    policy : dict, optional
        More keyword arguments of :class:`~vc_gym.agents.ScriptedHomingPolicy`,
        over those of the mode (scripted agent only).
    allow_imports : bool
        Let a learned agent's ``config.json`` name its tracker by import path (imports
        that module; :class:`~vc_gym.agents.learned.LearnedHomingAgent`).
    """
    loaded = load_agent(agent, allow_imports)
    mode = default_homing_mode(loaded) if mode is None else mode
    chosen = homing_mode(mode)
    tracker = default_tracker(loaded, mode) if tracker is None else tracker
    policy_kwargs = {**chosen.policy, **(policy or {})}
    task: dict[str, Any] = {
        "scene": scene,
        "relearn": relearn,
        "learn_time_s": learn_time_s,
        "stop_time_s": 5.0,  # the paper's rule, also for agents trained with a shorter one
        "success_radius_m": success_radius_m,
        "max_homing_s": max_homing_s,
        **chosen.task_learning,  # the mode's places, whatever a learned agent trained on
    }
    if learner is not None:
        task["learner"] = learner
    if isinstance(loaded, ScriptedHomingAgent):
        loaded = ScriptedHomingAgent(**policy_kwargs)
    env = make_agent_env(loaded, tracker=tracker, keep_image=keep_image, **task)
    acting = loaded.policy(env)
    return HomingRun(env, acting.predict, acting.reset)


#: What :func:`load_agent` returns: an agent that names its env and gives a policy for it.
HomingAgent = ScriptedHomingAgent | LearnedHomingAgent


def load_agent(
    agent: str, allow_imports: bool = False, policy: dict[str, Any] | None = None
) -> HomingAgent:
    """The agent named ``agent``: ``"scripted"`` or the path of a learned ``model.zip``.

    Parameters
    ----------
    agent : str
        ``"scripted"`` or a ``model.zip`` written by ``vc-gym train``.
    allow_imports : bool
        Let a learned agent's ``config.json`` name its tracker by import path.
    policy : dict, optional
        Keyword arguments of :class:`~vc_gym.agents.ScriptedHomingPolicy` (scripted only).
    """
    if agent == "scripted":
        return ScriptedHomingAgent(**(policy or {}))
    return LearnedHomingAgent(agent, allow_imports)


def make_agent_env(
    agent: HomingAgent, tracker: TrackerSpec = "grid", keep_image: bool = False, **task: Any
) -> gym.Env:
    """The env ``agent`` acts in: its ``env_id`` with its own settings, then ``task``'s.

    An agent observing ``"compass"`` sees the task through
    :class:`~vc_gym.envs.CompassObservation` with ``tracker`` (``keep_image`` keeps the
    frame, for a video); one observing ``"features"`` gets ``vc_gym/Homing-v0``, whose
    ``tracker`` is an env argument and whose stops are checked while it stands
    (:data:`LEARNED_CONFIRM_STOP_M`).
    """
    # the task ends its episodes itself, after max_homing_s (which may exceed the
    # registered horizon's 60 s): no TimeLimit
    if agent.observation == "compass":
        env = make_task(agent.env_id, **{**agent.env_kwargs, **task})
        return CompassObservation(env, keep_image=bool(keep_image), tracker=tracker)
    own = {"tracker": tracker, "confirm_stop_m": LEARNED_CONFIRM_STOP_M}
    return make_task(agent.env_id, **{**agent.env_kwargs, **own, **task})


def check_agent_env(agent: HomingAgent, source: str) -> None:
    """Build (and close) ``agent``'s env with its own settings once, so that settings the
    env refuses (an unknown key, scene or value) fail here, naming ``source``, not later
    in every worker.

    Raises
    ------
    ValueError
        Naming ``source`` and what the env said.
    """
    try:
        env = gym.make(agent.env_id, **agent.env_kwargs)
    except Exception as exc:  # noqa: BLE001 - TypeError (a key), ValueError (a value)
        cause = exc.__cause__ or exc
        raise ValueError(
            f"{source}: its env arguments are refused by {agent.env_id}: "
            f"{type(cause).__name__}: {str(cause).split(' was raised from')[0]}"
        ) from None
    env.close()


def _tracker_counters(env: gym.Env) -> tuple[float, int]:
    try:
        return float(env.get_wrapper_attr("tracker_time_s")), int(
            env.get_wrapper_attr("tracker_updates")
        )
    except AttributeError:
        return 0.0, 0


def run_episode(
    run: HomingRun,
    seed: int | None = None,
    options: dict[str, Any] | None = None,
    progress: bool = False,
    on_step: Callable[[EpisodeStep], None] | None = None,
) -> EpisodeRecord:
    """Reset the task (a kidnapping) and act until the episode ends; record everything.

    Parameters
    ----------
    run : HomingRun
        The env and policy (:func:`make_homing_run`).
    seed : int, optional
        Seed of the reset: odometry errors and kidnapping pose.
    options : dict, optional
        Reset options (``{"pose": (x, y, yaw)}`` sets the kidnapping pose).
    progress : bool
        Show a progress bar over the homing time limit.
    on_step : callable, optional
        ``on_step(EpisodeStep)`` after every step (a learned agent's stop decision is
        one step), after it is recorded; it must not step or reset the env nor modify
        the observation or info it is given. Watching does not change the episode.

    Returns
    -------
    EpisodeRecord
    """
    env = run.env
    obs, info = env.reset(seed=seed, options=options)
    if run.reset_policy is not None:
        run.reset_policy()
    u = env.unwrapped
    home = tuple(float(v) for v in getattr(u, "home", (0.0, 0.0)))
    record = EpisodeRecord(seed=seed, start_pose=tuple(float(v) for v in info["pose"]), home=home)
    t0, n0 = _tracker_counters(env)
    dt = record.dt_s = float(u.control_dt)
    limit = int(round(getattr(u, "max_homing_s", 60.0) / dt))
    with tqdm(total=limit, desc="homing", unit="step", disable=not progress) as bar:
        while True:
            obs, reward, terminated, truncated, info = env.step(run.act(obs))
            record.decisions += 1
            record.total_return += float(reward)
            true = tuple(float(v) for v in info["pose"])
            est = info.get("estimate")
            record.true.append(true)
            if est is None:
                record.estimated.append((math.nan, math.nan, math.nan))
            else:
                h = float(est["heading_deg"])
                record.estimated.append((*est["position"], h))
                record.heading_error.append(float(wrap180(h - true[2])))
            if on_step is not None:
                on_step(
                    EpisodeStep(
                        index=record.decisions - 1,
                        sim_time_s=float(info.get("sim_time", 0.0)),
                        observation=obs,
                        info=info,
                        true_pose=true,
                        estimate=est,
                    )
                )
            bar.update(min(limit, int(round(float(info.get("sim_time", 0.0)) / dt))) - bar.n)
            if terminated or truncated:
                break
    t1, n1 = _tracker_counters(env)
    record.tracker_time_s, record.tracker_updates = t1 - t0, n1 - n0
    stop = info.get("stop_position", info["pose"][:2])
    record.stop_position = (float(stop[0]), float(stop[1]))
    record.stop_error_m = float(
        info.get("stop_error_m", math.hypot(stop[0] - home[0], stop[1] - home[1]))
    )
    record.stopped = bool(info.get("stopped", False))
    record.success = bool(info.get("success", False))
    record.fell = bool(info.get("fallen", False))
    record.timed_out = bool(truncated)
    record.sim_time_s = float(info.get("sim_time", 0.0))
    return record
