"""Huge, NaN and infinite arguments to the filters: a ValueError naming the argument and
its range, or (a blur wider than the circle) the belief it means."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.filters.heading_grid import UNIFORM_SPREAD_DEG, HeadingGridFilter
from vc_gym.filters.heading_kalman import KalmanHeadingFilter
from vc_gym.filters.particle_filter import MAX_PARTICLES, ParticleFilter
from vc_gym.filters.synthetic_sensors import VonMisesHeadingSensor
from vc_gym.filters.translational import TranslationalFilter, weighted_spot_position

BAD = (1e308, float("inf"), float("nan"))


# ------------------------------------------------------------------ grid filter
@pytest.mark.parametrize("value", BAD)
def test_grid_noise_and_spread_beyond_range_name_the_argument(value):
    f = HeadingGridFilter()
    f.reset(10.0, 5.0)
    before = f.belief
    with pytest.raises(ValueError, match="noise_deg must be"):
        f.predict(0.0, noise_deg=value)
    with pytest.raises(ValueError, match="spread_deg must be"):
        f.reset(0.0, spread_deg=value)
    with pytest.raises(ValueError, match="dtheta_deg must be"):
        f.predict(value)
    with pytest.raises(ValueError, match="heading_deg must be"):
        f.reset(value)
    np.testing.assert_array_equal(f.belief, before)


def test_grid_range_errors_state_the_range():
    f = HeadingGridFilter()
    with pytest.raises(ValueError, match=r"noise_deg must be in \[0, 1e\+09\] degrees"):
        f.predict(0.0, noise_deg=1e308)
    with pytest.raises(ValueError, match=r"spread_deg must be in \[0, 1e\+09\] degrees"):
        f.reset(0.0, spread_deg=-1.0)


@pytest.mark.parametrize("width", [UNIFORM_SPREAD_DEG, 1e5, 1e9])
def test_a_blur_wider_than_the_circle_gives_the_uniform_belief(width):
    f = HeadingGridFilter()
    f.reset(10.0, 2.0)
    f.predict(0.0, noise_deg=width)
    np.testing.assert_allclose(f.belief, 1.0 / 360.0, rtol=1e-12)
    f.reset(10.0, spread_deg=width)
    np.testing.assert_allclose(f.belief, 1.0 / 360.0, rtol=1e-12)
    assert f.estimate().spread_deg > 1e3  # as the circular spread of a uniform belief


def test_a_grid_finer_than_any_sensor_is_refused():
    with pytest.raises(ValueError, match=r"resolution_deg must be in \[0.01, 90\]"):
        HeadingGridFilter(resolution_deg=1e-7)  # 3.6e9 bins


# ------------------------------------------------------------------ Kalman filter
@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"rate_spread_deg_per_s": 1e308}, "rate_spread_deg_per_s must be in"),
        ({"rate_noise_deg_per_s": 1e308}, "rate_noise_deg_per_s must be in"),
        ({"rate_noise_deg_per_s": float("nan")}, "rate_noise_deg_per_s must be finite"),
    ],
)
def test_kalman_rate_parameters_beyond_range_are_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        KalmanHeadingFilter(turn_rate_state=True, **kwargs)


def test_kalman_steps_and_grids_beyond_range_are_refused():
    f = KalmanHeadingFilter(turn_rate_state=True)
    with pytest.raises(ValueError, match=r"dt must be in \(0, 1e\+06\] seconds"):
        f.predict(0.0, 1.0, dt=1e308)
    with pytest.raises(ValueError, match="noise_deg"):
        f.predict(0.0, noise_deg=1e308)
    for step in (1e-300, 1e-3, 120.0):
        with pytest.raises(ValueError, match=r"grid_step_deg must be in \[0.01, 90\]"):
            f.update_from_sensor(VonMisesHeadingSensor(), 0.0, grid_step_deg=step)
    est = f.estimate()
    assert np.isfinite(est.heading_deg) and np.isfinite(est.spread_deg)


# ------------------------------------------------------------------ particle filter
def test_a_billion_particles_is_a_value_error():
    with pytest.raises(ValueError, match=r"n_particles must be an integer in \[1, 1_000_000\]"):
        ParticleFilter(10**9)
    assert ParticleFilter(MAX_PARTICLES).n_particles == MAX_PARTICLES


@pytest.mark.parametrize("value", BAD)
def test_particle_poses_beyond_range_are_refused(value):
    with pytest.raises(ValueError, match="bounds must"):
        ParticleFilter(10, bounds=(-value, value, -1.0, 1.0))
    pf = ParticleFilter(10, bounds=(-1.0, 1.0, -1.0, 1.0))
    with pytest.raises(ValueError, match="mean must"):
        pf.reset((value, 0.0, 0.0))
    with pytest.raises(ValueError, match="std must"):
        pf.reset((0.0, 0.0, 0.0), (value, 0.0, 0.0))
    with pytest.raises(ValueError, match="poses must"):
        pf.replace(np.array([0]), np.array([[value, 0.0, 0.0]]))
    assert np.all(np.isfinite(pf.particles))


# ------------------------------------------------------------------ translational filter
def test_goodness_limits_are_stated_without_a_unit():
    spots = np.array([[0.0, 0.0], [1.0, 0.0]])
    with pytest.raises(ValueError, match=r"goodness must be within ±1e\+06, got") as info:
        weighted_spot_position(spots, [1e7, 1.0])
    assert "1e+06 m" not in str(info.value)
    f = TranslationalFilter(spots)
    with pytest.raises(ValueError, match="goodness"):
        f.update([1e308, 1.0])
    with pytest.raises(ValueError, match=r"measured position must be within ±1e\+06 m"):
        f.update_position((1e7, 0.0))


def test_spots_beyond_range_are_refused():
    with pytest.raises(ValueError, match=r"spots must lie within ±1e\+06 m"):
        TranslationalFilter([[1e308, 0.0], [0.0, 0.0]])
