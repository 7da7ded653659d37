"""Tests of vc_gym.sim.scenes.choices: canonical or drawn layout choices."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.sim.scenes import Draw


def test_canonical_choices_draw_nothing():
    rng = np.random.default_rng(0)
    d = Draw(rng, randomize=False)
    assert d.randomize is False
    assert d.uniform(1.5, 0.0, 1.0) == 1.5
    assert d.integers(3, 0, 9) == 3
    assert d.choice("a", ["b", "c"]) == "a"
    assert d.chance(True, 0.0) is True
    np.testing.assert_array_equal(d.color((10, 20, 30)), np.float32([10, 20, 30]))
    assert rng.uniform() == np.random.default_rng(0).uniform()  # the generator is untouched


def test_randomised_choices_draw_from_the_ranges():
    d = Draw(np.random.default_rng(1), randomize=True)
    assert d.randomize is True
    assert 0.0 <= d.uniform(5.0, 0.0, 1.0) < 1.0
    assert d.integers(100, 2, 2) == 2  # both ends included
    assert d.choice("a", ["b"]) == "b"
    assert d.chance(True, 0.0) is False


def test_on_is_a_deprecated_alias_of_randomize():
    d = Draw(np.random.default_rng(0), randomize=True)
    with pytest.warns(DeprecationWarning, match="Draw.randomize"):
        assert d.on is d.randomize is True
    with pytest.warns(DeprecationWarning, match="Draw.randomize"):
        d.on = False
    assert d.randomize is False


@pytest.mark.parametrize("randomize", [False, True])
def test_colour_is_a_deprecated_alias_of_color(randomize):
    new = Draw(np.random.default_rng(3), randomize=randomize)
    old = Draw(np.random.default_rng(3), randomize=randomize)
    with pytest.warns(DeprecationWarning, match="Draw.color"):
        rgb = old.colour((10, 20, 30), dh=0.5)
    np.testing.assert_array_equal(rgb, new.color((10, 20, 30), dh=0.5))
    assert old.rng.uniform() == new.rng.uniform()  # the same draws
