"""HeadingGridFilter with synthetic sensors of known noise."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from vc_gym.angles import wrap180
from vc_gym.filters.heading_grid import HeadingGridFilter, mixing_lambda
from vc_gym.filters.synthetic_sensors import VonMisesHeadingSensor


def test_converges_from_uniform_prior():
    rng = np.random.default_rng(0)
    sensor = VonMisesHeadingSensor(noise_deg=10.0)
    f = HeadingGridFilter(rule="bayes")
    assert f.estimate().spread_deg > 100  # uniform: no information
    for _ in range(30):
        f.update(sensor, sensor.read(123.0, rng))
    est = f.estimate()
    assert abs(wrap180(est.heading_deg - 123.0)) < 4.0
    assert est.spread_deg < 10.0 / math.sqrt(30) * 2


@pytest.mark.parametrize("rule", ["mixing", "bayes"])
def test_tracks_turning_robot_with_noisy_odometry(rule):
    rng = np.random.default_rng(1)
    sensor = VonMisesHeadingSensor(noise_deg=8.0)
    f = HeadingGridFilter(rule=rule, dt_s=0.1)
    f.reset(10.0, 5.0)
    truth, errs = 10.0, []
    for _ in range(300):
        turn = 3.0
        truth += turn
        odo = turn * 1.1 + rng.normal(0.0, 0.5)  # 10 % scale error plus noise
        f.predict(odo, noise_deg=1.0)
        f.update(sensor, sensor.read(truth, rng))
        errs.append(abs(wrap180(f.estimate().heading_deg - truth)))
    assert np.mean(errs[20:]) < 5.0, np.mean(errs[20:])


def test_wrap_around_zero():
    f = HeadingGridFilter(rule="bayes")
    f.reset(358.0, 2.0)
    for _ in range(4):
        f.predict(1.0)
    assert abs(wrap180(f.estimate().heading_deg - 2.0)) < 0.5
    b = f.belief
    assert b[0:6].sum() > 0.5  # mass sits just above 0, not spread around 180


def test_sub_bin_shift_interpolates():
    f = HeadingGridFilter(resolution_deg=1.0)
    f.reset(100.0, 0.0)
    f.predict(0.25)
    b = f.belief
    assert b[100] == pytest.approx(0.75) and b[101] == pytest.approx(0.25)
    assert abs(f.estimate().heading_deg - 100.25) < 1e-4  # circular, not linear, mean


def test_blur_matches_noise():
    f = HeadingGridFilter(resolution_deg=1.0)
    f.reset(50.0, 0.0)
    f.predict(0.0, noise_deg=7.0)
    assert f.estimate().spread_deg == pytest.approx(7.0, rel=0.02)
    assert abs(f.estimate().heading_deg - 50.0) < 1e-6


def test_mixing_and_bayes_differ_as_documented():
    sensor = VonMisesHeadingSensor(noise_deg=5.0)
    prior = HeadingGridFilter(rule="bayes")
    prior.reset(90.0, 30.0)
    bayes = HeadingGridFilter(rule="bayes")
    bayes.set_belief(prior.belief)
    bayes.update(sensor, 100.0)
    mixing = HeadingGridFilter(rule="mixing", half_life_s=0.3, dt_s=0.1)
    mixing.set_belief(prior.belief)
    mixing.update(sensor, 100.0)
    lam = mixing_lambda(0.3, 0.1)
    # mixing = λ · Bayes posterior + (1 - λ) · prior  (paper eq. 24)
    np.testing.assert_allclose(mixing.belief, lam * bayes.belief + (1 - lam) * prior.belief)
    assert mixing.estimate().spread_deg > bayes.estimate().spread_deg
    # with λ = 1 (dt much longer than the half-life) the two rules coincide
    mixing.set_belief(prior.belief)
    mixing.update(sensor, 100.0, dt_s=1e6)
    np.testing.assert_allclose(mixing.belief, bayes.belief, atol=1e-12)


def test_half_life_replaces_half_the_belief():
    lam = mixing_lambda(0.3, 0.03)
    assert (1 - lam) ** 10 == pytest.approx(0.5)


def test_all_minus_inf_keeps_belief():
    class Blind:
        def heading_log_likelihood(self, obs, headings):
            return np.full(headings.shape, -np.inf)

    f = HeadingGridFilter()
    f.reset(45.0, 10.0)
    before = f.belief
    with pytest.warns(RuntimeWarning, match="unchanged"):
        assert f.update(Blind(), None) is False
    np.testing.assert_array_equal(f.belief, before)


def test_sensor_contradicting_belief_restarts_from_sensor():
    f = HeadingGridFilter(rule="bayes")
    f.set_belief(np.eye(360)[10])  # certain about 10 deg
    ll = np.full(360, -np.inf)
    ll[200] = 0.0  # the sensor is certain about 200 deg
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        f.update_log_likelihood(ll)
    assert f.map_heading() == 200.0


@pytest.mark.parametrize(
    "bad", [np.full(360, np.nan), np.full(359, 0.0), np.full(360, np.inf), np.zeros((360, 1))]
)
def test_bad_likelihoods_raise(bad):
    f = HeadingGridFilter()
    with pytest.raises(ValueError):
        f.update_log_likelihood(bad)


def test_bad_arguments_raise():
    with pytest.raises(ValueError):
        HeadingGridFilter(resolution_deg=0.7)
    with pytest.raises(ValueError):
        HeadingGridFilter(rule="magic")
    with pytest.raises(ValueError):
        HeadingGridFilter(half_life_s=0.0)
    f = HeadingGridFilter()
    with pytest.raises(ValueError):
        f.predict(1.0, noise_deg=-1.0)
    with pytest.raises(ValueError):
        f.predict(float("nan"))
    with pytest.raises(ValueError):
        f.update(object(), None)
    with pytest.raises(ValueError):
        f.set_belief(np.zeros(360))
