"""The shared argument checks in vc_gym.validation."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.validation import finite_float, nonnegative_float, positive_float


@pytest.mark.parametrize("value", [1, 0.5, np.float32(2.0), np.int64(3)])
def test_positive_accepts_real_numbers(value):
    assert positive_float("x", value) == float(value)
    assert nonnegative_float("x", value) == float(value)


def test_nonnegative_accepts_zero_positive_does_not():
    assert nonnegative_float("x", 0) == 0.0
    with pytest.raises(ValueError, match=r"x must be finite and > 0, got 0"):
        positive_float("x", 0)


@pytest.mark.parametrize("check", [positive_float, nonnegative_float])
@pytest.mark.parametrize("value", [-1.0, float("nan"), float("inf")])
def test_out_of_range_values_are_refused(check, value):
    with pytest.raises(ValueError, match="time_s must be finite"):
        check("time_s", value)


@pytest.mark.parametrize("check", [positive_float, nonnegative_float])
@pytest.mark.parametrize("value", ["0.5", True, None, [1.0]])
def test_non_numbers_are_refused(check, value):
    with pytest.raises(ValueError, match="time_s must be a real number"):
        check("time_s", value)


def test_finite_float_converts_and_refuses():
    assert finite_float("x", "2.5") == 2.5
    with pytest.raises(ValueError, match="finite"):
        finite_float("x", float("nan"))
    with pytest.raises(ValueError, match="real number"):
        finite_float("x", "abc")
