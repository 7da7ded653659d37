"""The argument checks shared by the view modules."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.experiments.views.checks import (
    checked_bounds,
    int_at_least,
    one_spot,
    positions_array,
    spots_array,
)


def test_good_values_pass_through():
    assert checked_bounds([-3, 3, -2, 2]) == (-3.0, 3.0, -2.0, 2.0)
    assert int_at_least("n", np.int64(2), 1) == 2
    assert positions_array([[1, 2]]).dtype == np.float64
    np.testing.assert_array_equal(spots_array((1.0, 2.0)), [[1.0, 2.0]])
    np.testing.assert_array_equal(spots_array([(1.0, 2.0), (3.0, 4.0)]), [[1, 2], [3, 4]])
    assert one_spot([1, 2]) == (1.0, 2.0)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: checked_bounds((0, 1, 0), "field_bounds"), "field_bounds must be 4"),
        (lambda: checked_bounds(None), "bounds must be"),
        (lambda: checked_bounds((0, 1, 1, 1)), "ymin < ymax"),
        (lambda: int_at_least("n", True, 0), "n must be an int >= 0"),
        (lambda: int_at_least("n", 0, 1), "n must be an int >= 1"),
        (lambda: positions_array([1.0, 2.0]), "shape"),
        (lambda: positions_array([[1.0, np.inf]]), "finite"),
        (lambda: spots_array([]), "spot must be"),
        (lambda: spots_array("here"), "spot must be"),
        (lambda: one_spot([(1.0, 2.0), (3.0, 4.0)]), "spot must be"),
    ],
)
def test_bad_values_are_clear_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()
