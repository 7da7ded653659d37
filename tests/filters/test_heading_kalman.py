"""The UKF heading filter: convergence, wrap-around, tracking, sensor updates, validation."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from filterpy.kalman import UnscentedKalmanFilter
from hypothesis import given, settings
from hypothesis import strategies as st

from vc_gym.angles import wrap180
from vc_gym.filters.estimates import HeadingEstimate
from vc_gym.filters.heading_kalman import KalmanHeadingFilter
from vc_gym.filters.synthetic_sensors import VonMisesHeadingSensor


def err(a: float, b: float) -> float:
    return abs(wrap180(a - b))


class ConstSensor:
    """A heading sensor that answers the same value for every heading."""

    def __init__(self, value: float):
        self.value = value

    def heading_log_likelihood(self, observation, headings_deg):
        return np.full(len(headings_deg), self.value)


# ------------------------------------------------------------------ behaviour


def test_converges_to_constant_heading():
    rng = np.random.default_rng(1)
    sensor = VonMisesHeadingSensor(noise_deg=5.0)
    f = KalmanHeadingFilter()  # default: 0 deg, no idea (180 deg spread)
    truth = 123.0
    for _ in range(50):
        f.predict(0.0, noise_deg=0.1)
        f.update(sensor.read(truth, rng), 5.0)
    est = f.estimate()
    assert isinstance(est, HeadingEstimate)
    assert err(est.heading_deg, truth) < 2.0
    assert est.spread_deg < 1.5  # ~5/sqrt(50) plus the process noise


def test_crossing_zero_is_tracked_without_jumps():
    rng = np.random.default_rng(2)
    sensor = VonMisesHeadingSensor(noise_deg=3.0)
    truth = 340.0
    f = KalmanHeadingFilter(truth, 5.0)
    errors, states = [], []
    for _ in range(40):  # 340 -> 20 deg in 1 deg steps, through 0
        turn = 1.0
        truth = (truth + turn) % 360.0
        f.predict(turn + rng.normal(0.0, 0.2), noise_deg=0.5)
        f.update(sensor.read(truth, rng), 3.0)
        est = f.estimate()
        errors.append(err(est.heading_deg, truth))
        states.append(float(f.ukf.x[0]))
    assert max(errors) < 7.0  # ~3 posterior sigmas; a wrap bug would give ~180 or ~360
    assert all(0.0 <= s < 360.0 for s in states)
    assert any(s < 30.0 for s in states) and any(s > 330.0 for s in states)
    assert err(f.estimate().heading_deg, 20.0) < 7.0


@pytest.mark.parametrize(("prior", "reading"), [(359.0, 1.0), (1.0, 359.0), (179.0, 181.0)])
def test_innovation_takes_the_short_way(prior, reading):
    f = KalmanHeadingFilter(prior, 10.0)
    f.update(reading, 10.0)
    mid = (prior + wrap180(reading - prior) / 2.0) % 360.0
    assert err(f.estimate().heading_deg, mid) < 1e-6
    assert f.ukf.y[0] == pytest.approx(wrap180(reading - prior))
    assert f.estimate().spread_deg == pytest.approx(10.0 / math.sqrt(2.0))


def test_wide_initial_belief_is_kept_by_predict_and_taken_over_by_a_reading():
    # a naive atan2 mean with the negative central sigma weight would flip this to 210
    f = KalmanHeadingFilter(30.0, 180.0)
    f.predict(0.0, noise_deg=0.0)
    assert err(f.estimate().heading_deg, 30.0) < 1e-9
    assert f.estimate().spread_deg == pytest.approx(180.0)
    f.update(210.0, 5.0)  # exactly opposite
    assert err(f.estimate().heading_deg, 210.0) < 0.2  # K = 180² / (180² + 5²)
    assert f.estimate().spread_deg == pytest.approx(5.0, rel=1e-3)


def test_tracks_turning_robot_with_biased_noisy_odometry():
    rng = np.random.default_rng(3)
    sensor = VonMisesHeadingSensor(noise_deg=5.0)
    truth = 10.0
    f = KalmanHeadingFilter(truth, 10.0)
    errors = []
    for k in range(300):
        turn = 4.0 * math.sin(k / 30.0) + 2.0
        truth = (truth + turn) % 360.0
        odo = 1.1 * turn + rng.normal(0.0, 0.5)  # 10 % scale error
        f.predict(odo, noise_deg=1.0 + 0.1 * abs(odo))
        f.update(sensor.read(truth, rng), 5.0)
        errors.append(err(f.estimate().heading_deg, truth))
        assert 0.0 <= f.ukf.x[0] < 360.0
    assert np.mean(errors) < 3.0


def test_turn_rate_state_learns_the_rate_without_odometry():
    rng = np.random.default_rng(4)
    sensor = VonMisesHeadingSensor(noise_deg=5.0)
    truth, rate, dt = 300.0, 12.0, 0.5
    f = KalmanHeadingFilter(truth, 10.0, turn_rate_state=True, rate_noise_deg_per_s=0.5)
    errors = []
    for _ in range(200):
        truth = (truth + rate * dt) % 360.0
        f.predict(0.0, noise_deg=0.5, dt=dt)
        f.update(sensor.read(truth, rng), 5.0)
        errors.append(err(f.estimate().heading_deg, truth))
        assert 0.0 <= f.ukf.x[0] < 360.0
    assert f.turn_rate_deg_per_s == pytest.approx(rate, abs=1.5)
    assert np.mean(errors[50:]) < 3.0


def test_update_from_sensor_matches_the_reading():
    rng = np.random.default_rng(5)
    sensor = VonMisesHeadingSensor(noise_deg=5.0)
    f = KalmanHeadingFilter(0.0, 180.0)
    for truth in (3.0, 200.0, 358.5):
        reading = sensor.read(truth, rng)
        meas = f.update_from_sensor(sensor, reading)
        assert err(meas.heading_deg, reading) < 0.05
        assert meas.spread_deg == pytest.approx(5.0, rel=0.02)
        assert 0.0 <= meas.heading_deg < 360.0
    # a coarser grid and a very sharp sensor: spread floored at one bin's spread
    sharp = VonMisesHeadingSensor(noise_deg=0.1)
    meas = f.update_from_sensor(sharp, 45.0, grid_step_deg=4.5)
    assert err(meas.heading_deg, 45.0) < 1e-6
    assert meas.spread_deg == pytest.approx(4.5 / math.sqrt(12.0))


def test_update_from_sensor_same_as_update_with_its_measurement():
    sensor = VonMisesHeadingSensor(noise_deg=8.0)
    a, b = KalmanHeadingFilter(350.0, 20.0), KalmanHeadingFilter(350.0, 20.0)
    meas = a.update_from_sensor(sensor, 12.0, grid_step_deg=0.5)
    b.update(meas.heading_deg, meas.spread_deg)
    assert a.estimate() == b.estimate()


def test_all_minus_inf_warns_and_leaves_state_unchanged():
    f = KalmanHeadingFilter(77.0, 9.0)
    x, P = f.ukf.x.copy(), f.ukf.P.copy()
    with pytest.warns(RuntimeWarning, match="every heading"):
        meas = f.update_from_sensor(ConstSensor(-np.inf), None)
    assert meas.spread_deg == math.inf
    assert meas.heading_deg == pytest.approx(77.0)
    np.testing.assert_array_equal(f.ukf.x, x)
    np.testing.assert_array_equal(f.ukf.P, P)


def test_flat_likelihood_and_infinite_spread_are_no_ops():
    f = KalmanHeadingFilter(77.0, 9.0)
    before = f.estimate()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        meas = f.update_from_sensor(ConstSensor(-3.0), None)
        f.update(200.0, math.inf)
        f.update(200.0, 1e200)  # variance overflows: treated as inf
    assert meas.spread_deg == math.inf
    assert f.estimate() == before
    f.update(200.0, 1e6)  # huge but finite: applied, moves almost nothing
    assert err(f.estimate().heading_deg, 77.0) < 1e-6


def test_long_prediction_caps_the_spread():
    f = KalmanHeadingFilter(10.0, 1.0)
    for _ in range(20):
        f.predict(5.0, noise_deg=200.0)
    est = f.estimate()
    assert est.spread_deg == pytest.approx(KalmanHeadingFilter.MAX_SPREAD_DEG)
    assert err(est.heading_deg, 110.0) < 1e-9
    f.update(300.0, 2.0)
    assert err(f.estimate().heading_deg, 300.0) < 0.01


def test_reset_and_ukf_property():
    f = KalmanHeadingFilter(turn_rate_state=True)
    assert isinstance(f.ukf, UnscentedKalmanFilter)
    f.update(100.0, 2.0)
    f.predict(3.0, 1.0, dt=0.1)
    f.reset(-30.0, 4.0)
    est = f.estimate()
    assert est.heading_deg == pytest.approx(330.0)
    assert est.spread_deg == pytest.approx(4.0)
    assert f.turn_rate_deg_per_s == 0.0
    assert KalmanHeadingFilter().turn_rate_deg_per_s is None


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    st.floats(-1e4, 1e4),
    st.lists(
        st.tuples(st.floats(-720, 720), st.floats(0, 30), st.floats(-1e4, 1e4), st.floats(0.1, 90)),
        min_size=1,
        max_size=15,
    ),
)
def test_heading_always_in_range_and_spread_shrinks_on_update(h0, steps):
    f = KalmanHeadingFilter(h0, 180.0)
    for turn, noise, z, spread in steps:
        f.predict(turn, noise)
        assert 0.0 <= f.ukf.x[0] < 360.0
        before = f.estimate().spread_deg
        f.update(z, spread)
        est = f.estimate()
        assert 0.0 <= f.ukf.x[0] < 360.0 and 0.0 <= est.heading_deg < 360.0
        assert est.spread_deg <= before * (1 + 1e-9)
        assert est.spread_deg <= spread * (1 + 1e-9)


# ------------------------------------------------------------------ validation


@pytest.mark.parametrize(
    "call",
    [
        lambda f: f.update(math.nan, 5.0),
        lambda f: f.update(math.inf, 5.0),
        lambda f: f.update(10.0, math.nan),
        lambda f: f.update(10.0, 0.0),
        lambda f: f.update(10.0, -1.0),
        lambda f: f.update(10.0, 1e-200),
        lambda f: f.update(20.0, 1e-160),  # must not leave the filter failing on every call
        lambda f: f.update(1e300, 1.0),
        lambda f: f.predict(10.0, noise_deg=1e155),  # nor must this one
        lambda f: f.predict(1e300),
        lambda f: f.predict(math.nan),
        lambda f: f.predict(1.0, noise_deg=-0.1),
        lambda f: f.predict(1.0, noise_deg=math.inf),
        lambda f: f.predict(1.0, dt=0.0),
        lambda f: f.predict(1.0, dt=-1.0),
        lambda f: f.reset(math.nan),
        lambda f: f.reset(0.0, 0.0),
        lambda f: f.reset(0.0, math.inf),
        lambda f: f.reset(0.0, 400.0),
        lambda f: f.update_from_sensor(VonMisesHeadingSensor(), 0.0, grid_step_deg=7.0),
        lambda f: f.update_from_sensor(VonMisesHeadingSensor(), 0.0, grid_step_deg=0.0),
        lambda f: f.update_from_sensor(ConstSensor(math.nan), 0.0),
        lambda f: f.update_from_sensor(ConstSensor(math.inf), 0.0),
        lambda f: f.update_from_sensor(VonMisesHeadingSensor(), math.nan),
    ],
)
def test_bad_input_raises_value_error_and_keeps_state(call):
    f = KalmanHeadingFilter(42.0, 3.0)
    before = f.estimate()
    with pytest.raises(ValueError):
        call(f)
    assert f.estimate() == before
    f.predict(5.0)  # and the filter still works
    f.update(47.0, 2.0)
    assert abs(wrap180(f.estimate().heading_deg - 47.0)) < 2.0


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda f: f.update(20.0, 1e-160), "spread_deg must be >="),
        (lambda f: f.predict(10.0, noise_deg=1e155), "noise_deg must be within"),
    ],
)
def test_a_vanishing_spread_or_a_huge_noise_names_its_limit(call, message):
    f = KalmanHeadingFilter(10.0, 5.0)
    with pytest.raises(ValueError, match=message):
        call(f)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"spread_deg": -1.0},
        {"heading_deg": math.inf},
        {"turn_rate_state": True, "rate_spread_deg_per_s": 0.0},
        {"turn_rate_state": True, "rate_noise_deg_per_s": -1.0},
    ],
)
def test_bad_constructor_arguments(kwargs):
    with pytest.raises(ValueError):
        KalmanHeadingFilter(**kwargs)


def test_non_sensor_is_a_type_error():
    with pytest.raises(TypeError, match="heading_log_likelihood"):
        KalmanHeadingFilter().update_from_sensor(object(), 0.0)
