"""The real VisualCompass plugged into the filters, on synthetic panoramas."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.angles import wrap180
from vc_gym.compass import Camera
from vc_gym.filters.heading_grid import HeadingGridFilter
from vc_gym.filters.sensor_protocol import HeadingSensor, PoseSensor
from vc_gym.localization import CompassHeadingSensor
from vc_gym.worlds.panorama import render_view


def turn_sequence(rng, steps=120):
    """True headings of a robot turning left, pausing and turning back right."""
    rates = np.concatenate([np.full(50, 6.0), np.zeros(20), np.full(50, -4.0)])[:steps]
    return 200.0 + np.cumsum(rates + rng.normal(0.0, 0.3, rates.size)), rates


@pytest.mark.parametrize("rule", ["mixing", "bayes"])
def test_grid_filter_with_compass_tracks_turns(room_pano, room_compass, rule):
    rng = np.random.default_rng(5)
    truth, rates = turn_sequence(rng)
    sensor = CompassHeadingSensor(room_compass, Camera())
    f = HeadingGridFilter(rule=rule, dt_s=1 / 30)
    errs = []
    prev = truth[0] - rates[0]
    for heading in truth:
        odo = (heading - prev) * 1.05 + rng.normal(0.0, 0.5)
        prev = heading
        f.predict(odo, noise_deg=1.0)
        img = render_view(room_pano, Camera(yaw_deg=float(heading)))
        f.update(sensor, img)
        errs.append(abs(wrap180(f.estimate().heading_deg - heading)))
    assert np.mean(errs[10:]) < 5.0, np.round(errs, 1)


def test_compass_sensor_satisfies_protocols(room_compass):
    sensor = CompassHeadingSensor(room_compass)
    assert isinstance(sensor, HeadingSensor) and isinstance(sensor, PoseSensor)


def test_head_pan_is_subtracted(room_pano, room_compass):
    sensor = CompassHeadingSensor(room_compass)
    headings = np.arange(360.0)
    body, pan = 80.0, 30.0  # head turned 30 deg left: the camera looks at 110 deg
    img = render_view(room_pano, Camera(yaw_deg=body + pan))
    ll = sensor.heading_log_likelihood(img, headings, head_pan_deg=pan)
    assert abs(wrap180(headings[np.argmax(ll)] - body)) <= 2.0


def test_compass_sensor_interpolates_between_grid_points(room_pano, room_compass):
    sensor = CompassHeadingSensor(room_compass)
    img = render_view(room_pano, Camera(yaw_deg=40.0))
    on_grid = sensor.heading_log_likelihood(img, np.arange(0.0, 360.0))
    np.testing.assert_array_equal(on_grid, room_compass.log_likelihood(img, Camera()))
    half = sensor.heading_log_likelihood(img, np.array([40.5, 359.5]))
    assert half[0] == pytest.approx(0.5 * (on_grid[40] + on_grid[41]))
    assert half[1] == pytest.approx(0.5 * (on_grid[359] + on_grid[0]))


def test_tempered_distribution_known_answers():
    from vc_gym.localization.compass_sensors import tempered_distribution

    ll = np.array([0.0, np.log(4.0), -np.inf])  # the last state ruled out
    np.testing.assert_allclose(tempered_distribution(ll, 1.0), [0.2, 0.8, 0.0])
    np.testing.assert_allclose(tempered_distribution(ll, 2.0), [1 / 3, 2 / 3, 0.0])
    assert tempered_distribution(np.full(3, -np.inf), 1.0) is None
