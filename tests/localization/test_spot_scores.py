"""Spot score vectors: the mean of the atlas' raw scores, highest for the spot the frames
were taken at, and the array checks the estimators share."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera
from vc_gym.localization import mean_spot_scores
from vc_gym.localization.spot_scores import finite_array
from vc_gym.worlds.room import render_room_view


def test_the_mean_of_the_raw_scores_is_highest_at_the_spot(synthetic_room, room_atlas):
    camera = Camera()
    east = room_atlas.names.index("east")
    x, y = room_atlas.positions[east]
    views = [render_room_view(synthetic_room, x, y, Camera(yaw_deg=a)) for a in (15.0, 135.0)]
    scores = mean_spot_scores(room_atlas, views, camera)
    assert scores.shape == (len(room_atlas),) and scores.dtype == np.float64
    expected = (room_atlas.scores(views[0], camera)[0] + room_atlas.scores(views[1], camera)[0]) / 2
    np.testing.assert_allclose(scores, expected, rtol=0, atol=1e-15)
    assert int(np.argmax(scores)) == east
    np.testing.assert_array_equal(
        mean_spot_scores(room_atlas, views[:1], camera), room_atlas.scores(views[0], camera)[0]
    )


def test_bad_atlases_and_image_lists_are_refused(room_atlas):
    image = np.zeros((48, 64, 3), np.uint8)
    with pytest.raises(ValueError, match="CompassAtlas"):
        mean_spot_scores("atlas", [image], Camera())
    for images in ([], image, None):
        with pytest.raises(ValueError, match="non-empty sequence"):
            mean_spot_scores(room_atlas, images, Camera())
    with pytest.raises(ValueError):
        mean_spot_scores(room_atlas, [np.zeros((48, 64), np.uint8)], Camera())


def test_finite_array_checks_shape_emptiness_and_finiteness():
    np.testing.assert_array_equal(finite_array("x", [[1, 2]], (None, 2)), [[1.0, 2.0]])
    assert finite_array("x", [1, 2, 3], (3,)).dtype == np.float64
    for value, shape, match in [
        ([[1, 2, 3]], (None, 2), r"x must have shape \(None, 2\)"),
        ([1, 2], (3,), "shape"),
        ([], (None,), "empty"),
        ([1.0, np.nan], (2,), "NaN"),
        ([1.0, np.inf], (2,), "finite"),
        ("abc", (None,), "array of numbers"),
    ]:
        with pytest.raises(ValueError, match=match):
            finite_array("x", value, shape)
