"""The field search for the poses one frame's colour changes fit, in the striped ray-cast
room whose colour edges are known exactly."""

from __future__ import annotations

import numpy as np
import pytest
from striped_room import HFOV, learned_views, striped_room, view

from vc_gym.compass import Camera
from vc_gym.compass.landmarks import learn_landmarks
from vc_gym.localization.bearing_search import search_poses
from vc_gym.localization.bearing_sensor import BearingSensor

BOUNDS = (-2.2, 2.2, -1.7, 1.7)  # the 5 x 4 m room, 0.3 m from its walls


@pytest.fixture(scope="module")
def sensor():
    striped = striped_room()
    colors, views = learned_views(striped)
    return striped[0], BearingSensor(learn_landmarks(views), colors, Camera(hfov_deg=HFOV))


@pytest.mark.parametrize(
    ("x", "y", "yaw"), [(1.8, 1.2, 200.0), (-1.9, -1.3, 35.0), (-1.5, 1.4, 290.0)]
)
def test_one_frame_proposes_its_pose_anywhere_in_the_room(sensor, x, y, yaw):
    """Poses far from every learned turn (the turns stood within 1 m of the centre), 6
    to 9 changes in view: one of the poses proposed lies within a grid cell and a few
    degrees of the truth, and the best fits the frame better than the truth moved by
    0.5 m (measured: the nearest 10-11 cm and 1-4° off; the best 10-35 cm)."""
    room, s = sensor
    img, _ = view(room, x, y, yaw)
    changes = s.bearings(img)
    assert len(changes) >= 6
    poses, ll = search_poses(s, changes, 0.0, BOUNDS)
    assert len(poses) and np.all(np.diff(ll) <= 0)  # best first
    off = np.hypot(poses[:, 0] - x, poses[:, 1] - y)
    turn = np.abs((poses[:, 2] - yaw + 180.0) % 360.0 - 180.0)
    assert np.any((off < 0.2) & (turn < 5.0)), (poses, off, turn)
    assert off[0] < 0.5
    moved = s.pose_log_likelihood(changes, np.array([[x + 0.5, y, yaw]]), noise_deg=2.0)
    assert ll[0] > moved[0]


def test_a_frame_without_known_changes_finds_nothing_and_bad_bounds_are_refused(sensor):
    room, s = sensor
    changes = s.bearings(np.zeros((160, 208, 3), np.uint8))  # black: no change at all
    poses, ll = search_poses(s, changes, 0.0, BOUNDS)
    assert poses.shape == (0, 3) and ll.shape == (0,)
    img, _ = view(room, 0.0, 0.0, 0.0)
    for bounds in [(1.0, -1.0, 0.0, 1.0), (0.0, 1.0, 0.0, float("nan"))]:
        with pytest.raises(ValueError, match="bounds"):
            search_poses(s, s.bearings(img), 0.0, bounds)
    with pytest.raises(ValueError, match="spacing_m"):
        search_poses(s, s.bearings(img), 0.0, BOUNDS, spacing_m=0.0)
