"""check_pose: the one validation of a planar pose (x, y, heading)."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.poses import check_pose


def test_a_pose_becomes_three_floats():
    assert check_pose((1, np.float32(-2.5), 90)) == (1.0, -2.5, 90.0)
    assert check_pose(np.array([0.0, 0.0, 359.9])) == (0.0, 0.0, 359.9)


@pytest.mark.parametrize(
    ("pose", "match"),
    [
        ((0.0, 0.0), r"\(x, y, heading_deg\)"),
        ((0.0, 0.0, 0.0, 0.0), r"\(x, y, heading_deg\)"),
        ("home", r"\(x, y, heading_deg\)"),
        (None, r"\(x, y, heading_deg\)"),
        ((0.0, float("nan"), 0.0), "3 finite numbers"),
        ((float("inf"), 0.0, 0.0), "3 finite numbers"),
    ],
)
def test_bad_poses_are_clear_errors(pose, match):
    with pytest.raises(ValueError, match=match):
        check_pose(pose)
