"""The calibrated heading spread: the temperature, its fit, its file entries, no evidence."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.angles import circular_std, wrap180
from vc_gym.compass import Camera, CompassAtlas, CompassConfig, MapFileError, VisualCompass
from vc_gym.compass.calibration import (
    MIN_CALIBRATION_FRAMES,
    TEMPERATURES,
    UNCALIBRATED,
    check_spread_calibration,
    fit_temperature,
    tempered_spreads,
)
from vc_gym.compass.map_files import read_map_file, write_map_file
from vc_gym.filters import HeadingGridFilter, KalmanHeadingFilter
from vc_gym.worlds.panorama import render_view

H = np.arange(360.0)
#: The yaws the conftest's ``learned_compass`` learns (8 directions x 3 head pans).
LEARN_YAWS = [body + pan for body in range(0, 360, 45) for pan in (-22.5, 0.0, 22.5)]


def gaussian_lls(centres: np.ndarray, width_deg: float) -> np.ndarray:
    """Rows ``-0.5 (d / width)²`` peaked at ``centres``: a posterior of spread ``width``."""
    d = wrap180(H[None, :] - np.asarray(centres, dtype=float)[:, None])
    return -0.5 * (d / width_deg) ** 2


@pytest.fixture(scope="module")
def calibrated(room_pano, make_learned_compass) -> tuple[VisualCompass, object]:
    """A compass of its own (the session's is shared), calibrated on its learning turn."""
    vc = make_learned_compass(room_pano)
    images = [render_view(room_pano, Camera(yaw_deg=y)) for y in LEARN_YAWS]
    report = vc.calibrate(images, [Camera(yaw_deg=y) for y in LEARN_YAWS], leave_one_out=True)
    return vc, report


# ---------------------------------------------------------------- the spread and its fit
def test_a_temperature_widens_the_spread_by_its_square_root_and_the_floor_holds():
    ll = gaussian_lls([100.0], 2.0)
    assert tempered_spreads(ll, H, 1.0, 0.0)[0] == pytest.approx(2.0, rel=1e-3)
    assert tempered_spreads(ll, H, 4.0, 0.0)[0] == pytest.approx(4.0, rel=1e-3)
    assert tempered_spreads(ll, H, 1.0, 3.0)[0] == 3.0
    sharp = gaussian_lls([100.0], 0.01)
    assert tempered_spreads(sharp, H, 1.0, 0.0)[0] == pytest.approx(0.0, abs=1e-6)
    assert tempered_spreads(sharp, H, 1.0, 0.5)[0] == 0.5


def test_uncalibrated_it_is_the_papers_eq27_spread():
    rng = np.random.default_rng(0)
    ll = rng.normal(0.0, 3.0, (4, 360))
    got = tempered_spreads(ll, H, *UNCALIBRATED)
    for row, s in zip(ll, got, strict=True):
        assert s == pytest.approx(circular_std(H, np.exp(row - row.max())), rel=1e-12)


def test_the_fitted_temperature_matches_the_spread_of_the_errors():
    # every posterior 1° wide, the errors 3° wide: T = 9 makes the spreads 3°
    rng = np.random.default_rng(1)
    truth = rng.uniform(0, 360, 400)
    est = truth + rng.normal(0.0, 3.0, truth.size)
    ll = gaussian_lls(np.round(est), 1.0)
    errors = np.abs(wrap180(np.round(est) - truth))
    t = fit_temperature(ll, errors, H, 0.5)
    assert 7.0 < t < 11.5
    s = tempered_spreads(ll, H, t, 0.5)
    assert np.mean(errors <= 2 * s) == pytest.approx(0.95, abs=0.04)
    assert np.mean(errors <= s) == pytest.approx(0.68, abs=0.06)


def test_errors_below_the_floor_keep_the_largest_temperature_that_stays_at_the_floor():
    ll = gaussian_lls(np.arange(10) * 30.0, 0.1)  # 0.1° posteriors
    t = fit_temperature(ll, np.full(10, 0.2), H, 0.5)
    # the spreads, about 0.1 * sqrt(T) on the grid, stay at the floor up to T ~ 25-30;
    # the next candidate already widens them
    assert 20.0 < t < 40.0
    assert np.all(tempered_spreads(ll, H, t, 0.5) == 0.5)
    hotter = TEMPERATURES[TEMPERATURES > t][0]
    assert np.all(tempered_spreads(ll, H, hotter, 0.5) > 0.5)


@pytest.mark.parametrize(
    "ll, errors, message",
    [
        (np.zeros((MIN_CALIBRATION_FRAMES - 1, 360)), np.zeros(4), "at least"),
        (np.zeros((6, 360)), np.zeros(5), "need"),
        (np.zeros((6, 359)), np.zeros(6), "need"),
        (np.zeros((6, 360)), np.array([0, 0, 0, 0, 0, np.nan]), "finite"),
    ],
)
def test_a_fit_on_bad_input_says_why(ll, errors, message):
    with pytest.raises(ValueError, match=message):
        fit_temperature(ll, errors, H, 0.5)


@pytest.mark.parametrize(
    "temperature, floor, message",
    [
        (0.0, 0.5, "temperature"),
        (1e4, 0.5, "temperature"),
        (math.nan, 0.5, "temperature"),
        (2.0, -1.0, "floor"),
        (2.0, 100.0, "floor"),
        ("hot", 0.5, "temperature"),
    ],
)
def test_impossible_calibrations_are_refused(temperature, floor, message):
    with pytest.raises(ValueError, match=message):
        check_spread_calibration(temperature, floor)


# ---------------------------------------------------------------- the compass
def test_leave_one_out_calibration_at_map_time(calibrated, room_pano):
    vc, report = calibrated
    assert report.frames == 24 and report.skipped == 0
    assert vc.is_spread_calibrated and vc.spread_floor_deg == 0.5
    assert vc.spread_temperature == report.temperature > 1.0
    assert report.within_2sigma >= 0.85
    # new views at the learning spot: the calibrated spread covers them, the paper's not
    yaws = np.random.default_rng(2).uniform(0, 360, 40)
    raw = VisualCompass.from_arrays(vc.to_arrays(), "copy")
    raw.set_spread_temperature(*UNCALIBRATED)
    covered, raw_covered = [], []
    for yaw in yaws:
        img = render_view(room_pano, Camera(yaw_deg=yaw))
        est, est_raw = vc.estimate(img, Camera()), raw.estimate(img, Camera())
        # the temperature changes the spread only
        assert est.heading_deg == est_raw.heading_deg
        np.testing.assert_array_equal(est.log_likelihood, est_raw.log_likelihood)
        err = abs(wrap180(est.heading_deg - yaw))
        covered.append(err <= 2 * est.spread_deg)
        raw_covered.append(err <= 2 * est_raw.spread_deg)
    assert np.mean(covered) >= 0.85
    assert np.mean(covered) > np.mean(raw_covered)


def test_calibration_with_held_out_frames(room_pano, calibrated):
    vc, _ = calibrated
    copy = VisualCompass.from_arrays(vc.to_arrays(), "copy")
    yaws = [7.0 + 29.0 * k for k in range(12)]
    report = copy.calibrate(
        [render_view(room_pano, Camera(yaw_deg=y)) for y in yaws],
        [Camera(yaw_deg=y) for y in yaws],
    )
    assert report.frames == 12 and report.skipped == 0
    assert 0.0 <= report.within_1sigma <= report.within_2sigma <= 1.0
    assert copy.spread_temperature == report.temperature


def test_leave_one_out_needs_overlapping_learning_frames(room_pano):
    vc = VisualCompass(CompassConfig(n_colors=3))
    yaws = range(0, 360, 72)  # 57° views 72° apart: no frame's view is seen by another
    images = [render_view(room_pano, Camera(yaw_deg=y)) for y in yaws]
    vc.fit_colors(images)
    for img, y in zip(images, yaws, strict=True):
        vc.learn(img, Camera(yaw_deg=y))
    with pytest.raises(ValueError, match="held-out frames"):
        vc.calibrate(images, [Camera(yaw_deg=y) for y in yaws], leave_one_out=True)
    assert not vc.is_spread_calibrated


def test_leave_one_out_refuses_a_frame_the_map_does_not_hold(calibrated, room_pano):
    vc, _ = calibrated
    copy = VisualCompass.from_arrays(vc.to_arrays(), "copy")
    other = VisualCompass(CompassConfig(), copy.colors)
    img = render_view(room_pano, Camera(yaw_deg=10.0))
    other.learn(img, Camera(yaw_deg=10.0))
    never = render_view(room_pano, Camera(yaw_deg=200.0))
    with pytest.raises(ValueError, match="does not hold the frame at yaw 200"):
        other.calibrate(
            [img, never] * 3, [Camera(yaw_deg=10.0), Camera(yaw_deg=200.0)] * 3, leave_one_out=True
        )


def test_calibrate_checks_its_inputs(calibrated, room_pano):
    vc, _ = calibrated
    img = render_view(room_pano, Camera())
    with pytest.raises(ValueError, match="2 images but 1 cameras"):
        vc.calibrate([img, img], [Camera()])
    with pytest.raises(ValueError, match="floor"):
        vc.calibrate([img] * 5, [Camera()] * 5, floor_deg=-1.0)
    with pytest.raises(ValueError, match="uint8"):
        vc.calibrate([img.astype(np.float32)] * 5, [Camera()] * 5)


def test_set_by_hand_and_forgotten_with_the_map(room_pano, make_learned_compass):
    vc = make_learned_compass(room_pano, CompassConfig(n_colors=3))
    img = render_view(room_pano, Camera(yaw_deg=40.0))
    before = vc.estimate(img, Camera())
    vc.set_spread_temperature(50.0)
    assert (vc.spread_temperature, vc.spread_floor_deg) == (50.0, 0.5)
    after = vc.estimate(img, Camera())
    assert after.spread_deg > before.spread_deg and after.heading_deg == before.heading_deg
    expected = tempered_spreads(before.log_likelihood[None], H, 50.0, 0.5)[0]
    assert after.spread_deg == pytest.approx(expected)
    with pytest.raises(ValueError, match="temperature"):
        vc.set_spread_temperature(0.0)
    vc.reset_map()
    assert not vc.is_spread_calibrated


def test_the_calibration_travels_with_the_map_file(calibrated, tmp_path):
    vc, _ = calibrated
    loaded = VisualCompass.load(vc.save(tmp_path / "m"))
    assert (loaded.spread_temperature, loaded.spread_floor_deg) == (
        vc.spread_temperature,
        vc.spread_floor_deg,
    )


def test_a_map_file_without_a_calibration_loads_uncalibrated(calibrated, tmp_path):
    vc, _ = calibrated
    arrays = dict(vc.to_arrays())
    del arrays["spread_calibration"]
    loaded = VisualCompass.load(write_map_file(tmp_path / "old", arrays))
    assert (loaded.spread_temperature, loaded.spread_floor_deg) == UNCALIBRATED
    assert not loaded.is_spread_calibrated


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda a: a.update(spread_calibration=np.array([20.0])), "two real numbers"),
        (lambda a: a.update(spread_calibration=np.array(["20", "1"])), "two real numbers"),
        (lambda a: a.update(spread_calibration=np.array([-3.0, 0.5])), "invalid spread calib"),
        (lambda a: a.update(spread_calibration=np.array([np.inf, 0.5])), "invalid spread calib"),
        (lambda a: a.update(spread_calibration=np.array([20.0, -1.0])), "floor"),
    ],
)
def test_a_bad_calibration_entry_is_refused_naming_the_file(calibrated, tmp_path, change, message):
    vc, _ = calibrated
    arrays = dict(read_map_file(vc.save(tmp_path / "m")))
    change(arrays)
    path = write_map_file(tmp_path / "bad", arrays)
    with pytest.raises(MapFileError, match=message) as info:
        VisualCompass.load(path)
    assert "bad.npz" in str(info.value)


