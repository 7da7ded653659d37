"""BearingTracker: the pose tracker's particles weighed also by the landmarks' bearings.

Known answers come from the ray-cast field of the pose tracker's tests
(:mod:`raycast_field`): the same walk, odometry and kidnapping, the landmarks learned
from the atlas' own turns at their known poses.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from raycast_field import AROUND, SPOTS, YAWS, field_atlas, field_room, walk

from vc_gym.compass import Camera
from vc_gym.compass.bearings import bands_bearings
from vc_gym.compass.landmarks import LearnedView, learn_landmarks
from vc_gym.localization import BearingTracker, PoseTracker, Tracker, make_tracker
from vc_gym.worlds.room import render_room_view


@pytest.fixture(scope="module")
def room():
    return field_room()


@pytest.fixture(scope="module")
def atlas(room, learn_room_turn):
    """The field's atlas with the landmarks its turns saw."""
    atlas = field_atlas(room, learn_room_turn)
    colors = atlas.compasses[0].colors
    views = []
    for x, y in SPOTS:
        for (dx, dy), yaws in [((0.0, 0.0), YAWS)] + [(d, YAWS[1::3]) for d in AROUND.values()]:
            for a in yaws:
                camera = Camera(yaw_deg=a)
                image = render_room_view(room, x + dx, y + dy, camera)
                views.append(LearnedView(bands_bearings(image, camera, colors), a, x + dx, y + dy))
    atlas.landmarks = learn_landmarks(views)
    return atlas


#: Frames of the walks scored: settled before the kidnapping (frame 130), and 3 s after.
SCORED = np.r_[50:130, 160:260]


@pytest.fixture(scope="module")
def walks(room, atlas):
    """Three kidnapped walks, tracked by the bearings and by the sector maps alone:
    ``{name: (frames, 3)}`` heading error, position error, stated heading spread."""
    out = {"bearings": [], "pose": []}
    for seed in (3, 4, 5):
        for name, tracker in (("bearings", BearingTracker), ("pose", PoseTracker)):
            errors = walk(room, atlas, tracker(seed=seed), frames=260, kidnap_at=130, seed=seed - 2)
            out[name].append(errors)
    return {name: np.stack(runs) for name, runs in out.items()}


def test_it_is_a_named_tracker():
    assert isinstance(make_tracker("bearings"), BearingTracker)
    assert make_tracker({"type": "bearings", "n_particles": 100}).n_particles == 100
    assert isinstance(BearingTracker(), Tracker)


def test_it_tracks_walks_finer_than_the_sector_maps(walks):
    """Measured: heading 1.4° and position 7.7 cm (mean), against 3.5° and 19 cm."""
    bearings = walks["bearings"][:, SCORED].reshape(-1, 3).mean(axis=0)
    pose = walks["pose"][:, SCORED].reshape(-1, 3).mean(axis=0)
    assert bearings[1] < 0.12 and bearings[1] < 0.6 * pose[1], (bearings, pose)
    assert bearings[0] < 2.5 and bearings[0] < 0.6 * pose[0], (bearings, pose)


def test_it_finds_the_robot_again_after_every_kidnapping(walks):
    """Within 10 s (measured: 2.7, 8.0 and 2.8 s)."""
    for run in walks["bearings"]:
        after = run[130:]
        ok = (after[:, 1] < 0.2) & (after[:, 0] < 5.0)
        found = next(i for i in range(len(after) - 20) if ok[i : i + 20].mean() >= 0.9)
        assert found < 100


def test_an_atlas_without_landmarks_is_warned_about_and_tracked_by_the_maps(room, atlas):
    plain = copy.copy(atlas)
    plain.landmarks = None
    tracker = BearingTracker(n_particles=64)
    with pytest.warns(UserWarning, match="no landmarks"):
        tracker.reset(plain, Camera(), 0.1)
    image = render_room_view(room, 0.0, 0.0, Camera())
    state = tracker.update(image, 0.0, (0.0, 0.0, 0.0))
    assert np.isfinite(state.position).all() and tracker.sensor is None


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"bearing_noise_deg": 0.0}, "bearing_noise_deg"),
        ({"bearing_outlier": 1.0}, "bearing_outlier"),
        ({"bearing_temperature": -1.0}, "bearing_temperature"),
        ({"resolution_m": -0.1}, "resolution_m"),
        ({"min_changes_alone": 0}, "min_changes_alone"),
    ],
)
def test_bad_settings_are_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        BearingTracker(**kwargs)
