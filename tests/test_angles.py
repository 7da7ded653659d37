import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from vc_gym.angles import (
    circular_mean,
    circular_std,
    circular_std_rows,
    interp_circular,
    wrap180,
    wrap360,
    wrap_pi,
)

angles = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)


@given(angles)
def test_wrap180_range_and_congruence(a):
    w = wrap180(a)
    assert -180.0 <= w < 180.0
    assert math.isclose(math.remainder(w - a, 360.0), 0.0, abs_tol=1e-6)


@given(angles)
def test_wrap_pi_range_and_congruence(a):
    w = wrap_pi(a)
    assert -math.pi <= w < math.pi
    assert math.isclose(math.remainder(w - a, 2 * math.pi), 0.0, abs_tol=1e-6)
    assert wrap_pi(np.array([a])).shape == (1,)  # arrays stay arrays


@given(angles)
def test_wrap360_range_and_congruence(a):
    w = wrap360(a)
    assert 0.0 <= w < 360.0
    assert math.isclose(math.remainder(w - a, 360.0), 0.0, abs_tol=1e-6)


@given(st.floats(-179.0, 179.0), st.floats(0.0, 360.0))
def test_circular_mean_is_rotation_equivariant(offset, base):
    pts = np.array([base - 10.0, base, base + 10.0])
    m0 = circular_mean(pts)
    m1 = circular_mean(pts + offset)
    assert abs(wrap180(m1 - m0 - offset)) < 1e-6


def test_circular_mean_across_zero():
    assert abs(wrap180(circular_mean([359.0, 1.0]))) < 1e-9
    assert abs(circular_mean([350.0, 10.0], weights=[3.0, 1.0]) - wrap360(-5.0)) < 0.1


def test_circular_std():
    assert circular_std([10.0, 10.0, 10.0]) == pytest.approx(0.0, abs=1e-6)
    assert circular_std([0.0, 180.0]) > 180.0  # opposite angles: no concentration at all
    rng = np.random.default_rng(0)
    samples = rng.normal(0.0, 5.0, 20000)
    assert circular_std(samples) == pytest.approx(5.0, rel=0.03)


def test_weights_validation():
    with pytest.raises(ValueError):
        circular_mean([1.0, 2.0], weights=[1.0])
    with pytest.raises(ValueError):
        circular_mean([1.0, 2.0], weights=[-1.0, 2.0])
    with pytest.raises(ValueError):
        circular_mean([])


def test_circular_std_rows_equals_circular_std_on_every_row():
    rng = np.random.default_rng(3)
    angles = np.arange(0.0, 360.0, 1.0)
    weights = np.exp(-0.5 * ((angles[None, :] - rng.uniform(0, 360, (5, 1))) / 4.0) ** 2)
    weights[2] = 1.0  # uniform: no concentration
    weights[3, :] = 0.0
    weights[3, 90] = 1.0  # one heading: spread 0
    rows = circular_std_rows(angles, weights)
    assert rows.shape == (5,)
    for row, w in zip(rows, weights, strict=True):
        assert row == circular_std(angles, w)
    assert rows[3] == 0.0 and rows[2] > 180.0


@pytest.mark.parametrize(
    "weights",
    [np.ones(4), np.ones((2, 3)), np.full((2, 4), np.nan), -np.ones((2, 4)), np.zeros((2, 4))],
)
def test_circular_std_rows_rejects_bad_weights(weights):
    with pytest.raises(ValueError, match="weights"):
        circular_std_rows([0.0, 90.0, 180.0, 270.0], weights)


@pytest.mark.parametrize(
    ("step", "n"), [(1.0, 360), (4.5, 80), (0.1, 3600), (360 / 7, 7), (7.0, None), (0.7, None)]
)
def test_steps_in_circle(step, n):
    from vc_gym.angles import steps_in_circle

    assert steps_in_circle(step) == n


@pytest.mark.parametrize("bad", [0.0, -4.5, float("nan"), float("inf"), True, "4.5"])
def test_steps_in_circle_refuses_what_is_not_a_step(bad):
    from vc_gym.angles import steps_in_circle

    with pytest.raises(ValueError, match="step_deg"):
        steps_in_circle(bad)


def test_interp_circular_is_exact_on_the_grid_linear_between_and_wraps():
    values = np.array([0.0, 10.0, 20.0, 30.0])  # at 0, 90, 180, 270 degrees
    got = interp_circular(values, 90.0, [0.0, 90.0, 45.0, 315.0, 360.0, -45.0, 720.0 + 135.0])
    np.testing.assert_allclose(got, [0.0, 10.0, 5.0, 15.0, 0.0, 15.0, 15.0])


def test_interp_circular_keeps_ruled_out_headings_out():
    values = np.array([0.0, -np.inf, 2.0, 3.0])
    got = interp_circular(values, 90.0, [0.0, 45.0, 180.0])
    assert got[0] == 0.0 and got[1] == -np.inf and got[2] == 2.0


def test_interp_circular_rows_equal_one_row_at_a_time():
    rows = np.random.default_rng(0).normal(size=(3, 360))
    query = np.array([0.25, 17.5, 359.9, -3.3])
    got = interp_circular(rows, 1.0, query)
    assert got.shape == (3, 4)
    for r in range(3):
        np.testing.assert_array_equal(got[r], interp_circular(rows[r], 1.0, query))
