"""TrackerState and the frame checks shared by every tracker."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.localization import TrackerState
from vc_gym.localization.tracker_protocol import check_frame_inputs


def state(belief):
    return TrackerState(0.0, 1.0, (0.0, 0.0), (0.1, 0.1), np.ones(2), belief, (0.0, 0.0))


def test_belief_sectors_sum_the_grid_into_sectors_from_zero():
    b = np.zeros(360)
    b[[0, 44, 45, 359]] = [0.1, 0.2, 0.3, 0.4]
    np.testing.assert_allclose(state(b).belief_sectors(8), [0.3, 0.3, 0, 0, 0, 0, 0, 0.4])
    coarse = np.array([0.25, 0.25, 0.5, 0.0])  # a 90 deg grid into 2 sectors
    np.testing.assert_allclose(state(coarse).belief_sectors(2), [0.5, 0.5])
    with pytest.raises(ValueError):
        state(b).belief_sectors(0)


def test_check_frame_inputs():
    assert check_frame_inputs(10, np.array([0.1, 0.0, 5.0], np.float32)) == pytest.approx(
        (10.0, 0.1, 0.0, 5.0)
    )
    for pan, odo in ((np.nan, (0, 0, 0)), ("left", (0, 0, 0)), (0.0, (0, 0, np.inf)), (0.0, [1])):
        with pytest.raises(ValueError):
            check_frame_inputs(pan, odo)
