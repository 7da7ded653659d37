"""Position from a full turn's signature: exact at a calibration place, between places
when the turn is between them, and clear errors on bad input."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera
from vc_gym.localization import (
    calibrate_goodness,
    calibration_points,
    locate_by_turn_signature,
    mean_spot_scores,
)
from vc_gym.worlds.room import render_room_view

SPOTS = np.array([[x, y] for x in (-2.25, -0.75, 0.75, 2.25) for y in (-1.5, 0.0, 1.5)])
BOUNDS = (-3.0, 3.0, -2.0, 2.0)


def scores_at(xy, a, b, length):
    d = np.hypot(*(SPOTS - np.asarray(xy)).T)
    return a - b * (1.0 - np.exp(-d / length))


def test_nearest_signatures_interpolate_between_places():
    rng = np.random.default_rng(1)
    a = rng.uniform(-0.12, -0.06, len(SPOTS))
    b = rng.uniform(0.15, 0.25, len(SPOTS))
    places = calibration_points(SPOTS, BOUNDS)
    sig = np.array([scores_at(p, a, b, 0.7) for p in places])
    sigma = np.full(len(SPOTS), 0.02)
    # at a calibration place: that place exactly, with the floor spread
    mean, std = locate_by_turn_signature(sig[5], places, sig, sigma)
    np.testing.assert_allclose(mean, places[5], atol=1e-6)
    # between places: no farther than the places' spacing (0.75 m) allows, and the
    # spread says it is between places
    for true in ((-0.375, 0.0), (0.3, 0.4), (-2.6, 1.8), (1.9, -0.2)):
        mean, std = locate_by_turn_signature(scores_at(true, a, b, 0.7), places, sig, sigma)
        assert np.hypot(*(mean - true)) < 0.4 and np.max(std) > 0.1
    with pytest.raises(ValueError, match="k must"):
        locate_by_turn_signature(sig[0], places, sig, sigma, k=0)
    with pytest.raises(ValueError, match="sigma"):
        locate_by_turn_signature(sig[0], places, sig, -sigma)
    with pytest.raises(ValueError, match="shape"):
        locate_by_turn_signature(sig[0][:3], places, sig, sigma)


def test_known_weights_and_spread():
    places = np.array([[0.0, 0.0], [1.0, 0.0], [5.0, 5.0]])
    sig = np.array([[0.0, 0.0], [1.0, 0.0], [9.0, 9.0]])
    # signature distances 0.25 and 0.75 from the first two places: weights 3/4 and 1/4
    mean, std = locate_by_turn_signature(
        np.array([0.25, 0.0]), places, sig, np.ones(2), k=2, min_std_m=1e-6
    )
    np.testing.assert_allclose(mean, [0.25, 0.0], atol=1e-8)
    np.testing.assert_allclose(std, [np.sqrt(0.75 * 0.25), 1e-6], rtol=1e-6)
    # the spread of one place is the floor; more places than there are: all of them
    _, std = locate_by_turn_signature(sig[2], places, sig, np.ones(2), k=1, min_std_m=0.1)
    np.testing.assert_allclose(std, [0.1, 0.1])
    mean, _ = locate_by_turn_signature(np.array([3.0, 3.0]), places, sig, np.ones(2), k=10)
    assert np.all(np.isfinite(mean))
    # sigma scales each spot's axis of the signature: spot 1 made decisive
    mean, _ = locate_by_turn_signature(
        np.array([0.6, 9.0]), places, sig, np.array([100.0, 0.01]), k=1
    )
    np.testing.assert_allclose(mean, places[2])


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((np.zeros(2), np.zeros((3, 3)), np.zeros((3, 2)), np.ones(2)), "places"),
        ((np.zeros(2), np.zeros((3, 2)), np.zeros((2, 2)), np.ones(2)), "place_scores"),
        ((np.zeros(2), np.zeros((0, 2)), np.zeros((0, 2)), np.ones(2)), "empty"),
        ((np.full(2, np.nan), np.zeros((3, 2)), np.zeros((3, 2)), np.ones(2)), "NaN"),
        ((np.zeros(2), np.zeros((3, 2)), np.zeros((3, 2)), np.ones(3)), "sigma"),
        ((np.zeros(2), np.zeros((3, 2)), np.zeros((3, 2)), np.ones(2), True), "k must"),
        ((np.zeros(2), np.zeros((3, 2)), np.zeros((3, 2)), np.ones(2), 2.0), "k must"),
        ((np.zeros(2), np.zeros((3, 2)), np.zeros((3, 2)), np.ones(2), 2, 0.0), "min_std_m"),
    ],
)
def test_bad_inputs_are_clear_errors(args, match):
    with pytest.raises(ValueError, match=match):
        locate_by_turn_signature(*args)


def test_a_turn_in_a_room_is_placed_at_the_spot_where_it_was_taken(synthetic_room, room_atlas):
    """The compass end to end: turns at the four spots are the places; a later turn at
    one of them (other headings) is recognised as that spot."""
    camera = Camera()

    def turn(x: float, y: float, start: float) -> np.ndarray:
        views = [
            render_room_view(synthetic_room, x, y, Camera(yaw_deg=start + 45.0 * k))
            for k in range(8)
        ]
        return mean_spot_scores(room_atlas, views, camera)

    places = room_atlas.positions
    signatures = np.array([turn(x, y, 0.0) for x, y in places])
    sigma = calibrate_goodness(places, places, signatures).sigma
    for i, (x, y) in enumerate(places):
        mean, _ = locate_by_turn_signature(turn(x, y, 20.0), places, signatures, sigma, k=1)
        np.testing.assert_array_equal(mean, places[i])