def test_an_atlas_uses_and_keeps_each_spots_calibration(calibrated, room_pano, tmp_path):
    vc, _ = calibrated
    other = VisualCompass.from_arrays(vc.to_arrays(), "copy", colors=vc.colors)
    other.set_spread_temperature(*UNCALIBRATED)
    atlas = CompassAtlas({"a": ((0.0, 0.0), vc), "b": ((1.0, 0.0), other)}, home="a")
    img = render_view(room_pano, Camera(yaw_deg=123.0))
    _, ests = atlas.scores(img, Camera())
    assert ests[0].spread_deg == pytest.approx(vc.estimate(img, Camera()).spread_deg)
    assert ests[1].spread_deg == pytest.approx(other.estimate(img, Camera()).spread_deg)
    assert ests[0].spread_deg > ests[1].spread_deg
    loaded = CompassAtlas.load(atlas.save(tmp_path / "atlas"))
    assert loaded.compasses[0].spread_temperature == vc.spread_temperature
    assert not loaded.compasses[1].is_spread_calibrated


def test_leave_one_out_with_the_light_map(room_pano, make_learned_compass):
    vc = make_learned_compass(room_pano, CompassConfig(n_colors=3, exposure="map"))
    light = vc._light.level_sum.copy()
    images = [render_view(room_pano, Camera(yaw_deg=y)) for y in LEARN_YAWS]
    report = vc.calibrate(images, [Camera(yaw_deg=y) for y in LEARN_YAWS], leave_one_out=True)
    assert report.frames == len(LEARN_YAWS) and 0.01 <= report.temperature <= 1000
    np.testing.assert_array_equal(vc._light.level_sum, light)  # the map is left as it was


# ---------------------------------------------------------------- no evidence
def test_a_frame_without_evidence_reports_an_infinite_spread_filters_ignore(calibrated):
    vc, _ = calibrated
    black = np.zeros((160, 208, 3), np.uint8)
    est = vc.estimate(black, Camera())
    assert not est.has_evidence and est.spread_deg == math.inf and est.heading_deg == 0.0
    assert not np.any(est.log_likelihood)
    # the filters: a flat log-likelihood leaves a grid belief as it was, under both rules
    for rule in ("mixing", "bayes"):
        grid = HeadingGridFilter(rule=rule)
        grid.reset(90.0, 10.0)
        belief = grid.belief.copy()
        grid.update_log_likelihood(est.log_likelihood)
        np.testing.assert_allclose(grid.belief, belief, rtol=1e-12, atol=1e-15)
    kalman = KalmanHeadingFilter(90.0, 10.0)
    kalman.update(est.heading_deg, est.spread_deg)
    assert kalman.estimate().heading_deg == pytest.approx(90.0)
    assert kalman.estimate().spread_deg == pytest.approx(10.0)
