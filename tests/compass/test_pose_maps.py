"""PoseMaps: the pose likelihood of many poses at once, against ParallaxMap's own.

Known answers come from the ray-cast room (:mod:`vc_gym.worlds.room`): views from any
position show true parallax, and the true pose of every view is known.
"""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera, CompassAtlas, CompassConfig, VisualCompass, wrap180
from vc_gym.compass.parallax import ParallaxMap
from vc_gym.compass.pose_maps import PoseMaps, around_groups
from vc_gym.exposure import gain_table
from vc_gym.worlds.room import make_room, render_room_view

WIDTH_M, DEPTH_M = 5.0, 4.0
SPOTS = {"spot0": (-1.0, 0.0), "spot1": (1.0, 0.0)}
AROUND = {"e": (0.5, 0.0), "w": (-0.5, 0.0), "n": (0.0, 0.5), "s": (0.0, -0.5)}


@pytest.fixture(scope="module")
def room():
    return make_room(np.random.default_rng(5), width_m=WIDTH_M, depth_m=DEPTH_M)


@pytest.fixture(scope="module")
def atlas(room, learn_room_turn):
    """Two spots 2 m apart, each with four turns 0.5 m around it kept of their own."""
    colors = None
    entries = {}
    for name, (x, y) in SPOTS.items():
        vc = learn_room_turn(room, x, y, colors)
        colors = vc.colors
        entries[name] = ((x, y), vc)
        for side, (dx, dy) in AROUND.items():
            entries[f"{name}.{side}"] = (
                (x + dx, y + dy),
                learn_room_turn(room, x + dx, y + dy, colors),
            )
    return CompassAtlas(entries, home="spot0")


@pytest.fixture(scope="module")
def pose_maps(atlas):
    return PoseMaps.from_atlas(atlas)


def test_around_groups_follow_the_names():
    names = ["a", "a.e", "b", "a.w", "b.n", "c.e", "x.y.z", "x.y"]
    assert around_groups(names) == {
        "a": ["a", "a.e", "a.w"],
        "b": ["b", "b.n"],
        "c.e": ["c.e"],  # no spot "c": a spot of its own
        "x.y": ["x.y", "x.y.z"],
    }


def test_spots_and_their_positions(pose_maps):
    assert pose_maps.names == ("spot0", "spot1")
    np.testing.assert_allclose(pose_maps.positions, [SPOTS["spot0"], SPOTS["spot1"]])
    np.testing.assert_array_equal(
        pose_maps.nearest(np.array([[-2.0, 1.0], [0.1, 0.0], [-0.1, 0.0]])), [0, 1, 0]
    )


def test_equals_the_parallax_maps_own_likelihood_on_the_lattice(room, atlas, pose_maps):
    spot = ParallaxMap.learn(
        SPOTS["spot1"],
        atlas.compasses[atlas.names.index("spot1")],
        [(AROUND[s], atlas.compasses[atlas.names.index(f"spot1.{s}")]) for s in "ewns"],
    )
    image = render_room_view(room, 1.3, -0.2, Camera(yaw_deg=70.0))
    xy = np.array([[1.3, -0.2], [1.0, 0.0], [0.6, 0.4]])
    expected = spot.pose_log_likelihood(image, Camera(), xy)  # (3, 360)
    terms = pose_maps.frame(image, Camera())
    for heading in (0.0, 70.0, 213.0):
        got = pose_maps.log_likelihood(terms, xy, np.full(3, heading), spot=np.ones(3, int))
        np.testing.assert_allclose(got, expected[:, int(heading)], rtol=1e-12, atol=1e-9)
    at_spot = pose_maps.heading_log_likelihood(terms, 1)
    np.testing.assert_allclose(at_spot, expected[1], rtol=1e-12, atol=1e-9)


