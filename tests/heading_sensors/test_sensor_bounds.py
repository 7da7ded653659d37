"""Sensor settings have upper bounds too, so a saved sensor cannot flatten its likelihood."""

from __future__ import annotations

import pytest

from vc_gym.heading_sensors import FeatureCompass, ImageDifferenceCompass, SectorColourCompass


@pytest.mark.parametrize(
    ("make", "name"),
    [
        (lambda: SectorColourCompass(temperature=1e300), "temperature"),
        (lambda: SectorColourCompass(smoothing=1e300), "smoothing"),
        (lambda: SectorColourCompass(min_sigma=1e300), "min_sigma"),
        (lambda: SectorColourCompass(prior_sigma=1e300), "prior_sigma"),
        (lambda: SectorColourCompass(prior_weight=1e300), "prior_weight"),
        (lambda: SectorColourCompass(gain_sigma=1e300), "gain_sigma"),
        (lambda: SectorColourCompass(model="histogram", n_bins=10**9), "n_bins"),
        (lambda: ImageDifferenceCompass(noise_std=1e300), "noise_std"),
        (lambda: FeatureCompass(n_features=10**9), "n_features"),
        (lambda: FeatureCompass(max_keypoints=10**12), "max_keypoints"),
    ],
)
def test_absurd_sensor_settings_are_refused_naming_them(make, name):
    with pytest.raises(ValueError, match=name):
        make()
