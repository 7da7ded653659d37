"""Every env refuses an action that is not a finite real array of its action space's
shape, reset options that are not a dict, and a time argument beyond its bound, with a
ValueError naming what it takes."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.envs import PlacePool
from vc_gym.envs.homing import PreviousAction, StopAction
from vc_gym.envs.learn_then_home import make_task
from vc_gym.envs.learning import LearningConfig, LearningResult
from vc_gym.sim.head_camera import HeadCameraSpec
from vc_gym.validation import (
    MAX_HALF_LIFE_S,
    MAX_HOMING_S,
    MAX_LEARN_TIME_S,
    MAX_LEARNING_PHASE_S,
    check_action,
    check_reset_options,
)

SMALL = HeadCameraSpec(52, 40, 56.9)


def bad_actions(n: int) -> dict[str, object]:
    """Actions of every kind an env must refuse (``n``: its action length)."""
    return {
        "dict": {"a": 1},
        "complex": np.ones(n, complex),
        "string": "forward",
        "strings": np.array(["0"] * n),
        "object array": np.zeros(n, object),
        "bools": np.zeros(n, bool),
        "ragged": [0.0, [0.0, 0.0]],
        "None": None,
        "too short": np.zeros(n - 1, np.float32),
        "2-D": np.zeros((1, n), np.float32),
        "NaN": np.full(n, np.nan, np.float32),
        "infinite": np.full(n, np.inf),
    }


BAD_OPTIONS = [[1], "pose", (("pose", (0.0, 0.0, 0.0)),), 3]


@pytest.mark.parametrize("name", list(bad_actions(5)))
def test_check_action_refuses_with_the_shape_and_dtype(name):
    with pytest.raises(ValueError, match=r"action must be (a real numeric array .*\(5,\)|finite)"):
        check_action(bad_actions(5)[name], (5,))


def test_check_action_accepts_real_numbers_as_float64():
    for action in ([1, 0, 0, 0, 0], np.zeros(5, np.float32), np.arange(5, dtype=np.int16)):
        a = check_action(action, (5,))
        assert a.dtype == np.float64 and a.shape == (5,)


@pytest.mark.parametrize("options", BAD_OPTIONS)
def test_check_reset_options_needs_a_dict(options):
    with pytest.raises(ValueError, match=r"reset options must be a dict \(or None\)"):
        check_reset_options(options, ("pose",))


# --------------------------------------------------------------------- AiboRoom-v0
@pytest.fixture(scope="module")
def room():
    env = gym.make("vc_gym/AiboRoom-v0", camera=SMALL)
    env.reset(seed=0)
    yield env
    env.close()


@pytest.mark.parametrize("name", list(bad_actions(5)))
def test_aibo_room_refuses_bad_actions(room, name):
    with pytest.raises(ValueError, match="action must be"):
        room.step(bad_actions(5)[name])
    room.step(np.zeros(5, np.float32))  # still usable


@pytest.mark.parametrize("options", BAD_OPTIONS)
def test_aibo_room_refuses_options_that_are_not_a_dict(room, options):
    with pytest.raises(ValueError, match=r"reset options must be a dict"):
        room.reset(options=options)


def test_aibo_room_refuses_unknown_options(room):
    known = r"unknown reset options \['teleport'\]; known: \['pose'\]"
    with pytest.raises(ValueError, match=known):
        room.reset(options={"teleport": True})


# ----------------------------------------------------------------- LearnThenHome-v0
class TokenLearner:
    """Answers with a token instead of learning (the rules tested need no real atlas)."""

    def __call__(self, room, config):
        return LearningResult(atlas=object(), spots={})


@pytest.fixture(scope="module")
def task():
    env = gym.make("vc_gym/LearnThenHome-v0", learner=TokenLearner(), camera=SMALL)
    env.reset(seed=0)
    yield env
    env.close()


@pytest.mark.parametrize("name", list(bad_actions(5)))
def test_learn_then_home_refuses_bad_actions(task, name):
    with pytest.raises(ValueError, match="action must be"):
        task.step(bad_actions(5)[name])


@pytest.mark.parametrize("options", BAD_OPTIONS)
def test_learn_then_home_refuses_options_that_are_not_a_dict(task, options):
    with pytest.raises(ValueError, match=r"reset options must be a dict"):
        task.reset(options=options)


def test_agent_learning_takes_seven_entries():
    env = gym.make("vc_gym/LearnThenHome-v0", learning="agent", camera=SMALL)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"of shape \(7,\)"):
        env.step(np.zeros(5, np.float32))
    with pytest.raises(ValueError, match="action must be"):
        env.step(np.ones(7, complex))
    env.close()


# ---------------------------------------------------------------------- Homing-v0
@pytest.fixture(scope="module")
def homing():
    """Homing-v0 with the previous action appended: PreviousAction over StopAction over
    the learned place (a short learning phase, small frames)."""
    env = gym.make(
        "vc_gym/Homing-v0",
        previous_action=True,
        learn_time_s=0.2,
        max_homing_s=3.0,
        camera=SMALL,
        learning_seed=0,
    )
    env.reset(seed=0)
    yield env
    env.close()


def _wrapper(env: gym.Env, cls: type) -> gym.Env:
    """The wrapper ``cls`` that Homing-v0 applies inside its env class."""
    inner = {
        PreviousAction: env.unwrapped.previous_action_wrapper,
        StopAction: env.unwrapped.stop_action,
    }[cls]
    assert isinstance(inner, cls)
    return inner


@pytest.mark.parametrize("name", list(bad_actions(3)))
@pytest.mark.parametrize("layer", [PreviousAction, StopAction])
def test_homing_refuses_bad_actions(homing, layer, name):
    env = _wrapper(homing, layer)
    with pytest.raises(ValueError, match=r"action must be (a real numeric array .*\(3,\)|finite)"):
        env.step(bad_actions(3)[name])


@pytest.mark.parametrize("options", BAD_OPTIONS)
def test_homing_refuses_options_that_are_not_a_dict(homing, options):
    with pytest.raises(ValueError, match=r"reset options must be a dict"):
        homing.reset(options=options)


# ----------------------------------------------------------------------- PlacePool
class _BoxPlace(gym.Env):
    """A place with Box actions that takes whatever it is given."""

    def __init__(self):
        self.observation_space = spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, (3,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return np.zeros(2, np.float32), {}

    def step(self, action):
        return np.zeros(2, np.float32), 0.0, False, False, {}


@pytest.mark.parametrize("options", BAD_OPTIONS)
def test_place_pool_refuses_options_that_are_not_a_dict(options):
    pool = PlacePool([_BoxPlace(), _BoxPlace()])
    with pytest.raises(ValueError, match=r"reset options must be a dict"):
        pool.reset(seed=0, options=options)


@pytest.mark.parametrize("name", list(bad_actions(3)))
def test_place_pool_refuses_bad_box_actions(name):
    pool = PlacePool([_BoxPlace(), _BoxPlace()])
    pool.reset(seed=0)
    with pytest.raises(ValueError, match="action must be"):
        pool.step(bad_actions(3)[name])
    pool.step(np.zeros(3, np.float32))


# --------------------------------------------------------------------- time limits
TASKS = ["vc_gym/LearnThenHome-v0", "vc_gym/Homing-v0"]


def _just_above(bound: float) -> float:
    return bound * (1 + 1e-9)


#: Time arguments beyond their bound, and the start of the message each gives. The
#: first two are the issue's repros: ``reset`` of the first never returned.
TOO_LONG = {
    "learn_time_s=1e12": (
        {"learn_time_s": 1e12, "max_homing_s": 5.0},
        r"learn_time_s must be in \(0, 60\] seconds, got 1000000000000\.0",
    ),
    "max_homing_s=1e12": (
        {"max_homing_s": 1e12},
        r"max_homing_s must be in \(0, 3600\] seconds, got 1000000000000\.0",
    ),
    "learn_time_s above": (
        {"learn_time_s": _just_above(MAX_LEARN_TIME_S)},
        r"learn_time_s must be in \(0, 60\] seconds",
    ),
    "max_homing_s above": (
        {"max_homing_s": _just_above(MAX_HOMING_S)},
        r"max_homing_s must be in \(0, 3600\] seconds",
    ),
    "stop_time_s above": (
        {"stop_time_s": _just_above(MAX_HOMING_S)},
        r"stop_time_s must be in \(0, 3600\] seconds",
    ),
    "max_learning_s above": (
        {"max_learning_s": _just_above(MAX_LEARNING_PHASE_S)},
        r"max_learning_s must be in \(0, 3600\] seconds",
    ),
}

#: Every time argument at its bound.
AT_BOUND = {
    "learn_time_s": MAX_LEARN_TIME_S,
    "max_homing_s": MAX_HOMING_S,
    "stop_time_s": MAX_HOMING_S,
    "max_learning_s": MAX_LEARNING_PHASE_S,
}


@pytest.mark.timeout(60)
@pytest.mark.parametrize("env_id", TASKS)
@pytest.mark.parametrize("case", list(TOO_LONG))
def test_times_beyond_their_bound_are_refused_when_the_env_is_made(env_id, case):
    kwargs, message = TOO_LONG[case]
    with pytest.raises(ValueError, match=message):
        gym.make(env_id, **kwargs)  # before any reset: no learning phase is started


@pytest.mark.timeout(60)
@pytest.mark.parametrize("value", [_just_above(MAX_HOMING_S), 1e12])
def test_homing_refuses_a_min_walk_beyond_its_bound(value):
    with pytest.raises(ValueError, match=r"min_walk_s must be in \[0, 3600\] seconds"):
        gym.make("vc_gym/Homing-v0", min_walk_s=value)


@pytest.mark.parametrize("env_id", TASKS)
def test_times_at_their_bound_are_taken(env_id):
    extra = {"min_walk_s": MAX_HOMING_S} if env_id == "vc_gym/Homing-v0" else {}
    env = make_task(env_id, place_cache=False, **AT_BOUND, **extra)
    try:
        task = env.unwrapped
        assert task.learn_config.learn_time_s == MAX_LEARN_TIME_S
        assert task.max_homing_s == task.stop_time_s == MAX_HOMING_S
        assert task.max_learning_s == MAX_LEARNING_PHASE_S
        if extra:
            assert task.stop_action.min_walk_steps == round(MAX_HOMING_S / task.control_dt)
    finally:
        env.close()


def test_learning_config_bounds_its_times_however_it_is_built():
    assert LearningConfig(learn_time_s=MAX_LEARN_TIME_S, half_life_s=MAX_HALF_LIFE_S)
    with pytest.raises(ValueError, match=r"learn_time_s must be in \(0, 60\] seconds"):
        LearningConfig(learn_time_s=1e12)
    with pytest.raises(ValueError, match=r"half_life_s must be in \(0, 60\] seconds"):
        LearningConfig(half_life_s=_just_above(MAX_HALF_LIFE_S))
