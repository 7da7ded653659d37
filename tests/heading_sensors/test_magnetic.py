"""The magnetometer baseline: true heading + noise + a disturbance that depends on position."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.angles import wrap180
from vc_gym.filters import HeadingGridFilter
from vc_gym.heading_sensors.magnetic import DisturbanceSource, NoisyMagneticCompass


def test_undisturbed_noiseless_reading_is_the_truth():
    m = NoisyMagneticCompass(noise_deg=0.0)
    rng = np.random.default_rng(0)
    for theta in (0.0, 12.5, 359.7, -90.0):
        z = m.read((1.0, 2.0, theta), rng)
        assert abs(wrap180(z - theta)) < 1e-9
        est = m.estimate(z)
        assert abs(wrap180(est.heading_deg - theta)) < 0.05
        assert est.spread_deg == pytest.approx(1.0, rel=0.05)  # model sigma floor of 1 deg


def test_noise_has_the_configured_spread():
    m = NoisyMagneticCompass(noise_deg=5.0)
    rng = np.random.default_rng(1)
    errs = [wrap180(m.read((0.0, 0.0, 30.0), rng) - 30.0) for _ in range(4000)]
    assert np.std(errs) == pytest.approx(5.0, rel=0.06)
    assert abs(np.mean(errs)) < 0.3


def test_disturbance_peaks_at_the_source_and_fades():
    src = DisturbanceSource(1.0, -1.0, 30.0, 0.5)
    m = NoisyMagneticCompass(noise_deg=0.0, sources=[src])
    assert m.disturbance_deg(1.0, -1.0) == pytest.approx(30.0)
    assert m.disturbance_deg(1.5, -1.0) == pytest.approx(30.0 * np.exp(-0.5))
    assert abs(m.disturbance_deg(4.0, 3.0)) < 1e-6
    # near the source the reading is confidently wrong: the model knows only the noise
    est = m.estimate(m.read((1.0, -1.0, 100.0), np.random.default_rng(2)))
    assert abs(wrap180(est.heading_deg - 130.0)) < 0.05 and est.spread_deg < 2.0


def test_random_field_is_seeded_and_inside_the_bounds():
    a = NoisyMagneticCompass.random_field((-3, 3, -2, 2), np.random.default_rng(5))
    b = NoisyMagneticCompass.random_field((-3, 3, -2, 2), np.random.default_rng(5))
    assert a.sources == b.sources and len(a.sources) == 4
    for s in a.sources:
        assert -3 <= s.x_m <= 3 and -2 <= s.y_m <= 2 and 12.5 <= abs(s.deviation_deg) <= 25.0


def test_plugs_into_the_heading_grid_filter():
    m = NoisyMagneticCompass(noise_deg=2.0)
    f = HeadingGridFilter(rule="bayes")
    f.reset(0.0, 180.0)
    rng = np.random.default_rng(3)
    for _ in range(10):
        f.update(m, m.read((0.0, 0.0, 250.0), rng))
    assert abs(wrap180(f.estimate().heading_deg - 250.0)) < 3.0


@pytest.mark.parametrize(
    "kwargs",
    [
        {"noise_deg": -1.0},
        {"noise_deg": float("nan")},
        {"noise_deg": 181.0},
        {"model_noise_deg": 0.0},
        {"heading_step_deg": 7.0},
        {"sources": [(0.0, 0.0, 10.0, 1.0)]},
    ],
)
def test_bad_parameters_are_refused(kwargs):
    with pytest.raises(ValueError):
        NoisyMagneticCompass(**kwargs)


@pytest.mark.parametrize(
    "source", [(0, 0, 200.0, 1.0), (0, 0, 10.0, 0.0), (float("inf"), 0, 10.0, 1.0)]
)
def test_bad_sources_are_refused(source):
    with pytest.raises(ValueError):
        DisturbanceSource(*source)


def test_bad_readings_and_poses_are_refused():
    m = NoisyMagneticCompass()
    rng = np.random.default_rng(0)
    for bad in (float("nan"), True, "north", None):
        with pytest.raises(ValueError):
            m.log_likelihood(bad)
    for pose in ((0.0, 0.0), (0.0, float("inf"), 0.0), "home"):
        with pytest.raises(ValueError):
            m.read(pose, rng)
    with pytest.raises(ValueError, match="Generator"):
        m.read((0.0, 0.0, 0.0), np.random.RandomState(0))


def test_a_magnetometer_in_the_head_is_an_image_compass_reading_the_head_pose():
    from vc_gym.compass import Camera, ImageCompass
    from vc_gym.heading_sensors import MagnetometerCompass
    from vc_gym.localization import CompassHeadingSensor

    head = [0.0, 0.0, 100.0]
    m = MagnetometerCompass(
        NoisyMagneticCompass(noise_deg=0.0), lambda: head, np.random.default_rng(0)
    )
    assert isinstance(m, ImageCompass)
    frame = np.zeros((4, 4, 3), np.uint8)  # not looked at
    assert m.estimate(frame, Camera()).heading_deg == pytest.approx(100.0, abs=0.05)
    head[2] = 220.0  # the head turned: the next reading follows it
    assert m.estimate(frame, Camera()).heading_deg == pytest.approx(220.0, abs=0.05)
    # a tracker asks for body headings: the head pan is taken off
    ll = CompassHeadingSensor(m, Camera()).heading_log_likelihood(frame, np.arange(360.0), 20.0)
    assert int(np.argmax(ll)) == 200
    with pytest.raises(ValueError, match="NoisyMagneticCompass"):
        MagnetometerCompass("north", lambda: head, np.random.default_rng(0))
    with pytest.raises(ValueError, match="callable"):
        MagnetometerCompass(NoisyMagneticCompass(), head, np.random.default_rng(0))
