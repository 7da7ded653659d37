import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from vc_gym.angles import circular_mean, circular_std, wrap180, wrap360

angles = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)


@given(angles)
def test_wrap180_range_and_congruence(a):
    w = wrap180(a)
    assert -180.0 <= w < 180.0
    assert math.isclose(math.remainder(w - a, 360.0), 0.0, abs_tol=1e-6)


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
