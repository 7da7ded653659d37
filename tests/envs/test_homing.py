"""vc_gym/Homing-v0: the task as a learned agent sees it, built the same by every maker."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest
from shared_places import POSE_HOME_SEED

import vc_gym  # noqa: F401
from vc_gym.envs import LearnThenHomeEnv
from vc_gym.envs.homing import HomingEnv, HomingFeatures, StopAction

#: A short learning phase of one pinned place (learned once per run, from the place cache).
FAST = {"learn_time_s": 0.2, "max_homing_s": 3.0, "learning_seed": 0}


def test_spaces_and_wrapper_chain():
    env = gym.make("vc_gym/Homing-v0", **FAST)
    assert env.observation_space.shape == (12,) and env.action_space.shape == (3,)
    chain, w = [], env
    while w is not w.unwrapped:
        chain.append(type(w).__name__)
        w = w.env
    # one env class: gym.make's wrappers once each, the task's wrappers inside it
    assert chain == ["TimeLimit", "OrderEnforcing", "PassiveEnvChecker"]
    u = env.unwrapped
    assert isinstance(u, HomingEnv) and isinstance(u, LearnThenHomeEnv)
    assert u.observation_space == env.observation_space
    assert u.action_space == env.action_space
    assert isinstance(u.stop_action, StopAction) and isinstance(u.features, HomingFeatures)
    assert u.stop_action.unwrapped is u and u.compass_observation.unwrapped is u
    assert u.task_action_space.shape == (5,)
    env.close()


@pytest.mark.slow
def test_a_reset_gives_a_feature_vector():
    env = gym.make("vc_gym/Homing-v0", **FAST)
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs) and "pose" in info
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("tracker", ["grid", "particle", "kalman"])
def test_trackers_plug_in_by_name(tracker):
    env = gym.make("vc_gym/Homing-v0", tracker=tracker, **FAST)
    obs, _ = env.reset(seed=1)
    for _ in range(3):
        obs, *_ = env.step(np.array([0.5, 0.0, 0.0], np.float32))
    assert np.all(np.isfinite(obs))
    assert env.get_wrapper_attr("tracker").__class__.__name__.lower().startswith(tracker)
    env.close()


@pytest.mark.slow
def test_make_vec_and_sb3_make_vec_env_build_the_same_env():
    sb3_env_util = pytest.importorskip("stable_baselines3.common.env_util")
    a = gym.make("vc_gym/Homing-v0", **FAST)
    obs_a, _ = a.reset(seed=5)
    vec = gym.make_vec("vc_gym/Homing-v0", num_envs=1, vectorization_mode="sync", **FAST)
    obs_v, _ = vec.reset(seed=5)
    sb3 = sb3_env_util.make_vec_env("vc_gym/Homing-v0", n_envs=1, seed=5, env_kwargs=FAST)
    obs_s = sb3.reset()
    np.testing.assert_array_equal(obs_a, obs_v[0])
    np.testing.assert_array_equal(obs_a, obs_s[0])
    for e in (a, vec, sb3):
        e.close()


def test_features_need_compass_observations():
    with pytest.raises(ValueError, match="CompassObservation"):
        HomingFeatures(gym.make("CartPole-v1"))
    with pytest.raises(ValueError, match="Box\\(5\\)"):
        StopAction(gym.make("CartPole-v1"))


@pytest.mark.slow
def test_stop_action_holds_still_until_the_task_stops():
    env = gym.make("vc_gym/Homing-v0", learn_time_s=0.2, stop_time_s=1.0)
    assert env.action_space.shape == (3,)
    stop_wrapper = env.unwrapped.stop_action
    env.reset(seed=0, options={"pose": (0.1, 0.0, 0.0)})
    stop = np.array([0.0, 0.0, 1.0], np.float32)
    turn_and_stop = np.array([0.0, 1.0, 1.0], np.float32)
    for _ in range(stop_wrapper.min_walk_steps):  # stop requests while the filters settle: ignored
        _, r, terminated, _, info = env.step(turn_and_stop)
        assert not terminated and info["still_time_s"] == 0.0
    env.reset(seed=0, options={"pose": (0.1, 0.0, 0.0)})
    stop_wrapper.min_walk_steps = 0
    obs, r, terminated, truncated, info = env.step(stop)
    assert terminated and info["stopped"] and info["success"]
    assert r == pytest.approx(10.0, abs=1e-3)  # the success bonus, summed over the hold
    assert info["still_time_s"] == pytest.approx(1.0)
    assert info["task_steps"] == 10  # the whole 1 s stand at 10 Hz in one decision
    env.reset(seed=0, options={"pose": (1.0, 0.0, 180.0)})
    _, r, terminated, _, info = env.step(np.array([1.0, 0.0, -1.0], np.float32))
    assert not terminated and r > 0.2  # walked towards home (0.4 m/s for 0.1 s, from rest)
    assert info["task_steps"] == 1
    assert r == pytest.approx(10.0 * (1.0 - info["home_error_m"]), abs=1e-6)
    with pytest.raises(ValueError):
        env.step(np.array([np.nan, 0.0, 0.0]))
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("walk", [[0.0, 0.0, 0.0], [-1.0, 0.02, -1.0], [-0.5, -0.01, 0.4]])
def test_only_the_stop_output_ends_an_episode(walk):
    # a walk decision too small to move is not standing still: if it were, the task's
    # short training stop time would end the episode by accident
    env = gym.make("vc_gym/Homing-v0", learn_time_s=0.2, stop_time_s=0.1, max_homing_s=3.0)
    env.reset(seed=0, options={"pose": (1.0, 0.0, 0.0)})
    for _ in range(10):
        _, _, terminated, truncated, info = env.step(np.array(walk, np.float32))
        assert not terminated and not truncated and info["still_time_s"] == 0.0
    env.close()


@pytest.mark.slow
def test_a_confirmed_stop_is_called_off_when_the_estimate_leaves_home():
    env = gym.make("vc_gym/Homing-v0", learn_time_s=0.2, stop_time_s=1.0, confirm_stop_m=0.25)
    stop_wrapper = env.unwrapped.stop_action
    stop_wrapper.min_walk_steps = 0
    stop = np.array([0.0, 0.0, 1.0], np.float32)
    # at home the estimate stays there: the stop holds and ends the episode
    env.reset(seed=0, options={"pose": (0.1, 0.0, 0.0)})
    _, _, terminated, _, info = env.step(stop)
    assert terminated and info["success"] and info["still_time_s"] == pytest.approx(1.0)
    # 1.5 m away the estimated home is far: the stop is called off after one standing
    # step and the policy decides again
    env.reset(seed=0, options={"pose": (1.5, 0.0, 0.0)})
    obs, _, terminated, truncated, info = env.step(stop)
    assert not terminated and not truncated
    assert np.hypot(*obs[HomingFeatures.HOME_VECTOR]) * HomingFeatures.METRES_SCALE > 0.25
    assert info["still_time_s"] == pytest.approx(0.1) and info["task_steps"] == 1
    env.close()


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_confirm_stop_must_be_a_positive_distance(bad):
    with pytest.raises(ValueError, match="confirm_stop_m"):
        gym.make("vc_gym/Homing-v0", learn_time_s=0.2, confirm_stop_m=bad)


@pytest.mark.slow
@pytest.mark.parametrize("head_scan", [True, False])
def test_the_head_scans_when_the_robot_does_not_walk_forward(head_scan):
    env = gym.make("vc_gym/Homing-v0", head_scan=head_scan, **FAST)
    env.reset(seed=0, options={"pose": (1.0, 0.0, 0.0)})
    pans = []
    for _ in range(8):  # turning in place: the scripted agent scans with its head here
        obs, *_ = env.step(np.array([-1.0, 1.0, -1.0], np.float32))
        pans.append(float(obs[-1]) * 90.0)
    if head_scan:
        assert min(pans) < -15.0 and max(pans) > 15.0
    else:
        assert np.allclose(pans, 0.0, atol=2.0)
    for _ in range(5):  # walking: the head looks ahead
        obs, *_ = env.step(np.array([1.0, 0.3, -1.0], np.float32))
    assert abs(float(obs[-1]) * 90.0) < 2.0
    env.close()


def test_head_scan_must_be_a_bool():
    with pytest.raises(ValueError, match="head_scan"):
        gym.make("vc_gym/Homing-v0", head_scan="yes", **FAST)


@pytest.mark.slow
def test_stop_requests_wait_until_the_robot_has_walked_min_walk_m():
    env = gym.make("vc_gym/Homing-v0", min_walk_s=0.0, min_walk_m=0.18, stop_time_s=1.0, **FAST)
    env.reset(seed=0, options={"pose": (0.1, 0.0, 0.0)})
    turn_and_stop = np.array([0.0, 1.0, 1.0], np.float32)
    for _ in range(5):  # stop requests without walking are walk decisions: here, turns
        _, _, terminated, _, info = env.step(turn_and_stop)
        assert not terminated and info["task_steps"] == 1
    walk_and_stop = np.array([1.0, 0.0, 1.0], np.float32)
    for _ in range(5):  # 0.4 m/s for 0.1 s each: 0.16 m after four, still a walk
        _, _, terminated, _, info = env.step(walk_and_stop)
        assert not terminated and info["task_steps"] == 1
    _, _, terminated, _, info = env.step(np.array([0.0, 0.0, 1.0], np.float32))
    assert terminated and info["task_steps"] == 10  # now the stop holds for the whole 1 s
    # a new episode must walk again
    env.reset(seed=0, options={"pose": (0.1, 0.0, 0.0)})
    _, _, terminated, _, info = env.step(turn_and_stop)
    assert not terminated and info["task_steps"] == 1
    env.close()
    with pytest.raises(ValueError, match="min_walk_m"):
        gym.make("vc_gym/Homing-v0", min_walk_m=-0.1, **FAST)


@pytest.mark.slow
def test_home_offset_moves_the_goal_of_the_features():
    offset = (0.1, -0.2)
    plain = gym.make("vc_gym/Homing-v0", **FAST)
    moved = gym.make("vc_gym/Homing-v0", home_offset_m=offset, **FAST)
    a, _ = plain.reset(seed=3)
    b, _ = moved.reset(seed=3)
    for _ in range(3):
        step = np.array([0.6, 0.3, 0.0], np.float32)
        a, *_ = plain.step(step)
        b, *_ = moved.step(step)
    m = HomingFeatures.METRES_SCALE
    c, s = a[HomingFeatures.HEADING]
    ox, oy = offset
    np.testing.assert_allclose(
        b[HomingFeatures.POSITION] * m, a[HomingFeatures.POSITION] * m - offset, atol=1e-5
    )
    shift = (ox * c + oy * s, -ox * s + oy * c)  # the offset in the robot's frame
    np.testing.assert_allclose(
        b[HomingFeatures.HOME_VECTOR] * m, a[HomingFeatures.HOME_VECTOR] * m + shift, atol=1e-5
    )
    rest = slice(HomingFeatures.GOODNESS_START, None)
    np.testing.assert_array_equal(b[rest], a[rest])
    assert moved.get_wrapper_attr("home_offset_m") == offset
    plain.close()
    moved.close()


@pytest.mark.parametrize("bad", [(1.2, 0.0), (float("nan"), 0.0), (0.1,), "0.1,0.2", (0.1, True)])
def test_home_offset_must_be_a_nearby_point(bad):
    with pytest.raises(ValueError, match="home_offset_m"):
        gym.make("vc_gym/Homing-v0", home_offset_m=bad, **FAST)


@pytest.mark.slow
def test_previous_action_appends_the_last_action_taken():
    from gymnasium.utils.env_checker import check_env
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    from vc_gym.envs import PreviousAction

    env = gym.make("vc_gym/Homing-v0", previous_action=True, **FAST)
    assert env.observation_space.shape == (15,)
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    np.testing.assert_array_equal(obs[PreviousAction.PREVIOUS_ACTION], np.zeros(3))
    plain = gym.make("vc_gym/Homing-v0", **FAST)  # the rest of the vector is its own
    np.testing.assert_array_equal(plain.reset(seed=0)[0], obs[:-3])
    obs, *_ = env.step(np.array([0.3, 2.0, -0.2]))  # the turn is clipped to 1
    np.testing.assert_allclose(obs[PreviousAction.PREVIOUS_ACTION], [0.3, 1.0, -0.2], atol=1e-6)
    assert env.observation_space.contains(obs)
    obs, _ = env.reset(seed=1)
    np.testing.assert_array_equal(obs[PreviousAction.PREVIOUS_ACTION], np.zeros(3))
    checked = gym.make("vc_gym/Homing-v0", previous_action=True, **FAST)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        check_env(checked)  # as the agent sees it
        sb3_check_env(checked, warn=True)
    checked.close()
    problems = [str(w.message) for w in record if "unwrapped version" not in str(w.message)]
    assert not problems, problems
    for e in (env, plain):
        e.close()
    with pytest.raises(ValueError, match="previous_action"):
        gym.make("vc_gym/Homing-v0", previous_action="yes", **FAST)
    with pytest.raises(ValueError, match="feature vector"):
        PreviousAction(gym.make("vc_gym/LearnThenHome-v0", **FAST))


@pytest.mark.slow
def test_position_std_adds_the_trackers_position_spread_in_the_pose_home_mode():
    from gymnasium.utils.env_checker import check_env

    from vc_gym.agents.learned import homing_spaces
    from vc_gym.envs.homing_modes import homing_mode

    mode = homing_mode("pose-home")
    kwargs = {
        **FAST,
        "learning_seed": POSE_HOME_SEED,  # the place the demo test learns
        **mode.learning,
        "tracker": mode.tracker,
        "position_std": True,
        "previous_action": True,
    }
    env = gym.make("vc_gym/Homing-v0", **kwargs)
    obs, _ = env.reset(seed=0)
    u = env.unwrapped
    assert u.n_spots == 25  # four spots and home, each with four turns around it
    assert env.observation_space.shape == (8 + 25 + 2 + 3,)
    assert homing_spaces(kwargs)[0] == env.observation_space  # what a saved agent is checked by
    where = HomingFeatures.position_std_slice(u.n_spots)
    spread = np.asarray(u.last_state.position_std_m) / HomingFeatures.POSITION_STD_SCALE_M
    np.testing.assert_allclose(obs[where], spread, rtol=1e-6)
    assert np.all(spread > 0)  # a belief just after a kidnapping is not sure of anything
    for _ in range(3):
        obs, *_ = env.step(np.array([0.5, 0.0, -1.0]))
        spread = np.asarray(u.last_state.position_std_m) / HomingFeatures.POSITION_STD_SCALE_M
        np.testing.assert_allclose(obs[where], spread, rtol=1e-6)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        check_env(env)  # the place is learned: its resets only kidnap
    problems = [str(w.message) for w in record if "unwrapped version" not in str(w.message)]
    assert not problems, problems
    env.close()
    with pytest.raises(ValueError, match="position_std"):
        gym.make("vc_gym/Homing-v0", position_std="yes", **FAST)


@pytest.mark.slow
def test_the_env_class_steps_as_the_task_wrapped_by_hand():
    # HomingEnv applies the wrappers inside itself; its episodes are those of the task
    # wrapped by hand (what vc_gym/Homing-v0 was built as, what trained policies saw)
    from vc_gym.envs import CompassObservation, PreviousAction

    kwargs = {**FAST, "stop_time_s": 1.0, "min_walk_s": 0.5}
    made = gym.make("vc_gym/Homing-v0", previous_action=True, confirm_stop_m=0.25, **kwargs)
    task = LearnThenHomeEnv(
        learn_time_s=0.2, max_homing_s=3.0, stop_time_s=1.0, learning_seed=0, place_cache=False
    )
    by_hand = PreviousAction(
        StopAction(
            HomingFeatures(CompassObservation(task, keep_image=False)),
            min_walk_s=0.5,
            confirm_stop_m=0.25,
        )
    )
    rng = np.random.default_rng(7)
    for seed in (3, 4):
        a, info_a = made.reset(seed=seed)
        b, info_b = by_hand.reset(seed=seed)
        np.testing.assert_array_equal(a, b)
        for i in range(40):
            action = rng.uniform(-1, 1, 3).astype(np.float32)
            action[2] = 1.0 if i % 9 == 8 else action[2]
            a, ra, ta, ua, info_a = made.step(action)
            b, rb, tb, ub, info_b = by_hand.step(action)
            np.testing.assert_array_equal(a, b)
            assert (ra, ta, ua) == (rb, tb, ub) and info_a.keys() == info_b.keys()
            np.testing.assert_array_equal(info_a["pose"], info_b["pose"])
            if ta or ua:
                break
    made.close()
    by_hand.close()


def test_the_inner_wrappers_settings_are_read_and_set_through_the_env():
    env = gym.make("vc_gym/Homing-v0", min_walk_m=0.3, confirm_stop_m=0.25, **FAST)
    u = env.unwrapped
    assert env.get_wrapper_attr("min_walk_m") == 0.3 == u.stop_action.min_walk_m
    assert env.get_wrapper_attr("confirm_stop_m") == 0.25
    assert env.get_wrapper_attr("n_spots") == 4 and env.get_wrapper_attr("max_forward") == 0.4
    env.set_wrapper_attr("min_walk_m", 0.5)
    assert u.stop_action.min_walk_m == 0.5
    env.set_wrapper_attr("home_offset_m", (0.1, 0.0))
    assert u.features.home_offset_m == (0.1, 0.0)
    assert not hasattr(u, "env")  # the env is no wrapper
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        u.nothing  # noqa: B018
    env.close()
