"""Moved public names still import from their old place for one release, with a warning."""

from __future__ import annotations

import importlib
import sys
import warnings

import pytest


def test_baselines_is_heading_sensors_with_a_warning():
    sys.modules.pop("vc_gym.baselines", None)
    with pytest.warns(DeprecationWarning, match="vc_gym.heading_sensors"):
        old = importlib.import_module("vc_gym.baselines")
    import vc_gym.heading_sensors as new

    assert old.make_sensor is new.make_sensor and old.__all__ == new.__all__


@pytest.mark.parametrize("package", ["vc_gym.heading_sensors", "vc_gym.baselines"])
def test_sector_colour_compass_is_sector_color_compass_with_a_warning(package):
    from vc_gym.heading_sensors import SectorColorCompass

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # vc_gym.baselines itself
        module = importlib.import_module(package)
    with pytest.warns(DeprecationWarning, match="SectorColorCompass"):
        assert module.SectorColourCompass is SectorColorCompass
    assert "SectorColourCompass" not in module.__all__


@pytest.mark.parametrize("name", ["AiboRoomEnv", "Quadruped", "build_scene", "SCENES"])
def test_sim_names_from_envs_warn_and_are_the_same(name):
    import vc_gym.envs
    import vc_gym.sim

    with pytest.warns(DeprecationWarning, match=f"vc_gym.sim.{name}"):
        assert getattr(vc_gym.envs, name) is getattr(vc_gym.sim, name)


def test_an_unknown_name_is_still_an_attribute_error():
    import vc_gym.envs

    with pytest.raises(AttributeError, match="no_such_name"):
        vc_gym.envs.no_such_name  # noqa: B018