def test_the_true_pose_fits_better_than_wrong_ones(room, pose_maps):
    rng = np.random.default_rng(0)
    wins = 0
    for _ in range(10):
        x, y = rng.uniform(-1.8, 1.8), rng.uniform(-1.3, 1.3)
        yaw = rng.uniform(0, 360)
        image = render_room_view(room, x, y, Camera(yaw_deg=yaw))
        terms = pose_maps.frame(image, Camera())
        wrong_heading = (yaw + rng.uniform(30, 330)) % 360
        wrong_xy = np.array([x, y]) + rng.normal(0, 1.0, 2)
        xy = np.array([[x, y], [x, y], wrong_xy])
        ll = pose_maps.log_likelihood(terms, xy, np.array([yaw, wrong_heading, yaw]))
        wins += ll[0] > ll[1] and ll[0] > ll[2]
    assert wins >= 8


def test_position_is_read_from_a_frame_between_spots(room, pose_maps):
    # the best position on a 0.1 m grid, at the true heading, summed over a few frames
    x, y = 0.1, 0.5
    grid = np.stack(np.meshgrid(np.arange(-2, 2.01, 0.1), np.arange(-1.5, 1.51, 0.1)), -1)
    grid = grid.reshape(-1, 2)
    total = np.zeros(len(grid))
    for yaw in (10.0, 100.0, 190.0, 280.0):
        terms = pose_maps.frame(render_room_view(room, x, y, Camera(yaw_deg=yaw)), Camera())
        total += pose_maps.log_likelihood(terms, grid, np.full(len(grid), yaw))
    best = grid[np.argmax(total)]
    assert np.hypot(*(best - (x, y))) < 0.5


def test_a_frame_that_sees_nothing_fits_every_pose_alike(pose_maps):
    terms = pose_maps.frame(np.zeros((160, 208, 3), np.uint8), Camera())
    assert not terms.has_evidence
    ll = pose_maps.log_likelihood(terms, np.zeros((4, 2)), np.arange(4.0))
    np.testing.assert_array_equal(ll, 0.0)


def test_only_some_spots(room, pose_maps):
    image = render_room_view(room, -0.8, 0.3, Camera(yaw_deg=30.0))
    full = pose_maps.frame(image, Camera())
    part = pose_maps.frame(image, Camera(), spots=[0])
    xy = np.array([[-0.8, 0.3], [-1.2, -0.1]])
    np.testing.assert_allclose(
        pose_maps.log_likelihood(part, xy, np.array([30.0, 50.0])),
        pose_maps.log_likelihood(full, xy, np.array([30.0, 50.0])),
    )
    with pytest.raises(ValueError, match="every spot"):
        pose_maps.log_likelihood(part, np.array([[1.0, 0.0]]), np.array([0.0]))


@pytest.mark.parametrize(
    ("xy", "heading", "match"),
    [
        (np.zeros((3,)), np.zeros(3), r"\(N, 2\)"),
        (np.zeros((3, 2)), np.zeros(2), r"\(N, 2\)"),
        (np.full((1, 2), np.nan), np.zeros(1), "finite"),
        (np.zeros((1, 2)), np.array([np.inf]), "finite"),
    ],
)
def test_bad_poses_are_refused(room, pose_maps, xy, heading, match):
    terms = pose_maps.frame(render_room_view(room, 0, 0, Camera()), Camera())
    with pytest.raises(ValueError, match=match):
        pose_maps.log_likelihood(terms, xy, heading)


def test_bad_arguments_are_refused(room, atlas, pose_maps):
    with pytest.raises(ValueError, match="ParallaxMap"):
        PoseMaps([])
    with pytest.raises(ValueError, match="lattice_m"):
        PoseMaps.from_atlas(atlas, lattice_m=0)
    with pytest.raises(ValueError, match="at most 200"):
        PoseMaps.from_atlas(atlas, lattice_m=0.001, reach_m=1.0)
    with pytest.raises(ValueError, match="CompassAtlas"):
        PoseMaps.from_atlas("atlas")
    with pytest.raises(ValueError, match="spots must be indices"):
        pose_maps.frame(render_room_view(room, 0, 0, Camera()), Camera(), spots=[5])


