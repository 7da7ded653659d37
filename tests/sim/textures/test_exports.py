"""vc_gym.sim.textures exports its painters, the store and the shared canvas and colours."""

from __future__ import annotations

import pytest

from vc_gym.sim import textures
from vc_gym.worlds import paint
from vc_gym.worlds.canvas import Canvas


def test_every_exported_name_is_there():
    assert set(textures.__all__) == {
        "Canvas", "MAP_IMAGES", "POSTER_STYLES", "SAMPLE_PHOTOS", "TEXTURE_DIR_PREFIX",
        "TextureStore", "ad_board", "desktop_screen", "facade", "hsv", "map_image",
        "outdoor_view", "photo_posters", "poster_image", "procedural_poster",
        "random_color", "sample_photo", "sky_band", "sky_cap", "smooth_noise",
    }  # fmt: skip
    for name in textures.__all__:
        assert hasattr(textures, name), name


def test_canvas_and_colours_are_the_worlds_ones():
    assert textures.Canvas is Canvas
    assert textures.hsv is paint.hsv
    assert textures.random_color is paint.random_color
    assert textures.smooth_noise is paint.smooth_noise


def test_random_colour_is_a_deprecated_alias_of_random_color():
    with pytest.warns(DeprecationWarning, match="random_color"):
        assert textures.random_colour is paint.random_color
