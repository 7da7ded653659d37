"""The tracker's error where the expert stops: an optional goal for a learned agent.

In the paper's procedure the spots are normalised where the robot believes home is after
walking back by odometry, a few centimetres off the true home, so the tracker's home lies
off the true one, by about the same amount on every learning seed. An agent that stops
where the tracker says home inherits it. A learned agent can do better because training,
unlike homing, knows the true pose: before the warm start, :func:`measure_home_offset`
lets the scripted expert home a few times in each of several places and takes, per axis,
the median of ``estimate − true position`` where it stands at the end. ``vc-gym train
--home-offset-episodes N`` then trains and evaluates on
``vc_gym/Homing-v0(home_offset_m=that)``: the policy's home vector points to where the
estimate read at the expert's stops would put the true home. Part of the offset belongs
to the place, so the measurement pools several places.

It is not the estimate read at the true home itself: the agent decides to stop on its
walking estimate, which is noisy, and the estimate after a stand there differs again.
What matters is where the stops end up, and going to the corrected goal the stops can
move further than the goal did. :func:`centre_home_offset` (``vc-gym train
--home-offset-centre``) then lets the expert home again on the same kidnappings, going
to the measured goal, and moves the goal so that its median stop lies at the true home
(a secant step per axis).

``vc-gym train`` measures and centres the goal by default
(:class:`~vc_gym.training.config.TrainConfig`: ``home_offset_episodes=10``,
``home_offset_centre=True``); ``--home-offset-episodes 0 --no-home-offset-centre`` trains
towards the tracker's home.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

from vc_gym.envs.homing import MAX_HOME_OFFSET_M, PreviousAction, home_offset
from vc_gym.envs.learning import HOME
from vc_gym.training.feature_expert import HomingFeatureExpert

__all__ = ["HomeOffset", "centre_home_offset", "measure_home_offset"]

#: Fewest expert stops a measured offset may rest on.
MIN_STOPS = 5
#: Bounds of how far the expert's median stop moves per metre of goal
#: (:func:`centre_home_offset`).
MIN_SLOPE, MAX_SLOPE = 0.5, 3.0


@dataclass(frozen=True)
class HomeOffset:
    """A measured goal correction.

    Attributes
    ----------
    offset_m : (float, float)
        Median ``estimate − true position`` at the expert's stops (world frame, m, to
        0.1 mm): the ``home_offset_m`` of ``vc_gym/Homing-v0``.
    episodes : int
        Expert episodes run (over all places).
    stops : int
        Of those, how many ended by a stop (the others timed out or fell).
    spread_m : (float, float)
        Per axis, the median absolute deviation of ``estimate − true`` over the stops.
    success_rate : float
        Share of the episodes that stopped within the success radius (of the expert
        going to the tracker's home, before the correction).
    per_place_m : tuple of (float, float)
        The median of each place's own stops (``nan`` for a place without stops).
    median_stop_m : (float, float)
        The median true position of the expert's stops, from home (m); after
        :func:`centre_home_offset`, of its stops going to ``first_offset_m``.
    first_offset_m : (float, float) or None
        With :func:`centre_home_offset`: the goal before the correction (``None``
        without).
    slope : (float, float) or None
        With :func:`centre_home_offset`: per axis, how far the median stop moved per
        metre of goal.
    centred_success_rate : float or None
        With :func:`centre_home_offset`: the expert's success going to
        ``first_offset_m``.
    """

    offset_m: tuple[float, float]
    episodes: int
    stops: int
    spread_m: tuple[float, float]
    success_rate: float
    per_place_m: tuple[tuple[float, float], ...]
    median_stop_m: tuple[float, float] = (float("nan"), float("nan"))
    first_offset_m: tuple[float, float] | None = None
    slope: tuple[float, float] | None = None
    centred_success_rate: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready figures (metres rounded to a tenth of a millimetre)."""

        def metres(v):
            return [None if np.isnan(x) else round(float(x), 4) for x in v]

        return {
            "home_offset_m": metres(self.offset_m),
            "episodes": self.episodes,
            "stops": self.stops,
            "spread_m": metres(self.spread_m),
            "success_rate": round(self.success_rate, 4),
            "per_place_m": [metres(v) for v in self.per_place_m],
            "median_stop_m": metres(self.median_stop_m),
            "first_offset_m": None if self.first_offset_m is None else metres(self.first_offset_m),
            "slope": None if self.slope is None else [round(v, 3) for v in self.slope],
            "centred_success_rate": None
            if self.centred_success_rate is None
            else round(self.centred_success_rate, 4),
        }


def _homing_attr(env: gym.Env, name: str) -> Any:
    """``name`` of one of the env's wrappers (refusing an env that is not Homing-v0)."""
    try:
        return env.get_wrapper_attr(name)
    except AttributeError:
        raise ValueError(f"measure_home_offset needs a vc_gym/Homing-v0 env (no {name})") from None


def measure_home_offset(
    envs: gym.Env | Sequence[gym.Env],
    episodes: int,
    seed: int,
    expert: Any = None,
    progress: bool = False,
) -> HomeOffset:
    """Let ``expert`` home ``episodes`` times in each env and measure its tracker's home.

    For each episode that ends by a stop, ``info["estimate"]["position"]`` (the
    tracker's position at the end of the stand) minus ``info["stop_position"]`` (the
    true one) is one sample; the offset is the per-axis median over the samples of
    every place, robust to the odd stop far away where one view looks like home.

    Parameters
    ----------
    envs : gymnasium.Env or sequence of them
        ``vc_gym/Homing-v0`` of each place, going to the atlas' home
        (``home_offset_m=(0, 0)``).
    episodes : int
        Kidnappings per place, >= 1; all places together must give at least
        :data:`MIN_STOPS` stops.
    seed : int
        Seed of the first reset in the first place (place ``j`` starts from
        ``seed + j``; later resets continue its generator).
    expert : object with ``predict(features) -> action``, optional
        Default: :class:`~vc_gym.agents.HomingFeatureExpert` (the scripted rule) at the
        env's walking speed and turn rate.
    progress : bool
        Show a progress bar.

    Raises
    ------
    ValueError
        For an env that is not ``Homing-v0`` or already corrected, too few episodes, or
        fewer than :data:`MIN_STOPS` stops, or an offset beyond
        :data:`~vc_gym.envs.homing.MAX_HOME_OFFSET_M` (the tracker is lost, not off).
    """
    envs = _checked_envs(envs, episodes, "measure_home_offset")
    if expert is None:
        expert = _default_expert(envs[0])
    with tqdm(
        total=episodes * len(envs), desc="home offset", unit="ep", disable=not progress
    ) as bar:
        per_place, stops, successes = _homing_round(envs, episodes, seed, expert, bar)
    samples = [e for place in per_place for e in place]
    total = episodes * len(envs)
    if len(samples) < MIN_STOPS:
        raise ValueError(
            f"the expert stopped in only {len(samples)} of {total} episodes; the home "
            f"offset needs at least {MIN_STOPS} stops"
        )
    errors = np.asarray(samples, np.float64)
    median = np.median(errors, axis=0)
    if np.hypot(*median) > MAX_HOME_OFFSET_M:
        raise ValueError(
            f"the tracker's home lies {np.hypot(*median):.2f} m from the true home at the "
            f"expert's stops (more than {MAX_HOME_OFFSET_M} m): it is lost, not offset"
        )
    spread = np.median(np.abs(errors - median), axis=0)
    places = tuple(
        tuple(float(v) for v in np.median(p, axis=0)) if p else (float("nan"),) * 2
        for p in per_place
    )
    return HomeOffset(
        offset_m=home_offset(tuple(round(float(v), 4) for v in median)),  # 0.1 mm
        episodes=total,
        stops=len(samples),
        spread_m=(float(spread[0]), float(spread[1])),
        success_rate=successes / total,
        per_place_m=places,  # type: ignore[arg-type]
        median_stop_m=tuple(float(v) for v in np.median(stops, axis=0)),  # type: ignore[arg-type]
    )


def _checked_envs(envs: gym.Env | Sequence[gym.Env], episodes: int, caller: str) -> list[gym.Env]:
    """``envs`` as a list, refused unless each is a Homing-v0 going to the atlas' home
    and ``episodes`` is an int >= 1."""
    envs = [envs] if isinstance(envs, gym.Env) else list(envs)
    if not envs:
        raise ValueError(f"{caller} needs at least one env")
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an int >= 1, got {episodes!r}")
    for env in envs:
        if _homing_attr(env, "home_offset_m") != (0.0, 0.0):
            raise ValueError("measure the offset on envs whose home_offset_m is (0, 0)")
    return envs


def _default_expert(env: gym.Env) -> HomingFeatureExpert:
    """The scripted rule at the env's walking speed and turn rate (reading its last
    action when the env's features hold it)."""
    return HomingFeatureExpert(
        _homing_attr(env, "max_forward"),
        _homing_attr(env, "max_turn_deg_s"),
        previous_action=_has_wrapper(env, PreviousAction),
    )


def _has_wrapper(env: gym.Env, kind: type) -> bool:
    """Whether ``env`` applies ``kind``: as one of its wrappers, or inside its unwrapped
    env (``vc_gym/Homing-v0`` applies its wrappers itself)."""
    while isinstance(env, gym.Wrapper):
        if isinstance(env, kind):
            return True
        env = env.env
    inner = getattr(env, "previous_action_wrapper", None) if kind is PreviousAction else None
    return isinstance(inner, kind)


def _homing_round(
    envs: list[gym.Env], episodes: int, seed: int, expert: Any, bar: tqdm
) -> tuple[list[list[np.ndarray]], list[np.ndarray], int]:
    """``episodes`` kidnappings in each env: per place the ``estimate − true`` of each
    stop, the true positions of all stops, and how many episodes succeeded."""
    per_place: list[list[np.ndarray]] = [[] for _ in envs]
    stops: list[np.ndarray] = []
    successes = 0
    for j, env in enumerate(envs):
        for k in range(episodes):
            obs, _ = env.reset(seed=int(seed) + j if k == 0 else None)
            done = False
            while not done:
                obs, _, terminated, truncated, info = env.step(expert.predict(obs))
                done = terminated or truncated
            successes += bool(info.get("success", False))
            estimate = info.get("estimate")
            if info.get("stopped") and estimate is not None:
                per_place[j].append(np.subtract(estimate["position"], info["stop_position"]))
                stops.append(np.asarray(info["stop_position"], np.float64) - HOME)
            bar.update(1)
    return per_place, stops, successes


def centre_home_offset(
    envs: gym.Env | Sequence[gym.Env],
    first: HomeOffset,
    episodes: int,
    seed: int,
    expert: Any = None,
    progress: bool = False,
) -> HomeOffset:
    """Correct a measured goal so that the expert's stops centre on the true home.

    ``first`` (:func:`measure_home_offset`) moves the goal by the error read where the
    expert stopped, but going there the stops can move further than the goal (1.2–1.5
    times in training seed 1's places, once in seed 0's: the expert stops where its
    noisy walking estimate first comes within its tolerance, and the estimate does not
    move one for one with the robot everywhere). So the expert homes again on the same
    kidnappings, going to ``first``'s goal, and per axis the goal at which the median
    stop would lie at home is found on the line through the two rounds (a secant step,
    the slope clipped to [:data:`MIN_SLOPE`, :data:`MAX_SLOPE`]).

    Parameters
    ----------
    envs, episodes, seed, expert, progress
        As given to :func:`measure_home_offset` for ``first`` (the envs' goal is set to
        ``first.offset_m`` for the round and back to ``(0, 0)`` after it).
    first : HomeOffset
        The measurement to correct (of :func:`measure_home_offset`).

    Raises
    ------
    ValueError
        For a ``first`` that is already centred, the env and episode errors of
        :func:`measure_home_offset`, fewer than :data:`MIN_STOPS` stops going to its
        goal, or a corrected goal beyond
        :data:`~vc_gym.envs.homing.MAX_HOME_OFFSET_M`.
    """
    if first.first_offset_m is not None:
        raise ValueError("this goal is already centred (centre_home_offset was applied)")
    envs = _checked_envs(envs, episodes, "centre_home_offset")
    if expert is None:
        expert = _default_expert(envs[0])
    goal = np.asarray(first.offset_m, np.float64)
    try:
        for env in envs:
            env.set_wrapper_attr("home_offset_m", home_offset(first.offset_m))
        with tqdm(
            total=episodes * len(envs), desc="home offset, 2nd", unit="ep", disable=not progress
        ) as bar:
            _, stops, successes = _homing_round(envs, episodes, seed, expert, bar)
    finally:
        for env in envs:
            env.set_wrapper_attr("home_offset_m", (0.0, 0.0))
    if len(stops) < MIN_STOPS:
        raise ValueError(
            f"going to the measured goal the expert stopped in only {len(stops)} of "
            f"{episodes * len(envs)} episodes; the correction needs at least {MIN_STOPS}"
        )
    before = np.asarray(first.median_stop_m, np.float64)
    after = np.median(np.asarray(stops, np.float64), axis=0)
    # how far the median stop moved per metre of goal, per axis (1 where the goal is ~0)
    moved = np.where(np.abs(goal) > 0.01, (after - before) / np.where(goal == 0, 1, goal), 1.0)
    slope = np.clip(moved, MIN_SLOPE, MAX_SLOPE)
    centred = goal - after / slope
    return replace(
        first,
        offset_m=home_offset(tuple(round(float(v), 4) for v in centred)),
        episodes=first.episodes + episodes * len(envs),
        median_stop_m=tuple(float(v) for v in after),  # type: ignore[arg-type]
        first_offset_m=first.offset_m,
        slope=tuple(float(v) for v in slope),  # type: ignore[arg-type]
        centred_success_rate=successes / (episodes * len(envs)),
    )
