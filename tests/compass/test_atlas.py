"""Several spots (eq. 28-30) in a synthetic room with real parallax."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.compass import (
    Camera,
    CompassAtlas,
    CompassConfig,
    NotLearnedError,
    VisualCompass,
    likelihood,
)
from vc_gym.worlds.room import render_room_view

TEST_YAWS = (10.0, 100.0, 200.0, 290.0)


@pytest.fixture(scope="module")
def room(synthetic_room):
    return synthetic_room


@pytest.fixture(scope="module")
def atlas(room_atlas):
    return room_atlas


def mean_position(atlas, room, x, y):
    pos = [
        atlas.estimate_position(render_room_view(room, x, y, Camera(yaw_deg=a)), Camera()).position
        for a in TEST_YAWS
    ]
    return np.mean(pos, axis=0)


def test_home_is_estimated_at_home(atlas, room):
    assert atlas.home_position == (0.0, 0.0)
    assert np.hypot(*mean_position(atlas, room, 0.0, 0.0)) < 0.15


@pytest.mark.parametrize("true", [(1.0, 0.0), (0.0, -1.0), (0.5, 0.0), (-0.5, 0.0)])
def test_position_moves_towards_the_true_offset(atlas, room, true):
    est = mean_position(atlas, room, *true)
    bearing_err = math.degrees(
        abs(math.remainder(math.atan2(est[1], est[0]) - math.atan2(true[1], true[0]), math.tau))
    )
    assert bearing_err < 30.0, est
    assert np.hypot(*est) > 0.25 * np.hypot(*true), est


def test_goodness_is_one_at_home_after_normalisation(atlas, room):
    est = atlas.estimate_position(render_room_view(room, 0.0, 0.0, Camera(yaw_deg=40.0)), Camera())
    assert set(est.goodness) == {"east", "north", "west", "south"}
    for g in est.goodness.values():
        assert g == pytest.approx(1.0, abs=0.1)
    assert sum(est.weights.values()) == pytest.approx(1.0)
    for e in est.estimates.values():
        assert abs(math.remainder(e.heading_deg - 40.0, 360.0)) < 20.0  # 1 m of parallax


def test_equal_goodness_gives_the_centroid(room):
    vc = VisualCompass(CompassConfig(n_colors=3))
    vc.fit_colors([render_room_view(room, 0.0, 0.0, Camera())])
    vc.learn(render_room_view(room, 0.0, 0.0, Camera()), Camera())
    atlas = CompassAtlas({"a": ((0.0, 0.0), vc), "b": ((2.0, 4.0), vc)}, home="a")
    est = atlas.estimate_position(render_room_view(room, 0.5, 0.5, Camera()), Camera())
    assert est.position == pytest.approx((1.0, 2.0))
    assert atlas.home_position == (0.0, 0.0)


def test_bad_atlas_arguments(room):
    vc = VisualCompass()
    with pytest.raises(ValueError):
        CompassAtlas({}, home="x")
    with pytest.raises(ValueError):
        CompassAtlas({"a": (0.0, vc)}, home="a")
    with pytest.raises(ValueError):
        CompassAtlas({"a": ((0.0, float("nan")), vc)}, home="a")
    with pytest.raises(ValueError):
        CompassAtlas({"a": ((0.0, 0.0), "not a compass")}, home="a")
    with pytest.raises(ValueError, match="CompassConfig"):
        CompassAtlas(
            {"a": ((0, 0), vc), "b": ((1, 0), VisualCompass(CompassConfig(n_colors=3)))}, home="a"
        )
    with pytest.raises(ValueError):
        CompassAtlas({"a": ((0.0, 0.0), vc)}, home="a", sharpness=0.0)
    atlas = CompassAtlas({"a": ((0.0, 0.0), vc)}, home="a")
    img = render_room_view(room, 0.0, 0.0, Camera())
    with pytest.raises(NotLearnedError):
        atlas.estimate_position(img, Camera())
    with pytest.raises(ValueError):
        atlas.normalize([img, img], [Camera()])


@pytest.mark.parametrize("pose", [(0.0, 0.0, 10.0), (0.7, -0.4, 200.0), (-1.2, 0.9, 290.0)])
def test_all_spots_at_once_equal_each_compass_on_its_own(atlas, room, pose):
    x, y, yaw = pose
    image = render_room_view(room, x, y, Camera(yaw_deg=yaw))
    raw, together = atlas.scores(image, Camera())
    for vc, est, score in zip(atlas.compasses, together, raw, strict=True):
        alone = vc.estimate(image, Camera())
        np.testing.assert_array_equal(est.log_likelihood, alone.log_likelihood)
        np.testing.assert_array_equal(est.log_likelihood, vc.log_likelihood(image, Camera()))
        assert est.heading_deg == alone.heading_deg and est.score == alone.score == score
        assert est.n_sectors == alone.n_sectors
        assert est.spread_deg == alone.spread_deg
    # a map that learns more gets new tables: the stacked ones follow
    before = atlas.scores(image, Camera())[0]
    extra = VisualCompass(atlas.compasses[0].config, atlas.compasses[0].colors)
    extra.learn(image, Camera(yaw_deg=yaw))
    grown = CompassAtlas(
        {"a": ((0.0, 0.0), atlas.compasses[0]), "b": ((1.0, 0.0), extra)}, home="a"
    )
    first = grown.scores(image, Camera())[0]
    extra.learn(render_room_view(room, x, y, Camera(yaw_deg=yaw + 90)), Camera(yaw_deg=yaw + 90))
    second = grown.scores(image, Camera())[0]
    assert first[0] == second[0] == before[0] and first[1] != second[1]
    assert second[1] == extra.estimate(image, Camera()).score


def test_a_subset_of_spots_equals_their_part_of_the_full_answer(atlas, room):
    image = render_room_view(room, 0.4, -0.3, Camera(yaw_deg=120.0))
    raw, full = atlas.scores(image, Camera())
    some = [2, 0]
    part_raw, part = atlas.scores(image, Camera(), spots=some)
    np.testing.assert_array_equal(part_raw, raw[some])
    for k, est in zip(some, part, strict=True):
        np.testing.assert_array_equal(est.log_likelihood, full[k].log_likelihood)
        assert est.heading_deg == full[k].heading_deg
    est = atlas.estimate_position(image, Camera(), spots=some)
    names = [atlas.names[k] for k in some]
    assert list(est.goodness) == list(est.weights) == list(est.estimates) == names
    assert sum(est.weights.values()) == pytest.approx(1.0)
    # eq. 30 over the subset: a weighted mean of those spots only
    expected = sum(est.weights[n] * atlas.positions[atlas.names.index(n)] for n in names)
    assert est.position == pytest.approx(tuple(expected))
    everything = atlas.estimate_position(image, Camera())
    whole = atlas.estimate_position(image, Camera(), spots=range(len(atlas)))
    assert whole.position == everything.position and whole.goodness == everything.goodness


def test_the_atlas_of_some_spots_scores_and_normalises_them_as_the_whole_did(atlas, room):
    image = render_room_view(room, 0.4, -0.3, Camera(yaw_deg=120.0))
    names = ["west", "east"]
    part = atlas.subset(names)
    assert part.names == tuple(names) and part.is_normalized
    assert part.home_position == atlas.home_position and part.sharpness == atlas.sharpness
    whole = atlas.estimate_position(image, Camera(), spots=[atlas.names.index(n) for n in names])
    est = part.estimate_position(image, Camera())
    assert est.goodness == whole.goodness and est.position == whole.position


@pytest.mark.parametrize("names", [[], ["east", "east"], ["home"], "east"])
def test_a_subset_names_distinct_spots_of_the_atlas(atlas, names):
    with pytest.raises(ValueError, match="subset"):
        atlas.subset(names)


@pytest.mark.parametrize("spots", [[], [0, 0], [-1], [99], [0.5], "ab", [[0, 1]]])
def test_bad_spot_subsets_are_refused(atlas, room, spots):
    image = render_room_view(room, 0.0, 0.0, Camera())
    with pytest.raises(ValueError, match="spots"):
        atlas.estimate_position(image, Camera(), spots=spots)


def test_a_narrow_normalisation_kernel_keeps_the_position_finite(atlas, room):
    # kernel_deg=0.01 underflows every raw home weight to 0 (0 / 0: position (nan, nan))
    spots = zip(atlas.names, atlas.positions, atlas.compasses, strict=True)
    fresh = CompassAtlas(
        {n: (tuple(p), vc) for n, p, vc in spots},
        home=atlas.home,
        home_position=atlas.home_position,
    )
    homes = [render_room_view(room, 0.0, 0.0, Camera(yaw_deg=a)) for a in (0.0, 120.0, 240.0)]
    fresh.normalize(homes, [Camera()] * 3, kernel_deg=0.01)
    est = fresh.estimate_position(render_room_view(room, 0.3, 0.2, Camera(yaw_deg=75.0)), Camera())
    assert np.all(np.isfinite(est.position))
    assert all(math.isfinite(g) and g > 0 for g in est.goodness.values())


@pytest.mark.parametrize("gather_bytes", [1, 1 << 12, 1 << 40])
def test_scores_do_not_depend_on_how_many_rows_are_gathered_at_once(
    atlas, room, monkeypatch, gather_bytes
):
    # one group per gather, a few groups, and every row at once give the same sums
    image = render_room_view(room, 0.3, 0.6, Camera(yaw_deg=75.0))
    raw, full = atlas.scores(image, Camera())
    monkeypatch.setattr(likelihood, "_GATHER_BYTES", gather_bytes)
    raw2, full2 = atlas.scores(image, Camera())
    np.testing.assert_array_equal(raw2, raw)
    for a, b in zip(full, full2, strict=True):
        np.testing.assert_array_equal(a.log_likelihood, b.log_likelihood)
    part = atlas.scores(image, Camera(), spots=[1])[1][0]
    np.testing.assert_array_equal(part.log_likelihood, full[1].log_likelihood)
