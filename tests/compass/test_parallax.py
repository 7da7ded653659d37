"""The parallax warp: distances learned from turns around a spot, maps re-drawn off the spot.

Known answers come from the ray-cast room (:mod:`vc_gym.worlds.room`): its walls are the
box ``[-W/2, W/2] x [-D/2, D/2]``, so the distance of every sector's wall point from the
spot is exact, and views from any position show true parallax.
"""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera, CompassConfig, VisualCompass, wrap180
from vc_gym.compass.parallax import ParallaxMap, learn_depths, sector_of
from vc_gym.worlds.room import make_room, render_room_view

#: A small room (4 x 3 m) where 0.5 m from the spot moves near walls by 10° and more.
WIDTH_M, DEPTH_M = 4.0, 3.0
AROUND = [(0.5, 0.0), (-0.5, 0.0), (0.0, 0.5), (0.0, -0.5)]
OFF_SPOT = [(0.35, 0.35), (-0.35, 0.35), (0.4, -0.2), (-0.3, -0.4), (0.6, 0.0)]


@pytest.fixture(scope="module")
def room():
    return make_room(np.random.default_rng(3), width_m=WIDTH_M, depth_m=DEPTH_M)


@pytest.fixture(scope="module")
def turns(room, learn_room_turn):
    spot = learn_room_turn(room, 0.0, 0.0)
    return spot, [(o, learn_room_turn(room, *o, spot.colors)) for o in AROUND]


def _room_depths(n: int = 80) -> np.ndarray:
    """Exact horizontal distance from the room's centre to its walls, per sector centre."""
    th = np.radians((np.arange(n) + 0.5) * 360.0 / n)
    c, s = np.cos(th), np.sin(th)
    return np.minimum((WIDTH_M / 2) / np.abs(c), (DEPTH_M / 2) / np.abs(s))


def _mean_error(room, vc: VisualCompass, pos, seed: int) -> float:
    errors = []
    for yaw in np.random.default_rng(seed).uniform(0.0, 360.0, 12):
        image = render_room_view(room, *pos, Camera(yaw_deg=yaw))
        errors.append(abs(wrap180(vc.estimate(image, Camera()).heading_deg - yaw)))
    return float(np.mean(errors))


def test_sector_of_follows_the_compass_sectors():
    deg = np.array([0.0, 4.4, 4.5, 90.0, 359.9, -0.1, 360.0])
    got = sector_of(np.cos(np.radians(deg)), np.sin(np.radians(deg)), 4.5)
    np.testing.assert_array_equal(got, [0, 0, 1, 20, 79, 79, 0])


def test_learned_depths_match_the_room(turns):
    spot, around = turns
    ratio = np.abs(np.log(learn_depths(spot, around) / _room_depths()))
    assert np.median(ratio) < np.log(1.25)
    assert np.mean(ratio < np.log(1.3)) > 0.65


def test_warp_of_the_spot_turn_at_the_spot_is_the_spot_map(turns):
    spot, _ = turns
    same = ParallaxMap((0.0, 0.0), _room_depths(), [((0.0, 0.0), spot)]).at((0.0, 0.0))
    np.testing.assert_array_equal(same.map_counts, spot.map_counts)
    np.testing.assert_array_equal(same.sector_observations, spot.sector_observations)


@pytest.mark.parametrize("pos", OFF_SPOT)
def test_true_depths_warp_the_spot_map_to_fit_off_the_spot(room, turns, pos):
    spot, _ = turns
    warped = ParallaxMap((0.0, 0.0), _room_depths(), [((0.0, 0.0), spot)]).at(pos)
    plain, fixed = _mean_error(room, spot, pos, 1), _mean_error(room, warped, pos, 1)
    assert plain > 5.0  # parallax is real here
    # the spot's turn alone leaves a few sectors no wall point lands on: up to 2.5°
    assert fixed < 3.0 and fixed < plain / 3


@pytest.mark.parametrize("pos", OFF_SPOT)
def test_learned_parallax_map_fits_off_the_spot(room, turns, pos, learn_room_turn):
    spot, around = turns
    merged = learn_room_turn(room, 0.0, 0.0, spot.colors)
    for _, m in around:
        merged.merge(m)
    warped = ParallaxMap.learn((0.0, 0.0), spot, around).at(pos)
    # the spot-grid mode's map (the turns merged as taken) against the learned warp
    assert _mean_error(room, warped, pos, 2) < min(2.0, _mean_error(room, merged, pos, 2) / 3)


