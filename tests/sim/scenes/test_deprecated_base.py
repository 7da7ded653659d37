"""vc_gym.sim.scenes.base is a deprecated alias: each name warns and is the moved object."""

from __future__ import annotations

import pytest

import vc_gym.sim.scenes as scenes
from vc_gym.sim.scenes import base

NAMES = [
    "FLOOR_PPM", "RGB", "WALL_PPM", "Builder", "Draw", "Part", "Quad", "Room", "Scene",
    "SceneLayout", "Wall", "ball", "box", "cyl",
]  # fmt: skip


@pytest.mark.parametrize("name", NAMES)
def test_each_old_name_warns_and_returns_the_same_object(name):
    moved = f"vc_gym.sim.scenes.base.{name} moved to vc_gym.sim.scenes."
    with pytest.warns(DeprecationWarning, match=moved):
        old = getattr(base, name)
    assert old is getattr(scenes, name)


def test_from_import_warns_too():
    moved = "vc_gym.sim.scenes.base.Room moved to vc_gym.sim.scenes.rooms.Room"
    with pytest.warns(DeprecationWarning, match=moved):
        from vc_gym.sim.scenes.base import Room
    assert Room is scenes.Room


def test_unknown_names_are_attribute_errors():
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        base.nothing  # noqa: B018
