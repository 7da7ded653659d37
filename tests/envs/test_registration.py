"""How the envs are registered: the tasks' horizon is their own time limit (one
truncation, on the same step for Gymnasium's TimeLimit and the env), Homing-v0 is one env
class, and both env checkers pass on every unwrapped env."""

from __future__ import annotations

import inspect
import warnings

import gymnasium as gym
import numpy as np
import pytest

from vc_gym import CONTROL_DT_S, MAX_HOMING_S, MAX_LEARNING_S, time_limit_steps
from vc_gym.envs import HomingEnv, LearnThenHomeEnv
from vc_gym.sim import AiboRoomEnv
from vc_gym.sim.head_camera import HeadCameraSpec

SMALL = HeadCameraSpec(52, 40, 56.9)
TASKS = ["vc_gym/LearnThenHome-v0", "vc_gym/Homing-v0"]


@pytest.mark.parametrize(
    ("seconds", "dt", "steps"),
    [(60.0, 0.1, 600), (0.3, 0.1, 3), (1.0, 0.3, 4), (0.05, 0.1, 1), (300.0, 0.1, 3000)],
)
def test_time_limit_steps(seconds, dt, steps):
    assert time_limit_steps(seconds, dt) == steps


@pytest.mark.parametrize("bad", [(0.0, 0.1), (1.0, 0.0), (float("nan"), 0.1), (1.0, -0.1)])
def test_time_limit_steps_refuses_impossible_times(bad):
    with pytest.raises(ValueError, match="finite and positive"):
        time_limit_steps(*bad)


def test_the_defaults_are_the_constants_the_horizon_is_computed_from():
    room = inspect.signature(AiboRoomEnv).parameters
    task = inspect.signature(LearnThenHomeEnv).parameters
    assert room["control_dt"].default == CONTROL_DT_S
    assert task["max_homing_s"].default == MAX_HOMING_S
    assert task["max_learning_s"].default == MAX_LEARNING_S


@pytest.mark.parametrize("env_id", TASKS)
def test_the_registered_horizon_is_the_envs_own_limit(env_id):
    assert gym.spec(env_id).max_episode_steps == 600 == time_limit_steps(60.0, 0.1)
    env = gym.make(env_id, learn_time_s=0.2, camera=SMALL)
    assert env.unwrapped.max_episode_steps == gym.spec(env_id).max_episode_steps
    assert env.spec.max_episode_steps == 600
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("env_id", TASKS)
def test_an_episode_run_to_the_limit_truncates_once(env_id):
    env = gym.make(env_id, learn_time_s=0.2, camera=SMALL)
    limit = gym.spec(env_id).max_episode_steps
    # turning in place: never still (no stop), never a stop decision
    action = (
        np.array([0.0, 1.0, 0.0], np.float32)
        if env_id.endswith("Homing-v0")
        else np.array([0.0, 0.0, 0.5, 0.0, 0.0], np.float32)
    )
    env.reset(seed=0, options={"pose": (1.0, 0.0, 0.0)})
    ends = []
    for i in range(limit):
        _, _, terminated, truncated, info = env.step(action)
        assert not terminated
        if truncated:
            ends.append(i + 1)
            break
    assert ends == [limit]
    # the env's own truncation: its end-of-episode keys are there
    assert info["is_success"] is False and info["stopped"] is False
    assert info["sim_time"] == pytest.approx(MAX_HOMING_S)
    env.close()


def test_a_limit_beyond_the_registered_horizon_warns():
    kwargs = {"learn_time_s": 0.2, "camera": SMALL}
    with pytest.warns(UserWarning, match="max_episode_steps=1200"):
        env = gym.make("vc_gym/LearnThenHome-v0", max_homing_s=120.0, **kwargs)
    env.close()
    with pytest.warns(UserWarning, match="max_episode_steps=3600"):
        env = gym.make("vc_gym/LearnThenHome-v0", learning="agent", **kwargs)
    assert env.unwrapped.max_episode_steps == 3600
    env.close()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = gym.make("vc_gym/Homing-v0", max_homing_s=3.0, **kwargs)  # ends before
        assert env.unwrapped.max_episode_steps == 30
        env.close()
        LearnThenHomeEnv(max_homing_s=120.0, **kwargs).close()  # no gym.make, no TimeLimit


def test_homing_is_one_class():
    assert gym.spec("vc_gym/Homing-v0").entry_point == "vc_gym.envs.homing:HomingEnv"
    assert issubclass(HomingEnv, LearnThenHomeEnv)


def test_make_task_leaves_the_time_limit_to_the_task():
    from vc_gym.envs.learn_then_home import make_task

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = make_task("vc_gym/LearnThenHome-v0", max_homing_s=120.0, learn_time_s=0.2)
    chain, w = [], env
    while w is not w.unwrapped:
        chain.append(type(w).__name__)
        w = w.env
    assert "TimeLimit" not in chain and env.unwrapped.max_episode_steps == 1200
    env.close()
