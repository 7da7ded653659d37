"""Tests of vc_gym.sim.scenes.furniture: the shared pieces of furniture and paint."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.sim.scenes import furniture


def test_wall_colours_is_a_deprecated_alias_of_wall_colors():
    with pytest.warns(DeprecationWarning, match="wall_colors"):
        assert furniture.wall_colours is furniture.wall_colors


def test_canonical_walls_share_the_canonical_paint():
    class _Builder:  # wall_colors reads only the builder's choices and generator
        choices = type("Choices", (), {"randomize": False})()
        rng = np.random.default_rng(0)

    paint = furniture.wall_colors(_Builder(), (10, 20, 30))
    assert set(paint) == set("ENWS")
    for rgb in paint.values():
        np.testing.assert_array_equal(rgb, np.float32([10, 20, 30]))
