"""The exposure correction: reference level, frame gain and the per-heading profile."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.compass.light_gain import (
    color_fitting_levels,
    exposure_corrected,
    frame_gain_of,
    profile_log_likelihood,
    scaled_to_reference,
    step_gain,
    upper_half,
)
from vc_gym.exposure import mean_linear_level


def test_the_reference_is_read_from_the_upper_halves():
    image = np.zeros((5, 4, 3), np.uint8)
    image[:2] = 200  # the upper half (2 of 5 rows) is bright, the rest black
    assert upper_half(image).shape == (2, 4, 3)
    assert upper_half(image[:1]).shape == (1, 4, 3)  # at least one row
    assert color_fitting_levels([image]) == [mean_linear_level(image[:2])]


def test_a_frame_is_scaled_to_the_reference_level():
    pixels = np.full((4, 6, 3), 60, np.uint8)
    level = mean_linear_level(pixels)
    scaled = scaled_to_reference(pixels, level, 2 * level)
    assert mean_linear_level(scaled) == pytest.approx(2 * level, rel=0.05)
    assert scaled_to_reference(pixels, 0.0, 0.5) is pixels  # black: nothing to scale
    np.testing.assert_array_equal(exposure_corrected(pixels, "mean", 2 * level), scaled)


def test_other_modes_apply_the_given_gain():
    pixels = np.full((4, 6, 3), 60, np.uint8)
    assert exposure_corrected(pixels, "none", 0.0) is pixels
    assert exposure_corrected(pixels, "session", 0.3, gain=1.0) is pixels
    brighter = exposure_corrected(pixels, "session", 0.3, gain=2.0)
    assert mean_linear_level(brighter) == pytest.approx(2 * mean_linear_level(pixels), rel=0.05)


def test_frame_gain_is_reference_over_level():
    pixels = np.full((4, 6, 3), 100, np.uint8)
    assert frame_gain_of(pixels, 0.4) == 0.4 / mean_linear_level(pixels)
    assert frame_gain_of(np.zeros_like(pixels), 0.4) == math.inf


def test_gain_steps_are_thirds_of_a_stop():
    assert step_gain(0) == 1.0
    assert step_gain(3) == pytest.approx(2.0)
    assert step_gain(-3) == pytest.approx(0.5)


def test_each_heading_takes_the_log_likelihood_at_its_own_gain():
    steps = np.array([0, 0, 3, 3, -3])
    # the features at a gain are the gain itself; every heading scores gain * (h + 1)
    seen = []

    def features_at(gain):
        seen.append(gain)
        return np.array([gain]), np.array([1.0])

    def log_likelihood_of(features):
        return features[0][0] * np.arange(1.0, 6.0)

    ll, best_features, best = profile_log_likelihood(steps, features_at, log_likelihood_of)
    assert seen == [step_gain(-3), step_gain(0), step_gain(3)]  # one pass per gain
    np.testing.assert_array_equal(
        ll, [1.0, 2.0, 3 * step_gain(3), 4 * step_gain(3), 5 * step_gain(-3)]
    )
    assert best == 3 and best_features[0][0] == step_gain(3)


def test_colour_fitting_levels_is_a_deprecated_alias():
    from vc_gym.compass import light_gain

    with pytest.warns(DeprecationWarning, match="color_fitting_levels"):
        assert light_gain.colour_fitting_levels is color_fitting_levels
