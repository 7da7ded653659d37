"""Frames from the robot standing at a pose: history-independent, the head scanning, and
a learning turn's true camera yaws."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.experiments.views.frames import check_frames, frames_at_pose, learning_turn
from vc_gym.sim import AiboRoomEnv

#: The training spot of the ``learned`` fixture (robolab's rear half centre, 5.1).
SPOT = (-1.5, 0.0)


def test_look_is_history_independent(room):
    pose = (0.4, -0.7, 123.0)
    first = frames_at_pose(room, pose, frames=4, seed=11)
    frames_at_pose(room, (2.0, 1.0, 10.0), frames=3, seed=2)  # something else in between
    again = frames_at_pose(room, pose, frames=4, seed=11)
    fresh_env = AiboRoomEnv()
    try:
        fresh = frames_at_pose(fresh_env, pose, frames=4, seed=11)
    finally:
        fresh_env.close()
    for other in (again, fresh):
        assert len(other) == len(first) == 4
        for (im_a, pan_a, odo_a), (im_b, pan_b, odo_b) in zip(first, other, strict=True):
            assert im_a.tobytes() == im_b.tobytes()
            assert (pan_a, odo_a) == (pan_b, odo_b)
    image, pan, odo = first[0]
    assert image.dtype == np.uint8 and image.shape == (160, 208, 3)
    assert pan == 0.0 and odo == (0.0, 0.0, 0.0)
    # the default scan: 0 -> -20 -> 0 -> 20 (the head moves at a bounded speed)
    pans = [f[1] for f in first]
    assert pans[1] < -10.0 and abs(pans[2]) < 5.0 and pans[3] > 10.0
    assert all(type(v) is float for f in first for v in f[2])


def test_bad_looks(room):
    with pytest.raises(ValueError, match="AiboRoomEnv"):
        frames_at_pose(object(), (0.0, 0.0, 0.0), 2, seed=0)
    for kwargs, match in [
        ({"pose": (0.0, float("nan"), 0.0)}, "pose"),
        ({"pose": (0.0, 0.0)}, "pose"),
        ({"frames": 0}, "frames"),
        ({"seed": -1}, "seed"),
        ({"seed": 1.5}, "seed"),
        ({"head_scan_deg": (100.0,)}, "head_scan_deg"),
        ({"head_scan_deg": ()}, "head_scan_deg"),
    ]:
        args = {"pose": (0.0, 0.0, 0.0), "frames": 2, "seed": 0, **kwargs}
        with pytest.raises(ValueError, match=match):
            frames_at_pose(room, **args)


def test_a_learning_turn_faces_eight_directions_with_the_measured_pans(room):
    turn = learning_turn(room, SPOT, frames_per_direction=2, seed=5)
    assert len(turn) == 8 * 2
    for k in range(8):
        pans = [f[1] for f in frames_at_pose(room, (*SPOT, 45.0 * k), 2, seed=5 + k)]
        for (image, camera), pan in zip(turn[2 * k : 2 * k + 2], pans, strict=True):
            assert image.shape == (160, 208, 3)
            assert camera.yaw_deg == pytest.approx(45.0 * k + pan)
            assert camera.hfov_deg == room.camera.hfov_deg


def test_check_frames_refuses_malformed_frames():
    image = np.zeros((4, 4, 3), np.uint8)
    assert check_frames([(image, 1, (0.0, 0.0, 0.0))])[0][1] == 1.0
    for frames, match in [
        ([], "non-empty"),
        (np.zeros(3), "non-empty"),
        ([(image, 0.0)], "frame 0 must be"),
        ([(image, float("nan"), (0.0, 0.0, 0.0))], "head_pan_deg"),
    ]:
        with pytest.raises(ValueError, match=match):
            check_frames(frames)


@pytest.mark.parametrize("module", ["vc_gym.experiments.views", "vc_gym.experiments.views.frames"])
def test_the_old_name_look_warns_and_is_frames_at_pose(module):
    import importlib

    from vc_gym.experiments.views.frames import frames_at_pose

    with pytest.warns(DeprecationWarning, match="frames_at_pose"):
        assert importlib.import_module(module).look is frames_at_pose
