"""SessionLight: the light of a session from its frames' gains."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.exposure import GAIN_STEP_STOPS, MAX_GAIN_STOPS, SessionLight, rounded_gain


def test_a_session_without_frames_is_at_the_fitting_light():
    assert SessionLight().gain == 1.0
    assert len(SessionLight()) == 0


def test_the_gain_is_the_median_in_stops_rounded_to_a_third():
    light = SessionLight(window=None)
    # content moves single frames by a stop or two; the median is the light
    for g in (0.5, 1.1, 0.95, 4.0, 1.05):
        light.update(g)
    assert light.gain == 1.0
    light.reset()
    for g in (2.2, 1.9, 0.7, 2.0, 8.0):
        light.update(g)
    assert light.gain == 2.0
    # 1.3 stops lies nearer 4/3 than 1
    assert SessionLight().update(2.0**1.3) == pytest.approx(2.0 ** (4 * GAIN_STEP_STOPS))


def test_the_window_keeps_the_newest_frames():
    light = SessionLight(window=3)
    for g in (4.0, 4.0, 4.0, 1.0, 1.0):
        light.update(g)
    assert len(light) == 3
    assert light.gain == 1.0  # the light went back up: two of the last three say so


def test_frames_without_a_level_say_nothing_about_the_light():
    light = SessionLight()
    for g in (2.0, math.inf, 0.0, -1.0, math.nan):
        light.update(g)
    assert len(light) == 1 and light.gain == 2.0


def test_gains_are_bounded_to_eight_stops():
    light = SessionLight()
    light.update(1e12)
    assert light.gain == pytest.approx(2.0**MAX_GAIN_STOPS)


@pytest.mark.parametrize("window", [0, -2, 1.5, "10", True])
def test_impossible_windows_are_refused(window):
    with pytest.raises(ValueError, match="window"):
        SessionLight(window)


def test_window_accepts_numpy_ints():
    assert SessionLight(np.int64(5)).window == 5


def test_rounded_gain_is_a_whole_number_of_thirds_of_a_stop():
    assert rounded_gain(1.1) == 1.0
    assert rounded_gain(2.0**1.3) == pytest.approx(2.0 ** (4 * GAIN_STEP_STOPS))
    assert rounded_gain(1e12) == pytest.approx(2.0**MAX_GAIN_STOPS)


def test_a_whole_session_at_once_is_the_same_as_frame_by_frame():
    gains = [2.2, 1.9, 0.7, 2.0, 8.0, float("inf")]
    light = SessionLight(window=None)
    for g in gains:
        light.update(g)
    assert SessionLight.of(gains) == light.gain == 2.0
    assert SessionLight.of([]) == 1.0
