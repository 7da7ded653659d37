"""PoseTracker: a pose belief over the whole field, on maps re-drawn for each position.

Known answers come from the ray-cast room (:mod:`vc_gym.worlds.room`): a walk with true
poses, odometry with scale errors and noise, and a kidnapping.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from raycast_field import AROUND, SPOTS, YAWS, field_atlas, field_room, walk

from vc_gym.compass import Camera, CompassAtlas, CompassConfig, VisualCompass
from vc_gym.exposure import SessionLight, rounded_gain
from vc_gym.localization import PoseTracker, Tracker, make_tracker
from vc_gym.worlds.room import render_room_view


@pytest.fixture(scope="module")
def room():
    return field_room()


@pytest.fixture(scope="module")
def atlas(room, learn_room_turn):
    return field_atlas(room, learn_room_turn)


_walk = walk


@pytest.fixture(scope="module")
def kidnapped_walk(room, atlas):
    return _walk(room, atlas, PoseTracker(seed=3), frames=260, kidnap_at=130)


def test_it_is_a_named_tracker():
    assert isinstance(make_tracker("pose"), PoseTracker)
    assert make_tracker({"type": "pose", "n_particles": 100}).n_particles == 100
    assert isinstance(PoseTracker(), Tracker)


def test_it_tracks_a_walk(kidnapped_walk):
    settled = kidnapped_walk[50:130]
    assert np.mean(settled[:, 0]) < 8.0  # degrees
    assert np.mean(settled[:, 1]) < 0.35  # metres


def test_it_finds_the_robot_again_after_a_kidnapping(kidnapped_walk):
    after = kidnapped_walk[130:]
    ok = (after[:, 1] < 0.4) & (after[:, 0] < 15.0)
    # within 5 s (50 frames) the belief is back, and stays mostly right
    found = next(i for i in range(len(after) - 20) if ok[i : i + 20].mean() >= 0.9)
    assert found < 50
    assert np.mean(after[found + 20 :, 1]) < 0.35


def test_the_same_seed_gives_the_same_walk(room, atlas):
    a = _walk(room, atlas, PoseTracker(n_particles=100, seed=4), frames=30)
    b = _walk(room, atlas, PoseTracker(n_particles=100, seed=4), frames=30)
    np.testing.assert_array_equal(a, b)


def test_particles_and_state(room, atlas):
    t = PoseTracker(n_particles=64)
    t.reset(atlas, Camera(), 0.1)
    s = t.update(render_room_view(room, 0.0, 0.0, Camera(yaw_deg=90.0)), 0.0, (0.0, 0.0, 0.0))
    assert t.particles.shape == (64, 3) and t.weights.shape == (64,)
    assert math.isclose(t.weights.sum(), 1.0)
    assert s.belief.shape == (360,) and math.isclose(s.belief.sum(), 1.0)
    assert s.goodness.shape == (len(atlas.names),)
    assert 0.0 <= s.heading_deg < 360.0 and s.heading_spread_deg <= 180.0


def test_a_frame_with_nothing_in_view_keeps_the_belief(room, atlas):
    t = PoseTracker(n_particles=64)
    t.reset(atlas, Camera(), 0.1)
    t.update(render_room_view(room, 0.0, 0.0, Camera(yaw_deg=90.0)), 0.0, (0.0, 0.0, 0.0))
    before = t.particles
    t.update(np.zeros((160, 208, 3), np.uint8), 0.0, (0.0, 0.0, 0.0))
    assert np.abs(t.particles[:, :2] - before[:, :2]).max() < 0.2  # motion noise only


def test_an_atlas_without_turns_around_its_spots_is_warned_about(atlas):
    spots = [k for k, n in enumerate(atlas.names) if "." not in n]
    plain = CompassAtlas(
        {atlas.names[k]: (tuple(atlas.positions[k]), atlas.compasses[k]) for k in spots},
        home="spot0",
    )
    with pytest.warns(UserWarning, match="no turns learned around its spots"):
        PoseTracker(n_particles=16).reset(plain, Camera(), 0.1)


def test_the_stated_uncertainty_adds_the_maps_resolution(room, atlas):
    image = render_room_view(room, 0.3, 0.1, Camera(yaw_deg=60.0))
    states = {}
    for r in (0.0, 0.25):
        t = PoseTracker(n_particles=200, resolution_m=r, resolution_deg=4.0 * r, seed=2)
        t.reset(atlas, Camera(), 0.1)
        states[r] = t.update(image, 0.0, (0.0, 0.0, 0.0))
    bare, stated = states[0.0], states[0.25]
    assert stated.position == bare.position and stated.heading_deg == bare.heading_deg
    for b, s in zip(bare.position_std_m, stated.position_std_m, strict=True):
        assert math.isclose(s, math.hypot(b, 0.25))
    assert math.isclose(stated.heading_spread_deg, math.hypot(bare.heading_spread_deg, 1.0))


@pytest.mark.parametrize("rule", ["nearest", "best2"])
def test_either_spot_rule_tracks(room, atlas, rule):
    walk = _walk(room, atlas, PoseTracker(n_particles=200, spot_rule=rule, seed=3), frames=80)
    assert np.mean(walk[30:, 0]) < 10.0 and np.mean(walk[30:, 1]) < 0.4


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"n_particles": 0}, "n_particles"),
        ({"temperature": 0}, "temperature"),
        ({"outlier": 1.0}, "outlier"),
        ({"motion_noise": (0.1, 0.1)}, "motion_noise"),
        ({"motion_noise": (0.1, -0.1, 1.0)}, "motion_noise"),
        ({"rescore_every": 0}, "rescore_every"),
        ({"reset_fraction": 1.5}, "reset_fraction"),
        ({"inject_fraction": -0.1}, "inject_fraction"),
        ({"lost_checks": 0}, "lost_checks"),
        ({"reset_spread_m": 0}, "reset_spread_m"),
        ({"margin_m": 1e9}, "margin_m"),
        ({"light_window": 0}, "light_window"),
        ({"seed": 1.5}, "seed"),
        ({"lattice_m": float("nan")}, "lattice_m"),
        ({"resolution_m": -0.1}, "resolution_m"),
        ({"resolution_deg": 200.0}, "resolution_deg"),
        ({"spot_rule": "best"}, "spot_rule"),
        ({"odometry_noise": -0.1}, "odometry_noise"),
        ({"odometry_noise": 1.5}, "odometry_noise"),  # a fraction of the odometry
        ({"odometry_noise": float("nan")}, "odometry_noise"),
        ({"lost_nats": -1.0}, "lost_nats"),
        ({"lost_nats": float("inf")}, "lost_nats"),
        ({"lost_nats": "3"}, "lost_nats"),
        ({"reach_m": 0.0}, "reach_m"),
        ({"reach_m": float("nan")}, "reach_m"),
        # the pose maps' lattice is precomputed: refused here, not at the first reset
        ({"reach_m": 1e9}, "reach_m"),
        ({"lattice_m": 0.001}, "reach_m / lattice_m"),
    ],
)
def test_bad_settings_are_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        PoseTracker(**kwargs)


def test_update_before_reset_and_bad_frames_are_refused(room, atlas):
    with pytest.raises(RuntimeError, match="reset"):
        PoseTracker().update(np.zeros((160, 208, 3), np.uint8), 0.0, (0, 0, 0))
    t = PoseTracker(n_particles=16)
    t.reset(atlas, Camera(), 0.1)
    with pytest.raises(ValueError, match="odometry"):
        t.update(np.zeros((160, 208, 3), np.uint8), 0.0, (0, np.nan, 0))
    with pytest.raises(ValueError):
        t.update(np.zeros((160, 208), np.uint8), 0.0, (0, 0, 0))


#: The box the particles are kept in with ``margin_m=0.3``: the spots (not the turns
#: learned 0.5 m around them) grown by 0.3 m.
BOX_LO, BOX_HI = np.array([-1.3, -1.05]), np.array([1.3, 1.05])


def test_particles_moved_out_of_the_room_are_put_on_its_edge(room, atlas):
    """A 10 m step takes every particle out of the spots' box grown by ``margin_m``:
    each is clipped back onto the edge it crossed (the robot stays in the room)."""
    t = PoseTracker(n_particles=64, margin_m=0.3, seed=1)
    t.reset(atlas, Camera(), 0.1)
    image = render_room_view(room, 0.0, 0.0, Camera(yaw_deg=90.0))
    t.update(image, 0.0, (0.0, 0.0, 0.0))
    t.update(image, 0.0, (10.0, 0.0, 0.0))
    p = t.particles
    assert np.all(p[:, :2] >= BOX_LO) and np.all(p[:, :2] <= BOX_HI)
    # 10 ± 3 m along the particle's own heading (1° of turn noise): it left the box
    # through the edge its heading points at
    c, s = np.cos(np.radians(p[:, 2])), np.sin(np.radians(p[:, 2]))
    for lean, xy, edge in ((c, 0, BOX_HI), (-c, 0, BOX_LO), (s, 1, BOX_HI), (-s, 1, BOX_LO)):
        np.testing.assert_array_equal(p[lean > 0.5, xy], edge[xy])
    assert np.all(np.maximum(np.abs(c), np.abs(s)) > 0.5)  # every particle was checked


def test_poses_drawn_around_the_spots_stay_in_the_room(room, atlas):
    """The first frame draws poses around the spots (σ ``reset_spread_m``, here far
    wider than the room): they are clipped into the box, reaching all four edges."""
    t = PoseTracker(n_particles=200, margin_m=0.3, reset_spread_m=5.0, seed=1)
    t.reset(atlas, Camera(), 0.1)
    t.update(render_room_view(room, 0.0, 0.0, Camera(yaw_deg=90.0)), 0.0, (0.0, 0.0, 0.0))
    xy = t.particles[:, :2]
    np.testing.assert_array_equal(xy.min(axis=0), BOX_LO)
    np.testing.assert_array_equal(xy.max(axis=0), BOX_HI)


@pytest.fixture(scope="module")
def session_atlas(room):
    """Two of the spots, each with its four turns around it, learned with
    ``exposure="session"`` (colour classes and reference light from spot0's views)."""
    config, colors, entries = CompassConfig(exposure="session"), None, {}
    for i, (x, y) in enumerate(SPOTS[:2]):
        for side, (dx, dy) in {"": (0.0, 0.0), **AROUND}.items():
            vc = VisualCompass(config, colors)
            if colors is None:
                vc.fit_colors(
                    [render_room_view(room, x, y, Camera(yaw_deg=a)) for a in range(0, 360, 45)]
                )
                colors = vc.colors
            for a in YAWS if not side else YAWS[1::3]:
                vc.learn(
                    render_room_view(room, x + dx, y + dy, Camera(yaw_deg=a)), Camera(yaw_deg=a)
                )
            entries[f"spot{i}.{side}" if side else f"spot{i}"] = ((x + dx, y + dy), vc)
    return CompassAtlas(entries, home="spot0")


def test_session_maps_score_every_frame_at_the_sessions_light(room, session_atlas, monkeypatch):
    """With ``exposure="session"`` maps every frame is scored at one gain: the median
    of the last ``light_window`` frames' gains (:class:`SessionLight`), not the frame's
    own. Three frames at full light, then three at a quarter of it: once the window
    holds only dark frames the gain is 4 times the bright frames'."""
    t = PoseTracker(n_particles=32, light_window=3)
    t.reset(session_atlas, Camera(), 0.1)
    gains = []
    frame = t.maps.frame

    def scored(image, camera, spots=None, gain=None):
        gains.append(gain)
        return frame(image, camera, spots, gain)

    monkeypatch.setattr(t.maps, "frame", scored)
    frames = [
        render_room_view(room, -0.8, -0.6, Camera(yaw_deg=yaw), illumination=light)
        for light in (1.0, 0.25)
        for yaw in (10.0, 130.0, 250.0)
    ]
    for image in frames:
        t.update(image, 0.0, (0.0, 0.0, 0.0))
    own = [session_atlas.frame_gain(image, Camera()) for image in frames]
    session = SessionLight(3)
    assert gains == [session.update(g) for g in own]
    assert gains[-1] == pytest.approx(4.0 * gains[2])
    assert len(t.light) == 3
    # the frames' own gains differ from the session's: the test tells the two apart
    assert gains != [rounded_gain(g) for g in own]
