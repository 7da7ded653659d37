"""Sensor settings have upper bounds too, so a saved sensor cannot flatten its likelihood."""

from __future__ import annotations

import pytest

from vc_gym.heading_sensors import FeatureCompass, ImageDifferenceCompass, SectorColorCompass


@pytest.mark.parametrize(
    ("make", "name"),
    [
        (lambda: SectorColorCompass(temperature=1e300), "temperature"),
        (lambda: SectorColorCompass(smoothing=1e300), "smoothing"),
        (lambda: SectorColorCompass(min_sigma=1e300), "min_sigma"),
        (lambda: SectorColorCompass(prior_sigma=1e300), "prior_sigma"),
        (lambda: SectorColorCompass(prior_weight=1e300), "prior_weight"),
        (lambda: SectorColorCompass(gain_sigma=1e300), "gain_sigma"),
        (lambda: SectorColorCompass(model="histogram", n_bins=10**9), "n_bins"),
        (lambda: ImageDifferenceCompass(noise_std=1e300), "noise_std"),
        (lambda: FeatureCompass(n_features=10**9), "n_features"),
        (lambda: FeatureCompass(max_keypoints=10**12), "max_keypoints"),
    ],
)
def test_absurd_sensor_settings_are_refused_naming_them(make, name):
    with pytest.raises(ValueError, match=name):
        make()
