"""The task's scripted learning phase: odometry loop closure, config, kidnapping poses."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import vc_gym  # noqa: F401
from vc_gym.envs.learning import LearningConfig, ScriptedLearner, kidnap_pose


def test_loop_closure_calibrates_odometry_turns():
    env = gym.make("vc_gym/AiboRoom-v0", max_episode_steps=10**7)
    room = env.unwrapped
    room.reset(seed=4, options={"pose": (0.0, 0.0, 0.0)})
    learner = ScriptedLearner(room, LearningConfig(learn_time_s=0.5))
    true_scale = room.robot.odometry_scale[1]  # drawn at reset, for this check only
    learner._learn_home(steps=5)
    env.close()
    assert abs(true_scale - 1.0) > 0.005  # there is an error to calibrate
    # the odometry over-reports turns by true_scale; the calibration undoes it
    assert learner.rot_scale * true_scale == pytest.approx(1.0, abs=0.02)


def test_kidnap_pose_lies_inside_the_margin():
    rng = np.random.default_rng(0)
    poses = np.array([kidnap_pose(rng, (-3.0, 3.0, -2.0, 2.0), 0.5) for _ in range(500)])
    assert poses[:, 0].min() >= -2.5 and poses[:, 0].max() <= 2.5
    assert poses[:, 1].min() >= -1.5 and poses[:, 1].max() <= 1.5
    assert poses[:, 2].min() >= 0.0 and poses[:, 2].max() < 360.0


@pytest.mark.parametrize(
    "bad",
    [
        {"learn_time_s": 0.0},
        {"spot_distance_m": float("nan")},
        {"head_scan_deg": ()},
        {"head_scan_deg": (100.0,)},
        {"normalise_directions": 0},
        {"normalise_directions": 2.5},
        {"compass": "fast"},
    ],
)
def test_bad_config(bad):
    with pytest.raises(ValueError):
        LearningConfig(**bad)
