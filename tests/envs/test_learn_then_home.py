"""vc_gym/LearnThenHome-v0: learning phase, kidnapping, stop rule, rewards, info."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import vc_gym  # noqa: F401
from vc_gym.agents.scripted import ScriptedHomingPolicy
from vc_gym.compass import CompassAtlas
from vc_gym.envs import CompassObservation
from vc_gym.envs.learning import LearningResult
from vc_gym.sim import HeadCameraSpec

STILL = np.zeros(5, np.float32)
SMALL_CAMERA = HeadCameraSpec(52, 40, 56.9)  # the suite's test camera
WALK = np.array([0.5, 0, 0, 0, 0], np.float32)  # 0.25 m/s straight ahead


@pytest.fixture(scope="module")
def env():
    # the place most fast envs of the suite share (learned once a run)
    e = gym.make(
        "vc_gym/LearnThenHome-v0", learn_time_s=0.2, learning_seed=0, camera=SMALL_CAMERA
    )
    yield e
    e.close()


@pytest.mark.slow
def test_reset_learns_an_atlas_and_kidnaps(env):
    obs, info = env.reset(seed=1)
    u = env.unwrapped
    assert isinstance(u.atlas, CompassAtlas) and u.atlas.is_normalized
    assert set(u.atlas.names) == {"east", "north", "west", "south"}
    assert info["phase"] == "homing" and obs["phase"][0] == 1.0
    fx0, fx1, fy0, fy1 = u.room.scene.field_bounds
    x, y, _ = info["pose"]
    assert fx0 + 0.5 <= x <= fx1 - 0.5 and fy0 + 0.5 <= y <= fy1 - 0.5
    assert info["home_error_m"] == pytest.approx(math.hypot(x, y))
    assert "pose" not in obs
    result = u.learning_result
    assert result.atlas is u.atlas and set(result.spots) == set(u.atlas.names)
    assert len(result.true_path) == 4 * 8 * 2  # 4 spots x 8 directions x 0.2 s at 10 Hz
    assert 0.8 <= result.odometry_turn_scale <= 1.25


class CountingLearner:
    """A learner that answers with a fresh token instead of learning.

    For tests of the task's rules that do not need a real atlas
    (test_reset_learns_an_atlas_and_kidnaps learns for real).
    """

    def __init__(self):
        self.calls = []

    def __call__(self, room, config):
        self.calls.append((room, config))
        return LearningResult(atlas=object(), spots={})


@pytest.fixture
def learner():
    return CountingLearner()


@pytest.mark.parametrize(("relearn", "learnings"), [("scene", 1), ("episode", 3)])
def test_atlas_is_reused_per_scene_and_relearned_per_episode(learner, relearn, learnings):
    e = gym.make("vc_gym/LearnThenHome-v0", relearn=relearn, learner=learner)
    atlases = []
    for seed in (0, 1, 2):
        _, info = e.reset(seed=seed)
        assert info["phase"] == "homing"
        atlases.append(e.unwrapped.atlas)
    e.close()
    assert len(learner.calls) == learnings
    assert len({id(a) for a in atlases}) == learnings
    room, config = learner.calls[0]
    assert room is e.unwrapped.room and config.learn_time_s == 5.0


def test_a_learner_must_return_a_learning_result():
    e = gym.make("vc_gym/LearnThenHome-v0", learner=lambda room, config: "atlas")
    with pytest.raises(TypeError, match="LearningResult"):
        e.reset(seed=0)
    e.close()
    with pytest.raises(ValueError, match="learner"):
        gym.make("vc_gym/LearnThenHome-v0", learner="scripted")


@pytest.mark.slow
def test_progress_reward_is_distance_gained(env):
    env.reset(seed=2, options={"pose": (2.0, 0.0, 180.0)})  # facing home, 2 m away
    total = 0.0
    for _ in range(10):  # 1 s at 0.25 m/s
        _, r, terminated, truncated, info = env.step(WALK)
        total += r
    assert not (terminated or truncated)
    assert info["home_error_m"] == pytest.approx(1.75, abs=0.01)
    assert total == pytest.approx(10.0 * (2.0 - info["home_error_m"]), abs=1e-6)


@pytest.mark.parametrize(("start", "success"), [((0.1, 0.1, 0.0), True), ((1.5, 0.0, 0.0), False)])
def test_standing_still_for_stop_time_ends_the_episode(env, start, success):
    env.reset(seed=3, options={"pose": start})
    steps = int(round(5.0 / env.unwrapped.control_dt))
    for i in range(steps):
        # head scanning is allowed while standing still
        a = STILL.copy()
        a[3] = 0.4 if i % 2 else -0.4
        _, r, terminated, truncated, info = env.step(a)
        if i < steps - 1:
            assert not terminated and r == pytest.approx(0.0, abs=1e-4)
    assert terminated and not truncated
    assert info["stopped"] and info["success"] is success and info["is_success"] is success
    np.testing.assert_allclose(info["stop_position"], start[:2], atol=1e-3)
    assert info["stop_error_m"] == pytest.approx(math.hypot(*start[:2]), abs=1e-3)
    assert r == pytest.approx(10.0 if success else 0.0, abs=1e-3)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(STILL)


@pytest.mark.parametrize(("start", "success"), [((0.1, 0.1, 0.0), True), ((0.4, 0.0, 0.0), False)])
def test_closeness_bonus_grows_towards_home(learner, start, success):
    e = gym.make("vc_gym/LearnThenHome-v0", stop_time_s=0.5, closeness_bonus=6.0, learner=learner)
    e.reset(seed=3, options={"pose": start})
    for _ in range(5):
        _, r, terminated, _, info = e.step(STILL)
    e.close()
    assert terminated and info["success"] is success
    d = info["stop_error_m"]
    assert d == pytest.approx(math.hypot(*start[:2]), abs=1e-3)
    bonus = 10.0 + 6.0 * (1.0 - d / 0.3) if success else 0.0
    assert r == pytest.approx(bonus, abs=1e-3)


def test_closeness_bonus_is_checked():
    with pytest.raises(ValueError, match="closeness_bonus"):
        gym.make("vc_gym/LearnThenHome-v0", closeness_bonus=-1.0)


def test_moving_resets_the_stop_clock_and_time_limit_truncates(learner):
    e = gym.make("vc_gym/LearnThenHome-v0", max_homing_s=3.0, stop_time_s=1.0, learner=learner)
    e.reset(seed=4, options={"pose": (1.0, 1.0, 0.0)})
    turn = np.array([0, 0, 0.5, 0, 0], np.float32)
    for i in range(30):
        _, _, terminated, truncated, info = e.step(STILL if i % 9 else turn)
        if terminated or truncated:
            break
    assert truncated and not terminated and i == 29
    assert not info["stopped"] and not info["success"]
    e.close()


@pytest.mark.slow
def test_scripted_homing_ends_at_home():
    """A short scripted episode on a fixed seed ends within the success radius."""
    e = gym.make("vc_gym/LearnThenHome-v0", learn_time_s=1.0)
    w = CompassObservation(e, keep_image=False)
    policy = ScriptedHomingPolicy.for_env(w)
    obs, info = w.reset(seed=4)  # kidnapped to (0.06, 1.43), heading 29 deg
    for _ in range(600):
        obs, _, terminated, truncated, info = w.step(policy.predict(obs))
        if terminated or truncated:
            break
    e.close()
    assert terminated and info["stopped"], info
    assert info["success"], info["stop_error_m"]


def test_agent_learning_phase():
    e = gym.make("vc_gym/LearnThenHome-v0", learning="agent", max_spots=3)
    assert e.action_space.shape == (7,)
    obs, info = e.reset(seed=5, options={"pose": (1.5, 1.0, 90.0)})
    assert info["phase"] == "learning" and obs["phase"][0] == 0.0
    assert e.unwrapped.atlas is None
    turn = np.array([0, 0, 0.6, 0, 0, 1, -1], np.float32)  # turn and learn
    for _ in range(70):  # a full turn at home (~36 deg/s)
        e.step(turn)
    for _ in range(10):  # walk 0.5 m without learning
        e.step(np.array([1, 0, 0, 0, 0, -1, -1], np.float32))
    for _ in range(70):  # a full turn at the second spot
        e.step(turn)
    obs, r, terminated, truncated, info = e.step(np.array([0, 0, 0, 0, 0, -1, 1], np.float32))
    atlas = e.unwrapped.atlas
    assert r == 0.0 and not terminated and info["phase"] == "homing" and obs["phase"][0] == 1.0
    assert isinstance(atlas, CompassAtlas) and len(atlas) == 2 and atlas.is_normalized
    spots = dict(zip(atlas.names, atlas.positions, strict=True))
    np.testing.assert_allclose(spots["spot0"], (0.0, 0.0), atol=0.05)
    assert 0.4 < np.hypot(*spots["spot1"]) < 0.6
    np.testing.assert_allclose(info["pose"][:2], (1.5, 1.0), atol=1e-6)  # kidnapped
    w = CompassObservation(e, keep_image=False)
    assert w.observation_space["goodness"].shape == (3,)
    e.close()


def test_agent_that_learns_nothing_fails():
    e = gym.make("vc_gym/LearnThenHome-v0", learning="agent")
    e.reset(seed=0)
    _, r, terminated, _, info = e.step(np.array([0, 0, 0, 0, 0, -1, 1], np.float32))
    assert terminated and r == -10.0 and info["learned"] is False and not info["success"]
    e.close()


@pytest.mark.parametrize(
    "kwargs",
    [
        {"learning": "teleport"},
        {"relearn": "never"},
        {"success_radius_m": 0.0},
        {"stop_time_s": float("nan")},
        {"still_threshold": 1.5},
        {"max_spots": 0},
        {"scene": "moon"},
        {"compass": "fast"},
        {"around_m": -0.5},
        {"around_m": "wide"},
        {"around_m": 0.8},  # beyond half of the 1 m spot distance
        {"around_m": 0.5, "learning": "agent"},
    ],
)
def test_bad_arguments(kwargs):
    with pytest.raises(ValueError):
        gym.make("vc_gym/LearnThenHome-v0", **kwargs)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"kidnap_margin_m": 100.0}, "kidnap_margin_m"), ({"spot_distance_m": 50.0}, "walls")],
)
def test_settings_the_scene_cannot_hold_are_refused_before_learning(kwargs, match):
    calls = []

    def learner(room, config):  # must never run
        calls.append(1)
        raise AssertionError("learned")

    env = gym.make("vc_gym/LearnThenHome-v0", learner=learner, **kwargs)
    with pytest.raises(ValueError, match=match):
        env.reset(seed=0)
    assert calls == []
    env.close()


def test_bad_actions_and_closed_env(learner):
    e = gym.make("vc_gym/LearnThenHome-v0", learner=learner)
    with pytest.raises(RuntimeError, match="reset"):
        e.unwrapped.step(STILL)
    e.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        e.unwrapped.step(np.zeros(7))
    with pytest.raises(ValueError, match="finite"):
        e.unwrapped.step(np.array([np.nan, 0, 0, 0, 0]))
    with pytest.raises(ValueError, match="reset options"):
        e.reset(options={"teleport": True})
    e.close()
    with pytest.raises(RuntimeError, match="closed"):
        e.unwrapped.step(STILL)
    with pytest.raises(RuntimeError, match="closed"):
        e.reset(seed=0)
