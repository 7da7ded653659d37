import numpy as np
import pytest

from vc_gym.filters.heading_grid import mixing_lambda
from vc_gym.filters.translational import TranslationalFilter, weighted_spot_position

SPOTS = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])


def test_eq30_weighted_mean():
    assert weighted_spot_position(SPOTS, [1, 1, 1, 1]) == pytest.approx([0.0, 0.0])
    assert weighted_spot_position(SPOTS, [3, 1, 0, 0]) == pytest.approx([0.75, 0.25])


def test_mixing_update_and_motion():
    f = TranslationalFilter(SPOTS, half_life_s=0.3, dt_s=0.1)
    assert f.position == (0.0, 0.0)
    f.predict(0.5, -0.2)
    assert f.position == pytest.approx((0.5, -0.2))
    lam = mixing_lambda(0.3, 0.1)
    f.update([1.0, 0.0, 0.0, 0.0])
    assert f.position == pytest.approx((lam * 1.0 + (1 - lam) * 0.5, (1 - lam) * -0.2))


def test_converges_to_constant_reading():
    f = TranslationalFilter(SPOTS, dt_s=0.1, start=(3.0, 3.0))
    for _ in range(60):
        f.update([2.0, 1.0, 1.0, 1.0])
    assert f.distance_to((0.2, 0.0)) < 1e-3


@pytest.mark.parametrize(
    "goodness", [[1, 1, 1], [-1, 1, 1, 1], [0, 0, 0, 0], [np.nan, 1, 1, 1], [np.inf, 1, 1, 1]]
)
def test_bad_goodness(goodness):
    f = TranslationalFilter(SPOTS)
    with pytest.raises(ValueError):
        f.update(goodness)


def test_bad_construction():
    with pytest.raises(ValueError):
        TranslationalFilter(np.zeros((3, 3)))
    with pytest.raises(ValueError):
        TranslationalFilter(SPOTS, half_life_s=-1)
    with pytest.raises(ValueError):
        TranslationalFilter(SPOTS).predict(np.nan, 0.0)


@pytest.mark.parametrize(
    "call", [lambda f: f.predict(1e308, 0.0), lambda f: f.update_position((1e7, 0))]
)
def test_huge_motion_or_position_is_refused_and_the_estimate_stays_finite(call):
    f = TranslationalFilter(SPOTS)
    with pytest.raises(ValueError, match="1e\\+06 m"):
        call(f)
    f.predict(2.0, 0.0)
    assert f.position == pytest.approx((2.0, 0.0))
