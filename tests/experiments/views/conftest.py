"""Fixtures of the view tests: robolab's room and one spot learned in it."""

from __future__ import annotations

import pytest

from vc_gym.compass import Camera
from vc_gym.envs import LearningConfig, SpotLearning
from vc_gym.sim import AiboRoomEnv

#: The centre of robolab's rear field half (the paper's training spot, 5.1).
SPOT = (-1.5, 0.0)


@pytest.fixture(scope="module")
def room():
    env = AiboRoomEnv()
    try:
        yield env
    finally:
        env.close()


@pytest.fixture(scope="module")
def learned(room):
    room.reset(seed=0)
    config = LearningConfig(learn_time_s=0.5, normalise_directions=6)
    atlas = SpotLearning(SPOT)(room, config).atlas
    return atlas, Camera(hfov_deg=room.camera.hfov_deg)
