"""exposure="map": the map learns the light per sector and undoes a change of light."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera, CompassAtlas, CompassConfig, MapFileError, VisualCompass, wrap180
from vc_gym.compass.light_map import GAIN_STEP_STOPS, LightMap, quantized_stops
from vc_gym.exposure import column_levels
from vc_gym.worlds.panorama import render_view

MAP = CompassConfig(exposure="map")


@pytest.fixture(scope="module")
def map_compass(room_pano, make_learned_compass) -> VisualCompass:
    return make_learned_compass(room_pano, MAP)


def test_column_levels_are_linear_light_per_column():
    pixels = np.zeros((4, 3, 3), np.uint8)
    pixels[:, 1] = 255
    pixels[:2, 2] = 255  # half the rows white
    np.testing.assert_allclose(column_levels(pixels), [0.0, 1.0, 0.5])
    assert column_levels(np.zeros((0, 5, 3), np.uint8)).shape == (5,)


def test_quantized_stops_are_thirds_of_a_stop_within_8_stops():
    gains = np.array([1.0, 2.0, 0.5, 1.26, 1e6, 1e-6])
    np.testing.assert_array_equal(quantized_stops(gains), [0, 3, -3, 1, 24, -24])
    assert GAIN_STEP_STOPS == pytest.approx(1 / 3)


def test_light_map_learns_the_mean_light_of_each_sector(map_compass):
    light = map_compass._light
    seen = light.columns > 0
    assert seen.all()  # the learning turn covers the circle
    mean = light.level_sum / light.columns
    assert np.all((mean > 0) & (mean < 1))
    assert mean.std() > 0.01  # the room is not equally bright in every direction


@pytest.mark.parametrize("illumination, steps", [(1.0, 0), (0.5, 3), (0.25, 6), (0.7, 2)])
def test_light_gain_of_a_view_undoes_the_change_of_light(
    room_pano, map_compass, illumination, steps
):
    # at least 9 of 10 views get the gain that undoes the darkening, to a step
    yaws = np.random.default_rng(5).uniform(0, 360, 10)
    found = []
    for yaw in yaws:
        img = render_view(room_pano, Camera(yaw_deg=yaw), illumination=illumination)
        found.append(round(np.log2(map_compass.light_gain(img, Camera())) / GAIN_STEP_STOPS))
    assert np.sum(np.abs(np.array(found) - steps) <= 1) >= 9, found


@pytest.mark.parametrize("illumination", [1.0, 0.5, 0.25])
def test_map_exposure_finds_the_heading_in_changed_light(
    room_pano, map_compass, illumination, view_heading_errors
):
    yaws = np.random.default_rng(16).uniform(0.0, 360.0, 20)
    errs = view_heading_errors(map_compass, room_pano, yaws, illumination)
    assert np.mean(errs < 5.0) >= 0.9, np.round(errs, 1)


def test_a_known_session_gain_is_one_classification(room_pano, map_compass):
    img = render_view(room_pano, Camera(yaw_deg=140.0), illumination=0.5)
    est = map_compass.estimate(img, Camera(), gain=2.0)
    assert abs(wrap180(est.heading_deg - 140.0)) < 5.0
    # gain 1 on a compass without light correction is the paper's likelihood
    plain = VisualCompass(CompassConfig(), map_compass.colors)
    plain._counts[:] = map_compass._counts
    plain._n_obs[:] = map_compass._n_obs
    plain._frames = map_compass.frames_learned
    plain._sizes = set(map_compass._sizes)
    np.testing.assert_array_equal(
        map_compass.log_likelihood(img, Camera(), gain=1.0), plain.log_likelihood(img, Camera())
    )


def test_gain_and_light_gain_reject_what_they_cannot_do(room_pano, map_compass):
    img = render_view(room_pano, Camera(yaw_deg=10.0))
    for bad in (0.0, -1.0, float("nan"), float("inf"), "2"):
        with pytest.raises(ValueError, match="gain"):
            map_compass.estimate(img, Camera(), gain=bad)
    mean = VisualCompass(CompassConfig(exposure="mean", n_colors=4))
    mean.fit_colors([img])
    mean.learn(img, Camera())
    with pytest.raises(ValueError, match="sets its own gain"):
        mean.log_likelihood(img, Camera(), gain=2.0)
    with pytest.raises(ValueError, match="exposure='map'"):
        mean.light_gain(img, Camera())


def test_light_map_survives_save_load_and_merge(tmp_path, room_pano, map_compass):
    loaded = VisualCompass.load(map_compass.save(tmp_path / "m.npz"))
    img = render_view(room_pano, Camera(yaw_deg=77.0), illumination=0.5)
    np.testing.assert_array_equal(
        loaded.log_likelihood(img, Camera()), map_compass.log_likelihood(img, Camera())
    )
    twice = VisualCompass.load(tmp_path / "m.npz").merge(loaded)
    np.testing.assert_array_equal(twice._light.level_sum, 2 * map_compass._light.level_sum)
    np.testing.assert_array_equal(twice._light.columns, 2 * map_compass._light.columns)
    twice.reset_map()
    assert not twice._light.columns.any()


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda a: a.pop("light_sum"), "light_sum"),
        (lambda a: a.update(light_columns=a["light_columns"][:5]), "light_columns"),
        (lambda a: a.update(light_sum=-a["light_sum"]), ">= 0"),
        (lambda a: a.update(light_sum=a["light_sum"] * np.nan), "finite"),
        (lambda a: a.update(light_sum=a["light_columns"] * 2.0), "exceeds"),
    ],
)
def test_a_map_file_with_a_broken_light_map_is_refused(tmp_path, map_compass, change, message):
    path = map_compass.save(tmp_path / "m.npz")
    with np.load(path, allow_pickle=False) as f:
        arrays = dict(f)
    change(arrays)
    np.savez(path, **arrays)
    with pytest.raises(MapFileError, match=message):
        VisualCompass.load(path)


def test_an_atlas_scores_each_map_with_its_own_light(room_pano, map_compass):
    other = VisualCompass(MAP, map_compass.colors)
    for yaw in range(0, 360, 30):
        other.learn(
            render_view(room_pano, Camera(yaw_deg=yaw), illumination=0.8), Camera(yaw_deg=yaw)
        )
    atlas = CompassAtlas({"a": ((0.0, 0.0), map_compass), "b": ((1.0, 0.0), other)}, home="a")
    img = render_view(room_pano, Camera(yaw_deg=250.0), illumination=0.5)
    scores, ests = atlas.scores(img, Camera())
    for vc, score, est in zip((map_compass, other), scores, ests, strict=True):
        alone = vc.estimate(img, Camera())
        assert score == alone.score and est.heading_deg == alone.heading_deg


def test_heading_gains_is_one_where_nothing_was_learned():
    light = LightMap(4)

    def gains() -> np.ndarray:
        # six scanned columns of light 0.3, three in each of two relative sectors;
        # heading h looks into map sectors h and h + 1
        return light.heading_gains(
            np.full(6, 0.3),
            first_col=np.array([0, 3]),
            stop_col=np.array([3, 6]),
            n_rel=2,
            heading_phase=np.zeros(4, np.intp),
            sector_of=np.array([[0, 1, 2, 3], [1, 2, 3, 0]]),
        )

    np.testing.assert_array_equal(gains(), 1.0)
    light.add(np.array([0, 0, 1]), np.array([0.6, 0.6, 0.15]))
    # heading 0 sees sectors 0 (0.6) and 1 (0.15): (0.6*3 + 0.15*3) / (0.3*6) = 1.25
    # heading 1 sees 1 and 2 (unknown): 0.15 / 0.3; heading 2 nothing known; heading 3: 2.0
    np.testing.assert_allclose(gains(), [1.25, 0.5, 1.0, 2.0])


def test_an_atlas_of_map_exposure_compasses_keeps_their_light(tmp_path, room_pano, map_compass):
    atlas = CompassAtlas({"a": ((0.0, 0.0), map_compass)}, home="a")
    loaded = CompassAtlas.load(atlas.save(tmp_path / "atlas.npz"))
    np.testing.assert_array_equal(loaded.compasses[0]._light.columns, map_compass._light.columns)
    img = render_view(room_pano, Camera(yaw_deg=300.0), illumination=0.5)
    assert loaded.scores(img, Camera())[0][0] == atlas.scores(img, Camera())[0][0]


def test_a_light_map_is_resampled_and_regrouped_like_the_counts():
    light = LightMap(4)
    light.add(np.array([0, 1, 1, 3]), np.array([0.2, 0.4, 0.6, 0.8]))
    copied = light.resampled(np.array([3, 3, 0, 1]))
    np.testing.assert_array_equal(copied.level_sum, [0.8, 0.8, 0.2, 1.0])
    np.testing.assert_array_equal(copied.columns, [1, 1, 1, 2])
    moved = light.regrouped(np.array([2, 2, 0, 0]))
    np.testing.assert_allclose(moved.level_sum, [0.8, 0.0, 1.2, 0.0])
    np.testing.assert_array_equal(moved.columns, [1, 0, 3, 0])
    np.testing.assert_array_equal(light.columns, [1, 2, 0, 1])  # the original is unchanged
