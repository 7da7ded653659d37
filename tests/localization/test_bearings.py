"""Bearings of colour changes, landmarks placed from the learned turns, and the pose
likelihood they give, in a ray-cast room whose colour edges are known exactly."""

from __future__ import annotations

import math

import numpy as np
import pytest
from striped_room import HFOV, PALETTE, learned_views, striped_room, true_offsets, view

from vc_gym.compass import Camera
from vc_gym.compass.bearings import bands_bearings, frame_bearings
from vc_gym.compass.landmarks import LearnedView, learn_landmarks
from vc_gym.localization.bearing_sensor import BearingSensor


@pytest.fixture(scope="module")
def striped():
    return striped_room()


@pytest.fixture(scope="module")
def learned(striped):
    return learned_views(striped)


def test_each_colour_edge_is_a_bearing_to_a_fraction_of_a_degree(striped, learned):
    room, points = striped
    colors, _ = learned
    for x, y, yaw in [(0.3, -0.4, 20.0), (-1.2, 0.7, 200.0), (1.5, 1.0, 95.0)]:
        img, cam = view(room, x, y, yaw)
        b = frame_bearings(img, cam, colors)
        truth = true_offsets(points, x, y, yaw)
        assert len(b) >= len(truth) - 1  # every edge in view (the frame's rim aside)
        errors = [np.min(np.abs(truth - o)) for o in b.offsets_deg if abs(o) < HFOV / 2 - 1]
        # a pixel is 0.27 deg; measured: median 0.07 deg, at most 0.11 deg
        assert np.max(errors) < 0.3 and np.median(errors) < 0.15, errors


def test_a_dimmer_frame_read_at_its_gain_shows_the_same_changes(striped, learned):
    """Half the light and a gain of 2 give back the classes and the columns: without
    the gain the dim frame's classes, and so its changes, are others."""
    from vc_gym.exposure import gain_table

    room, _ = striped
    colors, _ = learned
    img, cam = view(room, 0.3, -0.4, 20.0)
    bright = bands_bearings(img, cam, colors)
    dim = np.take(gain_table(0.5), img)
    again = bands_bearings(dim, cam, colors, gain=2.0)
    assert np.array_equal(again.pairs, bright.pairs)
    assert np.max(np.abs(again.offsets_deg - bright.offsets_deg)) < 0.1
    as_is = bands_bearings(dim, cam, colors)
    assert len(as_is) != len(bright) or not np.array_equal(as_is.pairs, bright.pairs)
    with pytest.raises(ValueError, match="gain"):
        bands_bearings(img, cam, colors, gain=0.0)


def test_a_frame_read_as_a_dimmer_room_shows_it_holds_the_edges_it_would_see(striped, learned):
    """A surface whose colour lies on a class border changes class in a room at half the
    light read at a gain of 2 (its levels rounded): its edges show another pair there.
    With ``dimmed_stops=(1,)`` the full-light frame's changes include that reading's, so
    every change of the dimmer frame is among them, at its bearing."""
    from vc_gym.exposure import gain_table

    room, _ = striped
    colors, _ = learned
    # on the blend from red to violet: a colour the round trip through half the light
    # moves into another class
    blend = np.linspace(0.0, 1.0, 512)[:, None]
    shades = (PALETTE[0] * (1 - blend) + PALETTE[4] * blend).round().astype(np.uint8)
    back = np.take(gain_table(2.0), np.take(gain_table(0.5), shades))
    flips = np.flatnonzero(colors.classify(shades[None])[0] != colors.classify(back[None])[0])
    assert flips.size, "no colour of the blend changes class through half the light"
    img, cam = view(room, 0.3, -0.4, 20.0)
    img[:, 60:150] = shades[flips[0]]
    dim = np.take(gain_table(0.5), img)
    seen_dim = bands_bearings(dim, cam, colors, gain=2.0)
    plain = bands_bearings(img, cam, colors)
    both = bands_bearings(img, cam, colors, dimmed_stops=(1.0,))

    def found(changes, among):
        same = changes.pairs[:, None] == among.pairs[None, :]
        near = np.abs(changes.offsets_deg[:, None] - among.offsets_deg[None, :]) < 0.1
        return np.any(same & near, axis=1)

    assert not np.all(found(seen_dim, plain))  # the repainted surface's edges: other pairs
    assert np.all(found(seen_dim, both))
    assert np.all(found(plain, both))  # the full light's own changes are all kept
    with pytest.raises(ValueError, match="dimmed_stops"):
        bands_bearings(img, cam, colors, dimmed_stops=(0.0,))


