"""Tests of vc_gym.experiments.spot_sensors: teaching an image sensor at a spot."""

from __future__ import annotations

import pytest

from vc_gym.experiments import spot_sensors


def test_fit_colours_is_a_deprecated_alias_of_fit_colors():
    with pytest.warns(DeprecationWarning, match="fit_colors"):
        assert spot_sensors.fit_colours is spot_sensors.fit_colors
