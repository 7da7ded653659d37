"""Saving and loading a CompassAtlas: exact round trip, clear errors for bad files."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera, CompassAtlas, VisualCompass
from vc_gym.errors import MapFileError
from vc_gym.worlds.room import render_room_view


@pytest.fixture(scope="module")
def saved(room_atlas, tmp_path_factory):
    path = room_atlas.save(tmp_path_factory.mktemp("atlas") / "atlas", metadata={"seed": 3})
    return path


def test_round_trip_gives_identical_estimates(room_atlas, synthetic_room, saved):
    assert saved.suffix == ".npz"
    loaded, meta = CompassAtlas.load_with_metadata(saved)
    assert meta == {"seed": 3}
    assert loaded.names == room_atlas.names
    assert loaded.home == room_atlas.home and loaded.home_position == room_atlas.home_position
    np.testing.assert_array_equal(loaded.positions, room_atlas.positions)
    assert loaded.is_normalized
    # shared colour classes stay shared (the atlas computes features once)
    assert all(vc.colors is loaded.compasses[0].colors for vc in loaded.compasses)
    for x, y, yaw in ((0.0, 0.0, 10.0), (0.7, -0.4, 200.0)):
        img = render_room_view(synthetic_room, x, y, Camera(yaw_deg=yaw))
        a = room_atlas.estimate_position(img, Camera())
        b = loaded.estimate_position(img, Camera())
        assert a.position == b.position
        assert a.goodness == b.goodness


def _rewrite(src, dst, change):
    with np.load(src) as data:
        arrays = {k: data[k] for k in data.files}
    change(arrays)
    np.savez_compressed(dst, **arrays)
    return dst


def test_a_single_compass_file_is_not_an_atlas(room_atlas, tmp_path):
    path = room_atlas.compasses[0].save(tmp_path / "one.npz")
    with pytest.raises(MapFileError, match="expected a 'vc_gym.CompassAtlas'"):
        CompassAtlas.load(path)
    assert isinstance(VisualCompass.load(path), VisualCompass)


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda a: a.pop("spot1/counts"), "spot1|spot 'east'|counts"),
        (lambda a: a.__setitem__("home_scores", np.full((2, 1), np.nan)), "home_scores"),
        (lambda a: a.__setitem__("atlas", np.array("{not json")), "not valid JSON"),
        (lambda a: a.__setitem__("atlas", np.array('{"names": 3}')), "invalid atlas header"),
    ],
)
def test_bad_files_give_map_file_errors(saved, tmp_path, change, message):
    bad = _rewrite(saved, tmp_path / "bad.npz", change)
    with pytest.raises(MapFileError, match=message):
        CompassAtlas.load(bad)


def test_truncated_file(saved, tmp_path):
    bad = tmp_path / "cut.npz"
    bad.write_bytes(saved.read_bytes()[:200])
    with pytest.raises(MapFileError, match="cut.npz"):
        CompassAtlas.load(bad)


def _with_landmarks(atlas, tmp_path, **changes):
    from vc_gym.compass.landmarks import LandmarkMap

    n = atlas.compasses[0].config.n_colors
    fields = {
        "positions": np.array([[2.0, -1.0], [-2.5, 0.5]]),
        "pairs": np.array([3, n * n - 1]),
        "std_m": np.array([0.01, 0.02]),
        "support": np.array([4, 7]),
        "n_colors": n,
        "eye_forward_m": 0.25,
    }
    fields.update(changes)
    atlas.landmarks = LandmarkMap(**fields)
    try:
        return atlas.save(tmp_path / "with_landmarks.npz")
    finally:
        atlas.landmarks = None


def test_the_landmarks_are_saved_with_the_atlas(room_atlas, saved, tmp_path):
    assert CompassAtlas.load(saved).landmarks is None  # an atlas learned without them
    loaded = CompassAtlas.load(_with_landmarks(room_atlas, tmp_path)).landmarks
    np.testing.assert_array_equal(loaded.positions, [[2.0, -1.0], [-2.5, 0.5]])
    assert loaded.pairs.tolist()[0] == 3 and loaded.support.tolist() == [4, 7]
    assert loaded.n_colors == room_atlas.compasses[0].config.n_colors
    assert loaded.eye_forward_m == 0.25  # where the camera sat: the sensor's too
    assert loaded.bands == ((0.5, 4.0),)  # the bands its changes were read in
    assert loaded.light_gain == 1.0  # learned at the colour classes' light
    darker = CompassAtlas.load(_with_landmarks(room_atlas, tmp_path, light_gain=2.0))
    assert darker.landmarks.light_gain == 2.0  # a frame is read relative to it


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"positions": np.array([[np.nan, 0.0], [1.0, 1.0]])}, "finite"),
        ({"positions": np.array([[1e9, 0.0], [1.0, 1.0]])}, "finite"),
        ({"pairs": np.array([3, 10_000])}, "colour classes"),
        ({"pairs": np.array([-1, 3])}, "colour classes"),
        ({"std_m": np.array([-0.1, 0.1])}, "std_m"),
        ({"support": np.array([1, 5])}, "2 positions"),
        ({"std_m": np.array([0.1])}, "count"),
        ({"eye_forward_m": 5.0}, "eye_forward_m"),
        ({"eye_forward_m": float("nan")}, "eye_forward_m"),
        ({"bands": ((4.0, 1.0),)}, "band"),
        ({"bands": ((0.5, float("nan")),)}, "band"),
        ({"bands": ()}, "bands must number"),
        ({"bands": ((0.5, 4.0),) * 17}, "bands must number"),
        ({"light_gain": 0.0}, "light_gain"),
        ({"light_gain": float("inf")}, "light_gain"),
        ({"light_gain": 2.0**9}, "light_gain"),
    ],
)
def test_bad_landmarks_in_a_file_are_refused(room_atlas, tmp_path, changes, message):
    path = _with_landmarks(room_atlas, tmp_path, **changes)
    with pytest.raises(MapFileError, match=message):
        CompassAtlas.load(path)