def test_the_learned_turns_place_every_edge_they_all_see(striped, learned):
    _, points = striped
    _, views = learned
    lm = learn_landmarks(views)
    # every landmark lies on a true colour edge of the walls, to a few centimetres
    # (measured: all 27 edges found, median 3 mm off, at most 16 mm)
    gaps = np.min(np.hypot(*(lm.positions[:, None, :] - points[None]).transpose(2, 0, 1)), axis=1)
    assert len(lm) >= 0.8 * len(points), (len(lm), len(points))
    assert np.max(gaps) < 0.05 and np.median(gaps) < 0.02, np.sort(gaps)[-5:]
    assert np.all(lm.support >= 3) and np.all(lm.std_m < 0.1)


def test_the_likelihood_peaks_at_the_true_pose(striped, learned):
    room, _ = striped
    colors, views = learned
    sensor = BearingSensor(learn_landmarks(views), colors, Camera(hfov_deg=HFOV))
    x, y, yaw = 0.7, -0.6, 130.0  # a pose no turn was learned at
    img, _ = view(room, x, y, yaw)
    obs = sensor.bearings(img)
    gx, gy = np.meshgrid(np.arange(-0.2, 0.21, 0.01), np.arange(-0.2, 0.21, 0.01))
    for dyaw in (-1.0, 0.0, 1.0):
        poses = np.stack([x + gx.ravel(), y + gy.ravel(), np.full(gx.size, yaw + dyaw)], 1)
        ll = sensor.pose_log_likelihood(obs, poses)
        best = poses[np.argmax(ll)]
        if dyaw == 0.0:
            # a sector histogram places the robot 0.2 m off; the bearings to a few cm
            # (measured: 1.4 cm, from 5 changes in view)
            assert math.hypot(best[0] - x, best[1] - y) < 0.04, best
            at_truth = ll[np.argmin(np.hypot(poses[:, 0] - x, poses[:, 1] - y))]
    # the true heading beats one degree off at the best positions
    worse = [sensor.pose_log_likelihood(obs, np.array([[x, y, yaw + d]]))[0] for d in (-1.0, 1.0)]
    assert at_truth > max(worse)


def test_a_stray_change_does_not_move_the_best_pose(striped, learned):
    room, _ = striped
    colors, views = learned
    sensor = BearingSensor(learn_landmarks(views), colors, Camera(hfov_deg=HFOV))
    x, y, yaw = -0.4, 0.8, 300.0
    img, _ = view(room, x, y, yaw)
    spoiled = img.copy()
    spoiled[:, 90:100] = PALETTE[2]  # a person in a blue coat: two changes no turn learned
    poses = np.array([[x, y, yaw], [x + 0.15, y, yaw], [x, y - 0.15, yaw + 2.0]])
    clean = sensor.pose_log_likelihood(img, poses)
    noisy = sensor.pose_log_likelihood(spoiled, poses)
    assert np.argmax(clean) == 0 and np.argmax(noisy) == 0