def test_parallax_map_moves_with_the_spot(room, turns):
    """The same maps learned 1 m further east give the same warp 1 m further east."""
    spot, around = turns
    here = ParallaxMap.learn((0.0, 0.0), spot, around)
    there = ParallaxMap.learn((1.0, 0.0), spot, around)
    np.testing.assert_array_equal(here.depths_m, there.depths_m)
    np.testing.assert_array_equal(here.at((0.3, -0.2)).map_counts, there.at((1.3, -0.2)).map_counts)
    np.testing.assert_allclose(
        here.wall_points((0.3, -0.2)) + [1.0, 0.0], there.wall_points((1.3, -0.2))
    )


def test_regrouped_adds_counts_of_sectors_sent_to_one(turns):
    spot, _ = turns
    n = spot.config.n_sectors
    same = spot.regrouped(np.arange(n))
    np.testing.assert_array_equal(same.map_counts, spot.map_counts)
    img = np.random.default_rng(0).integers(0, 255, (160, 208, 3), dtype=np.uint8)
    np.testing.assert_array_equal(
        same.log_likelihood(img, Camera()), spot.log_likelihood(img, Camera())
    )
    target = np.arange(n) // 2  # pairs of sectors into the first half
    half = spot.regrouped(target)
    np.testing.assert_array_equal(half.map_counts[0], spot.map_counts[0] + spot.map_counts[1])
    assert half.sector_observations[n // 2 :].sum() == 0
    assert half.sector_observations.sum() == spot.sector_observations.sum()
    assert half.frames_learned == spot.frames_learned and half.colors is spot.colors


def test_map_views_are_read_only_and_log_probabilities_normalised(turns):
    spot, _ = turns
    with pytest.raises(ValueError):
        spot.map_counts[0, 0, 0] = 1.0
    p = np.exp(spot.sector_log_probabilities())
    np.testing.assert_allclose(p.sum(axis=2), 1.0)


@pytest.mark.parametrize(
    "target", [np.arange(79), np.arange(80) + 1, -np.ones(80, int), np.zeros(80), "x"]
)
def test_regrouped_rejects_bad_targets(turns, target):
    with pytest.raises(ValueError, match="target"):
        turns[0].regrouped(target)


def test_bad_input_is_refused(turns):
    spot, around = turns
    unlearned = VisualCompass(CompassConfig(), spot.colors)
    with pytest.raises(ValueError, match="at least one"):
        learn_depths(spot, [])
    with pytest.raises(ValueError, match="learned"):
        learn_depths(unlearned, around)
    with pytest.raises(ValueError, match="learned"):
        learn_depths(spot, [((0.5, 0.0), unlearned)])
    with pytest.raises(ValueError, match="finite"):
        learn_depths(spot, [((np.nan, 0.0), around[0][1])])
    with pytest.raises(ValueError, match=r"\(\(x, y\), VisualCompass\)"):
        learn_depths(spot, [around[0][1]])
    with pytest.raises(ValueError, match="candidates"):
        learn_depths(spot, around, np.array([0.5, -1.0]))
    with pytest.raises(ValueError, match="depths_m"):
        ParallaxMap((0, 0), np.ones(79), [((0, 0), spot)])
    with pytest.raises(ValueError, match="depths_m"):
        ParallaxMap((0, 0), np.zeros(80), [((0, 0), spot)])
    with pytest.raises(ValueError, match="parts"):
        ParallaxMap((0, 0), np.ones(80), [])
    pm = ParallaxMap((0, 0), np.ones(80), [((0, 0), spot)])
    with pytest.raises(ValueError, match="position"):
        pm.at((np.inf, 0.0))
    with pytest.raises(ValueError, match="position"):
        pm.at((1.0, 2.0, 3.0))


def test_maps_of_another_config_cannot_join(room, turns):
    spot, _ = turns
    three = VisualCompass(CompassConfig(n_colors=3))
    three.fit_colors([render_room_view(room, 0.0, 0.0, Camera(yaw_deg=a)) for a in (0, 120, 240)])
    three.learn(render_room_view(room, 0.0, 0.0, Camera()), Camera())
    with pytest.raises(ValueError, match="CompassConfig"):
        ParallaxMap((0, 0), np.ones(80), [((0, 0), spot), ((1, 0), three)])
    with pytest.raises(ValueError, match="CompassConfig"):
        learn_depths(spot, [((0.5, 0.0), three)])


def test_remapped_identity_is_the_plain_likelihood_and_a_roll_a_turn(room, turns):
    spot, _ = turns
    n = spot.config.n_sectors
    img = render_room_view(room, 0.2, -0.1, Camera(yaw_deg=33.0))
    plain = spot.log_likelihood(img, Camera())
    rows = np.stack([np.arange(n), (np.arange(n) + 2) % n])  # identity; 2 sectors = 9°
    got = spot.log_likelihood_remapped(img, Camera(), rows)
    np.testing.assert_array_equal(got[0], plain)
    np.testing.assert_allclose(got[1], np.roll(plain, -9), rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    "rows", [np.zeros((2, 79), int), np.zeros(80, int), np.full((1, 80), 80), np.zeros((1, 80))]
)
def test_remapped_rejects_bad_rows(turns, rows):
    img = np.zeros((160, 208, 3), np.uint8)
    with pytest.raises(ValueError, match="sector_maps"):
        turns[0].log_likelihood_remapped(img, Camera(), rows)


def test_remapped_refuses_a_gain_per_heading(room, turns):
    vc = VisualCompass(CompassConfig(exposure="map"))
    vc.fit_colors([render_room_view(room, 0.0, 0.0, Camera(yaw_deg=a)) for a in (0, 120, 240)])
    vc.learn(render_room_view(room, 0.0, 0.0, Camera()), Camera())
    with pytest.raises(ValueError, match="exposure"):
        vc.log_likelihood_remapped(render_room_view(room, 0, 0, Camera()), Camera(), [range(80)])


def test_centred_map_at_the_spot_and_its_sector_maps(turns):
    spot, around = turns
    alone = ParallaxMap((0.0, 0.0), _room_depths(), [((0.0, 0.0), spot)])
    np.testing.assert_array_equal(alone.centred().map_counts, spot.map_counts)
    np.testing.assert_array_equal(alone.sector_maps([(0.0, 0.0)])[0], np.arange(80))
    pm = ParallaxMap.learn((0.0, 0.0), spot, around)
    assert pm.centred().frames_learned == spot.frames_learned * 5
    assert pm.centred().learned_fraction == 1.0
    with pytest.raises(ValueError, match="positions"):
        pm.sector_maps([0.0, 0.0])


@pytest.mark.parametrize("pos", OFF_SPOT)
def test_pose_likelihood_gives_the_heading_at_the_position(room, turns, pos):
    """At the true position the pose likelihood gives the heading; it also fits the true
    position better than the spot (0.35-0.6 m away), summed over a look with the head."""
    spot, around = turns
    pm = ParallaxMap.learn((0.0, 0.0), spot, around)
    yaw = float(np.random.default_rng(OFF_SPOT.index(pos)).uniform(0, 360))
    total = np.zeros((2, 360))
    for pan in (-20, 0, 20, 40):
        img = render_room_view(room, *pos, Camera(yaw_deg=yaw + pan))
        total += np.roll(pm.pose_log_likelihood(img, Camera(), [pos, (0.0, 0.0)]), -pan, axis=1)
    assert abs(wrap180(np.argmax(total[0]) - yaw)) <= 2.0
    assert total[0].max() > total[1].max()


def test_pose_likelihood_finds_the_position_in_the_ray_cast_room(room, turns):
    """Ten frames looking one way, head scanning: the best of 13 x 13 positions 0.1 m
    apart is near the truth (README: 0.13 m median over 20 views in this room)."""
    spot, around = turns
    pm = ParallaxMap.learn((0.0, 0.0), spot, around)
    step = np.arange(-0.6, 0.61, 0.1)
    cand = np.stack(np.meshgrid(step, step, indexing="ij"), axis=-1).reshape(-1, 2)
    rows = pm.sector_maps(cand)
    rng = np.random.default_rng(11)
    position_errors, heading_errors = [], []
    for _ in range(8):
        r, a = rng.uniform(0.2, 0.6), rng.uniform(0.0, 2 * np.pi)
        pos, yaw = (r * np.cos(a), r * np.sin(a)), rng.uniform(0.0, 360.0)
        total = np.zeros((len(cand), 360))
        for pan in (-20, 0, 20, 40, 20, 0, -20, 0, 20, 40):
            img = render_room_view(room, *pos, Camera(yaw_deg=yaw + pan))
            ll = pm.centred().log_likelihood_remapped(img, Camera(), rows)
            total += np.roll(ll, -pan, axis=1)
        n, h = np.unravel_index(np.argmax(total), total.shape)
        position_errors.append(np.hypot(*(cand[n] - pos)))
        heading_errors.append(abs(wrap180(h - yaw)))
    assert np.median(position_errors) <= 0.2
    assert np.mean(heading_errors) < 5.0


def test_maps_of_other_colour_classes_cannot_join(room, turns, learn_room_turn):
    spot, around = turns
    stranger = learn_room_turn(room, 0.5, 0.0)  # its own colour classes, fitted there
    assert not stranger.shares_colors(spot) and around[0][1].shares_colors(spot)
    with pytest.raises(ValueError, match="colour classes"):
        learn_depths(spot, [((0.5, 0.0), stranger)])
    with pytest.raises(ValueError, match="colour classes"):
        ParallaxMap((0, 0), np.ones(80), [((0, 0), spot), ((0.5, 0), stranger)])
