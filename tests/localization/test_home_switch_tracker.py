"""HomeSwitchTracker: the far tracker's state away from home, the near tracker's near it."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera, CompassAtlas
from vc_gym.localization import (
    GridTracker,
    HomeSwitchTracker,
    PoseTracker,
    TrackerState,
    make_tracker,
)


class Scripted:
    """A tracker that reports the positions it is given, one per update."""

    def __init__(self, positions, goodness):
        self.positions = list(positions)
        self.goodness = goodness
        self.frames = 0

    def reset(self, atlas, camera, dt_s):
        self.frames = 0

    def update(self, image, head_pan_deg, odometry):
        x, y = self.positions[self.frames]
        self.frames += 1
        return TrackerState(
            heading_deg=0.0,
            heading_spread_deg=1.0,
            position=(x, y),
            position_std_m=(0.1, 0.1),
            goodness=np.full(4, self.goodness),
            belief=np.full(360, 1 / 360),
            atlas_position=(self.goodness, self.goodness),
        )


def test_it_answers_with_far_away_from_home_and_with_near_at_home(room_atlas):
    home = room_atlas.home_position
    far_path = [(home[0] + d, home[1]) for d in (2.0, 0.8, 0.4, 0.1, 0.7)]
    far = Scripted(far_path, goodness=0.0)
    near = Scripted([(9.0, 9.0)] * len(far_path), goodness=1.0)
    t = HomeSwitchTracker(far, near, switch_m=0.5)
    t.reset(room_atlas, Camera(), 0.1)
    image = np.zeros((40, 52, 3), np.uint8)
    states = [t.update(image, 0.0, (0.0, 0.0, 0.0)) for _ in far_path]
    # within 0.5 m of home by the far tracker's position: the near tracker answers
    assert [s.position for s in states] == [
        far_path[0],
        far_path[1],
        (9.0, 9.0),
        (9.0, 9.0),
        far_path[4],
    ]
    assert far.frames == near.frames == len(far_path)  # both see every frame
    # the frame's goodness and eq. 30 position are always the near tracker's
    assert all(np.all(s.goodness == 1.0) and s.atlas_position == (1.0, 1.0) for s in states)


def test_it_is_named_pose_grid_with_the_pose_and_grid_trackers():
    t = make_tracker({"type": "pose-grid", "switch_m": 0.7})
    assert isinstance(t, HomeSwitchTracker) and t.switch_m == 0.7
    assert isinstance(t.far, PoseTracker) and isinstance(t.near, GridTracker)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"switch_m": 0.0}, "switch_m"),
        ({"switch_m": float("nan")}, "switch_m"),
        ({"switch_m": 1e9}, "switch_m"),
        ({"far": "pose"}, "far must be a tracker"),
        ({"near": object()}, "near must be a tracker"),
    ],
)
def test_bad_settings_are_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        HomeSwitchTracker(**kwargs)


def test_near_tracks_on_the_spots_without_the_turns_around_them(room_atlas, synthetic_room):
    from vc_gym.compass import CompassAtlas
    from vc_gym.worlds.room import render_room_view

    entries = {n: (tuple(p), c) for n, p, c in zip(*_parts(room_atlas), strict=True)}
    east = room_atlas.names.index("east")
    entries["east.e"] = ((1.5, 0.0), room_atlas.compasses[east])  # a turn learned around east
    atlas = CompassAtlas(entries, home=room_atlas.home, home_position=room_atlas.home_position)
    frames = [
        render_room_view(synthetic_room, 0.0, 0.0, Camera(yaw_deg=a)) for a in range(0, 360, 45)
    ]
    atlas.normalize(frames, [Camera()] * len(frames))
    t = HomeSwitchTracker(PoseTracker(n_particles=64), GridTracker())
    t.reset(atlas, Camera(), 0.1)
    assert t.near.atlas.names == room_atlas.names
    state = t.update(frames[1], 0.0, (0.0, 0.0, 0.0))
    assert state.goodness.shape == (len(atlas),)
    assert state.goodness[atlas.names.index("east.e")] == 0.0
    assert np.all(np.delete(state.goodness, atlas.names.index("east.e")) > 0)


def _parts(atlas):
    return atlas.names, atlas.positions, atlas.compasses


#: Home away from the origin and from every spot, so that a distance measured from
#: anywhere else switches at other places.
HOME = (0.4, -0.3)


def _shifted_home(atlas):
    """``atlas``'s spots with home at :data:`HOME`."""
    entries = {n: (tuple(p), c) for n, p, c in zip(*_parts(atlas), strict=True)}
    return CompassAtlas(entries, home="centre", home_position=HOME)


def _answers(atlas, offsets, switch_m):
    """Which tracker answered (``"far"``/``"near"``) and :attr:`near_home` after each
    update, with the far tracker placing the robot at ``offsets`` from :data:`HOME`."""
    far = Scripted([(HOME[0] + dx, HOME[1] + dy) for dx, dy in offsets], goodness=0.0)
    near = Scripted([(9.0, 9.0)] * len(offsets), goodness=1.0)
    t = HomeSwitchTracker(far, near, switch_m=switch_m)
    t.reset(atlas, Camera(), 0.1)
    image = np.zeros((40, 52, 3), np.uint8)
    out = []
    for _ in offsets:
        state = t.update(image, 0.0, (0.0, 0.0, 0.0))
        out.append(("near" if state.position == (9.0, 9.0) else "far", t.near_home))
    return out, t


def test_the_switch_is_at_switch_m_from_home_in_any_direction(room_atlas):
    """Just inside ``switch_m`` (Euclidean, from the atlas' home) the near tracker
    answers, just outside the far one: along an axis and along a diagonal, where a
    box (max of |dx|, |dy|) or a diamond (|dx| + |dy|) would switch elsewhere."""
    inside = [(0.79, 0.0), (0.0, -0.79), (0.6 * 0.79, 0.8 * 0.79), (-0.6 * 0.79, -0.8 * 0.79)]
    outside = [(0.81, 0.0), (0.0, -0.81), (0.6 * 0.81, 0.8 * 0.81), (-0.6 * 0.81, -0.8 * 0.81)]
    got, _ = _answers(_shifted_home(room_atlas), inside + outside, switch_m=0.8)
    assert [who for who, _ in got] == ["near"] * 4 + ["far"] * 4


def test_near_home_says_which_tracker_answered_the_last_frame(room_atlas):
    atlas = _shifted_home(room_atlas)
    got, t = _answers(atlas, [(2.0, 0.0), (0.1, 0.2), (0.0, -1.5), (0.0, 0.0)], switch_m=0.5)
    assert got == [("far", False), ("near", True), ("far", False), ("near", True)]
    t.reset(atlas, Camera(), 0.1)
    assert t.near_home is False  # a new run starts away from home until a frame says so
    assert HomeSwitchTracker(switch_m=0.5).near_home is False


def test_update_before_reset_is_refused_before_either_tracker_sees_the_frame():
    far = Scripted([(0.0, 0.0)], goodness=0.0)
    near = Scripted([(0.0, 0.0)], goodness=1.0)
    t = HomeSwitchTracker(far, near)
    with pytest.raises(RuntimeError, match=r"reset\(atlas, camera, dt_s\) before update"):
        t.update(np.zeros((40, 52, 3), np.uint8), 0.0, (0.0, 0.0, 0.0))
    assert far.frames == near.frames == 0
