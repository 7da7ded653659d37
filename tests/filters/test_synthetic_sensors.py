"""The test-double sensors have the noise they claim."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.angles import circular_std, wrap180
from vc_gym.filters.sensor_protocol import HeadingSensor, PoseSensor, check_log_likelihood
from vc_gym.filters.synthetic_sensors import GaussianPoseSensor, VonMisesHeadingSensor


def test_von_mises_readings_have_the_configured_noise():
    rng = np.random.default_rng(0)
    s = VonMisesHeadingSensor(noise_deg=6.0)
    readings = np.array([s.read(350.0, rng) for _ in range(4000)])
    assert abs(wrap180(np.mean(wrap180(readings - 350.0)))) < 0.5
    assert circular_std(readings) == pytest.approx(6.0, rel=0.05)


def test_von_mises_likelihood_peaks_at_reading_and_wraps():
    s = VonMisesHeadingSensor(noise_deg=5.0)
    h = np.arange(360.0)
    ll = s.heading_log_likelihood(359.0, h)
    assert h[np.argmax(ll)] == 359.0
    assert ll[1] == pytest.approx(ll[357])  # 2 deg either side of 359, across 0


def test_outlier_model_has_a_floor():
    s = VonMisesHeadingSensor(noise_deg=1.0, outlier_prob=0.1)
    ll = s.heading_log_likelihood(0.0, np.arange(360.0))
    assert np.all(np.isfinite(ll))
    assert ll.min() == pytest.approx(np.log(0.1 / (2 * np.pi)), rel=1e-6)
    # the density integrates to one over the circle
    assert np.sum(np.exp(ll)) * np.radians(1.0) == pytest.approx(1.0, rel=1e-3)


def test_gaussian_pose_sensor():
    s = GaussianPoseSensor(pos_noise_m=0.1, heading_noise_deg=5.0)
    poses = np.array([[1.0, 2.0, 30.0], [1.1, 2.0, 30.0], [1.0, 2.0, 35.0]])
    ll = s.pose_log_likelihood(np.array([1.0, 2.0, 30.0]), poses)
    assert ll[0] == 0.0 and ll[1] == pytest.approx(-0.5) and ll[2] == pytest.approx(-0.5)
    assert isinstance(s, PoseSensor) and isinstance(VonMisesHeadingSensor(), HeadingSensor)


def test_bad_sensor_arguments():
    with pytest.raises(ValueError):
        VonMisesHeadingSensor(noise_deg=0.0)
    with pytest.raises(ValueError):
        VonMisesHeadingSensor(outlier_prob=1.0)
    with pytest.raises(ValueError):
        GaussianPoseSensor(pos_noise_m=-1)
    with pytest.raises(ValueError):
        VonMisesHeadingSensor().heading_log_likelihood(float("nan"), np.arange(3.0))
    with pytest.raises(ValueError):
        GaussianPoseSensor().pose_log_likelihood(np.array([1.0, 2.0]), np.zeros((2, 3)))


def test_check_log_likelihood():
    assert check_log_likelihood([0.0, -np.inf], 2).dtype == np.float64
    for bad in ([np.nan, 0.0], [np.inf, 0.0], [0.0]):
        with pytest.raises(ValueError):
            check_log_likelihood(bad, 2)