def test_heading_at_a_spot_is_the_compass_heading(room, pose_maps):
    for yaw in (20.0, 140.0, 300.0):
        terms = pose_maps.frame(render_room_view(room, -1.0, 0.0, Camera(yaw_deg=yaw)), Camera())
        best = float(np.argmax(pose_maps.heading_log_likelihood(terms, 0)))
        assert abs(wrap180(best - yaw)) < 3.0


def test_maps_learned_with_exposure_map_are_refused(room, atlas):
    # exposure="map" brings a frame to each map sector's own light: one set of frame
    # terms for every pose cannot hold that
    spot = atlas.compasses[atlas.names.index("spot0")]
    by_sector = VisualCompass(CompassConfig(exposure="map"), spot.colors)
    for yaw in range(0, 360, 45):
        by_sector.learn(render_room_view(room, -1.0, 0.0, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    with pytest.raises(ValueError, match='exposure="map"'):
        PoseMaps.from_atlas(CompassAtlas({"spot0": ((-1.0, 0.0), by_sector)}, home="spot0"))


def test_maps_with_other_colour_classes_are_refused(room, atlas, learn_room_turn):
    """Poses near different spots are compared by their maps' scores: only maps that
    count the same colour transitions compare."""
    spot0 = ((-1.0, 0.0), atlas.compasses[atlas.names.index("spot0")])
    spot1 = ((1.0, 0.0), atlas.compasses[atlas.names.index("spot1")])
    own = learn_room_turn(room, 1.0, 0.0, yaws=range(0, 360, 45))  # its own colour classes
    assert not own.shares_colors(spot0[1])
    with pytest.raises(ValueError, match="colour classes"):
        PoseMaps.from_atlas(CompassAtlas({"spot0": spot0, "spot1": ((1.0, 0.0), own)}, "spot0"))
    # the same two spots with shared classes are taken
    assert len(PoseMaps.from_atlas(CompassAtlas({"spot0": spot0, "spot1": spot1}, "spot0"))) == 2


@pytest.mark.parametrize("gain", [2.0, 0.5])
def test_a_gain_multiplies_the_frames_linear_light(room, pose_maps, gain):
    """``frame(gain=g)`` scores the frame as the frame with its linear light times
    ``g`` (:func:`~vc_gym.exposure.gain_table`), as ``VisualCompass.log_likelihood``."""
    image = render_room_view(room, -0.8, 0.2, Camera(yaw_deg=40.0))
    with_gain = pose_maps.frame(image, Camera(), gain=gain)
    lit = pose_maps.frame(np.take(gain_table(gain), image), Camera())
    np.testing.assert_array_equal(with_gain.per_group, lit.per_group)
    assert not np.array_equal(with_gain.per_group, pose_maps.frame(image, Camera()).per_group)


def test_half_the_light_with_gain_two_finds_the_heading_at_every_spot(room, pose_maps):
    """At half the light the maps lose the heading; the session's gain of 2 brings the
    frames back to the learned light and the heading with them."""
    with_gain, without = [], []
    for spot, (x, y) in enumerate(SPOTS.values()):
        for yaw in (20.0, 140.0, 300.0):
            dark = render_room_view(room, x, y, Camera(yaw_deg=yaw), illumination=0.5)
            for gain, errors in ((2.0, with_gain), (None, without)):
                ll = pose_maps.heading_log_likelihood(
                    pose_maps.frame(dark, Camera(), gain=gain), spot
                )
                errors.append(abs(wrap180(float(np.argmax(ll)) - yaw)))
    assert max(with_gain) <= 2.0, with_gain
    assert np.mean(np.array(without) > 20.0) >= 0.5, without  # what the gain is for
