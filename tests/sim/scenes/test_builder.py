"""Tests of vc_gym.sim.scenes.builder: the Builder's layout choices and bodies."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.sim.scenes import Builder, Draw, box


@pytest.mark.parametrize("randomize", [False, True])
def test_choices_follow_randomize_and_share_the_rng(bc, randomize):
    rng = np.random.default_rng(0)
    b = Builder(bc, rng, randomize)
    assert isinstance(b.choices, Draw)
    assert b.choices.randomize is randomize and b.choices.rng is rng is b.rng


def test_var_is_a_deprecated_alias_of_choices(bc):
    b = Builder(bc, np.random.default_rng(0), True)
    with pytest.warns(DeprecationWarning, match="Builder.choices"):
        assert b.var is b.choices


def test_low_solid_furniture_is_an_obstacle(bc):
    b = Builder(bc, np.random.default_rng(0), False)
    b.solid([box(0.0, 1.0, 2.0, 3.0, 0.0, 0.5, (100, 100, 100))])
    b.solid([box(0.0, 1.0, 2.0, 3.0, 1.0, 1.5, (100, 100, 100))])  # above the robot
    assert len(b.bodies) == 2 and bc.getNumBodies() == 2
    assert b.obstacles == [(0.0, 1.0, 2.0, 3.0)]
