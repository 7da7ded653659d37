"""The shared argument checks in vc_gym.validation."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.validation import (
    finite_float,
    flag,
    int_at_least,
    nonnegative_float,
    nonnegative_float_at_most,
    open_fraction,
    positive_float,
    positive_float_at_most,
)


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


def test_open_fraction_is_neither_impossible_nor_certain():
    assert open_fraction("p", 0.05) == 0.05
    for value in (0.0, -0.1, float("nan")):
        with pytest.raises(ValueError, match="p must be finite and > 0"):
            open_fraction("p", value)
    for value in (1.0, 1.5, float("inf")):
        with pytest.raises(ValueError, match="p must be"):
            open_fraction("p", value)
    with pytest.raises(ValueError, match=r"p must be in \(0, 1\), got 1.0"):
        open_fraction("p", 1.0)


def test_finite_float_converts_and_refuses():
    assert finite_float("x", "2.5") == 2.5
    with pytest.raises(ValueError, match="finite"):
        finite_float("x", float("nan"))
    with pytest.raises(ValueError, match="real number"):
        finite_float("x", "abc")


@pytest.mark.parametrize("value", [2, 7, np.int64(3), np.uint8(2)])
def test_int_at_least_accepts_integers(value):
    out = int_at_least("width", value, 2)
    assert out == int(value)
    assert type(out) is int


def test_int_at_least_refuses_small_values():
    assert int_at_least("n", 0, 0) == 0
    with pytest.raises(ValueError, match=r"width must be >= 2, got 1"):
        int_at_least("width", 1, 2)
    with pytest.raises(ValueError, match=r"n must be >= 0, got -1"):
        int_at_least("n", np.int32(-1), 0)


@pytest.mark.parametrize("value", [2.0, "3", True, None, np.float64(4.0)])
def test_int_at_least_refuses_non_integers(value):
    with pytest.raises(ValueError, match=r"width must be an integer >= 2"):
        int_at_least("width", value, 2)


def test_flag_takes_only_true_or_false():
    assert flag("x", True) is True and flag("x", np.False_) is False
    for bad in (1, 0, "yes", None, 1.0):
        with pytest.raises(ValueError, match="x must be True or False"):
            flag("x", bad)


def test_bounded_floats_take_their_bound_and_name_it_with_the_unit():
    assert positive_float_at_most("t", 60, 60.0, "seconds") == 60.0
    assert nonnegative_float_at_most("t", 0, 60.0, "seconds") == 0.0
    assert nonnegative_float_at_most("t", 60, 60.0) == 60.0
    with pytest.raises(ValueError, match=r"^t must be in \(0, 60\] seconds, got 60\.5$"):
        positive_float_at_most("t", 60.5, 60.0, "seconds")
    with pytest.raises(ValueError, match=r"^t must be in \[0, 60\] seconds, got 1e\+20$"):
        nonnegative_float_at_most("t", 1e20, 60.0, "seconds")
    with pytest.raises(ValueError, match=r"^t must be in \(0, 60\], got 61$"):
        positive_float_at_most("t", 61, 60.0)


@pytest.mark.parametrize("value", [-1.0, float("nan"), float("inf"), "5", True])
def test_nonnegative_float_at_most_refuses_what_nonnegative_float_refuses(value):
    with pytest.raises(ValueError, match="^t must be (finite|a real number)"):
        nonnegative_float_at_most("t", value, 60.0)


def test_head_pans_are_a_non_empty_sequence_within_90_degrees():
    from vc_gym.validation import head_pans

    assert head_pans("pans", [-40, 0, 40.5]) == (-40.0, 0.0, 40.5)
    for bad in ((), (100.0,), (float("nan"),), "left", None, (0.0, "x")):
        with pytest.raises(ValueError, match="pans must be non-empty pans within"):
            head_pans("pans", bad)