def test_bad_inputs_are_refused(striped, learned):
    colors, views = learned
    sensor = BearingSensor(learn_landmarks(views), colors)
    with pytest.raises(ValueError, match="shape"):
        sensor.pose_log_likelihood(views[0].bearings, np.zeros((4, 2)))
    with pytest.raises(ValueError, match="finite"):
        sensor.pose_log_likelihood(views[0].bearings, np.full((1, 3), np.nan))
    with pytest.raises(ValueError, match="outlier"):
        BearingSensor(learn_landmarks(views), colors, outlier=1.0)
    with pytest.raises(ValueError, match="no views"):
        learn_landmarks([])
    lm, found = sensor.landmarks, views[0].bearings
    with pytest.raises(ValueError, match="positions must be"):
        lm.log_likelihood(found, np.zeros((3, 3)), np.zeros(3), 0.01, 0.05)
    with pytest.raises(ValueError, match="finite"):
        lm.log_likelihood(found, np.zeros((1, 2)), np.array([np.nan]), 0.01, 0.05)
    with pytest.raises(ValueError, match="noise_rad"):
        lm.log_likelihood(found, np.zeros((1, 2)), np.zeros(1), 0.0, 0.05)
    with pytest.raises(ValueError, match="outlier"):
        lm.log_likelihood(found, np.zeros((1, 2)), np.zeros(1), 0.01, 1.5)
    with pytest.raises(ValueError, match="band_deg"):
        frame_bearings(np.zeros((40, 52, 3), np.uint8), Camera(), colors, band_deg=(5.0, 1.0))
    for bands in ([(5.0, 1.0)], [(1.0,)], "high", [(0.0, float("inf"))], [], [(0.5, 4.0)] * 17):
        with pytest.raises(ValueError, match="band"):
            bands_bearings(np.zeros((40, 52, 3), np.uint8), Camera(), colors, bands_deg=bands)
    # changes read in other bands than the map's are refused, not matched wrongly
    other = bands_bearings(view(striped[0], 0.0, 0.0, 0.0)[0], Camera(hfov_deg=HFOV), colors)
    with pytest.raises(ValueError, match="bands"):
        lm.log_likelihood(other, np.zeros((1, 2)), np.zeros(1), 0.01, 0.05)


def test_the_camera_ahead_of_the_body_is_where_the_bearings_are_seen_from(striped, learned):
    room, _ = striped
    colors, views = learned
    ahead = 0.25  # the simulated robot's eye, ahead of its trunk's centre
    camera = Camera(hfov_deg=HFOV)
    sensor = BearingSensor(learn_landmarks(views), colors, camera, eye_forward_m=ahead)
    x, y, yaw = -0.5, -0.3, 60.0  # the body
    t = math.radians(yaw)
    img, _ = view(room, x + ahead * math.cos(t), y + ahead * math.sin(t), yaw)
    gx, gy = np.meshgrid(np.arange(-0.3, 0.31, 0.01), np.arange(-0.3, 0.31, 0.01))
    poses = np.stack([x + gx.ravel(), y + gy.ravel(), np.full(gx.size, yaw)], 1)
    best = poses[np.argmax(sensor.pose_log_likelihood(img, poses))]
    assert math.hypot(best[0] - x, best[1] - y) < 0.04, best
    with pytest.raises(ValueError, match="eye_forward_m"):
        BearingSensor(sensor.landmarks, colors, eye_forward_m=float("nan"))


def test_many_rays_are_triangulated_within_bounded_work():
    """1,200 rays of one colour pair (720,000 pairs of rays) from 400 positions: the
    candidates are drawn (MAX_CANDIDATES) and scored in chunks, and every landmark is
    still found."""
    from vc_gym.compass.bearings import FrameBearings
    from vc_gym.compass.landmarks import MAX_CANDIDATES

    rng = np.random.default_rng(2)
    marks = np.array([[3.0, 1.0], [2.5, -1.5], [-3.0, 0.5]])
    views = []
    for x, y in rng.uniform(-1.0, 1.0, (400, 2)):
        world = np.degrees(np.arctan2(marks[:, 1] - y, marks[:, 0] - x))
        found = FrameBearings(world.copy(), np.zeros(3, np.int64), np.ones(3, np.int64), 4, 360.0)
        views.append(LearnedView(found, 0.0, float(x), float(y)))
    assert 1200 * 1199 // 2 > MAX_CANDIDATES
    lm = learn_landmarks(views)
    assert len(lm) == 3
    gaps = np.min(np.hypot(*(lm.positions[:, None, :] - marks[None]).transpose(2, 0, 1)), 1)
    assert np.max(gaps) < 0.01 and np.all(lm.support >= 300)
