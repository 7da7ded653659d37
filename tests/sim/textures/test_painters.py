"""Tests of vc_gym.sim.textures.painters: procedural posters (and the photos they mix in)."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.sim import textures


def test_procedural_posters_are_coarse_seeded_rgb():
    for style in textures.POSTER_STYLES:
        a = textures.procedural_poster(np.random.default_rng(3), (90, 60), style)
        b = textures.procedural_poster(np.random.default_rng(3), (90, 60), style)
        assert a.shape == (90, 60, 3) and a.dtype == np.uint8
        np.testing.assert_array_equal(a, b)
        assert a.std() > 5.0
    with pytest.raises(ValueError, match="blocks"):
        textures.procedural_poster(np.random.default_rng(0), 64, "plaid")
    with pytest.raises(ValueError, match="16"):
        textures.procedural_poster(np.random.default_rng(0), 8)
    photos = textures.photo_posters()
    assert photos and all(p.ndim == 3 and p.shape[2] == 3 for p in photos)


@pytest.mark.parametrize(
    "paint",
    [
        lambda rng: textures.outdoor_view(rng),
        lambda rng: textures.desktop_screen(rng),
        lambda rng: textures.ad_board(rng),
        lambda rng: textures.facade(rng, 9.0, 7.0),
        lambda rng: textures.sky_band(rng, 256, 64),
        lambda rng: textures.sky_cap(rng, (120, 160, 220), 32),
        lambda rng: textures.poster_image(rng, 1.5),
    ],
)
def test_every_painter_gives_seeded_rgb(paint):
    a, b = paint(np.random.default_rng(4)), paint(np.random.default_rng(4))
    assert a.ndim == 3 and a.shape[2] == 3 and a.dtype == np.uint8
    np.testing.assert_array_equal(a, b)
