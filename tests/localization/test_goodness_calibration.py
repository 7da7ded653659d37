"""The calibrated one-view position likelihood: known falloffs recovered, noise-free frames
located where they were taken, the calibration places, and clear errors on bad input."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.localization import (
    GoodnessCalibration,
    calibrate_goodness,
    calibration_points,
    goodness_log_likelihood,
    locate_by_goodness,
)
from vc_gym.localization.goodness_calibration import BORDER_MARGIN_M

SPOTS = np.array([[x, y] for x in (-2.25, -0.75, 0.75, 2.25) for y in (-1.5, 0.0, 1.5)])
BOUNDS = (-3.0, 3.0, -2.0, 2.0)


def scores_at(xy, a, b, length):
    d = np.hypot(*(SPOTS - np.asarray(xy)).T)
    return a - b * (1.0 - np.exp(-d / length))


def known_model(seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-0.12, -0.06, len(SPOTS)), rng.uniform(0.15, 0.25, len(SPOTS))


def test_calibration_recovers_a_known_falloff_and_locates_noise_free_frames():
    rng = np.random.default_rng(0)
    a = rng.uniform(-0.12, -0.06, len(SPOTS))
    b = rng.uniform(0.15, 0.25, len(SPOTS))
    where = calibration_points(SPOTS)
    scores = np.array([scores_at(p, a, b, 0.7) for p in where])
    scores += rng.normal(0.0, 0.002, scores.shape)
    fa, fb, sigma, length = calibrate_goodness(SPOTS, where, scores)
    assert length == 0.7
    np.testing.assert_allclose(fa, a, atol=0.01)
    np.testing.assert_allclose(fb, b, atol=0.02)
    assert np.all(sigma < 0.01)
    for true in ((0.3, -0.4), (-1.9, 1.1), (2.6, 1.8)):
        mean, std = locate_by_goodness(
            scores_at(true, a, b, 0.7), SPOTS, (fa, fb, sigma, length), BOUNDS
        )
        assert np.hypot(*(mean - true)) < 0.1
        assert np.all(std < 0.2)


def test_the_calibration_is_a_named_tuple_of_the_fit():
    a, b = known_model(2)
    where = calibration_points(SPOTS, BOUNDS)
    scores = [scores_at(p, a, b, 1.4) for p in where]
    cal = calibrate_goodness(SPOTS, where, scores)
    assert isinstance(cal, GoodnessCalibration) and cal.length_m == 1.4
    assert cal == (cal.a, cal.b, cal.sigma, cal.length_m)
    # noise-free scores: the fit is exact and sigma sits at its floor
    np.testing.assert_allclose(cal.a, a, atol=1e-9)
    np.testing.assert_allclose(cal.b, b, atol=1e-9)
    np.testing.assert_array_equal(cal.sigma, 1e-3)
    # only the given length scales are tried
    assert calibrate_goodness(SPOTS, where, scores, (0.5,)).length_m == 0.5


def test_the_log_likelihood_peaks_where_the_scores_were_made():
    a, b = known_model(3)
    cal = GoodnessCalibration(a, b, np.full(len(SPOTS), 0.002), 0.7)
    true = np.array([0.4, -0.9])
    where = np.array([true, [0.0, 0.0], [-2.0, 1.0], [2.5, 1.5]])
    logl = goodness_log_likelihood(scores_at(true, a, b, 0.7), SPOTS, cal, where)
    assert logl.shape == (4,) and logl[0] == pytest.approx(0.0, abs=1e-12)
    assert np.all(logl[1:] < -1.0)
    # the posterior on a grid finds the same place, sharply (small sigma)
    mean, std = locate_by_goodness(scores_at(true, a, b, 0.7), SPOTS, cal, BOUNDS, grid_step_m=0.02)
    assert np.hypot(*(mean - true)) < 0.03 and np.all(std < 0.05)


def test_calibration_points_are_the_spots_and_the_midpoints_between_neighbours():
    pts = calibration_points(SPOTS)
    assert len(pts) == len(SPOTS) + 3 * 3 + 4 * 2  # 12 spots, 9 + 8 neighbour pairs
    assert any(np.allclose(p, (-1.5, 0.0)) for p in pts)
    assert not any(np.allclose(p, (-1.5, -0.75)) for p in pts)  # no diagonals


def test_border_points_cover_the_strip_beyond_the_outer_spots():
    pts = calibration_points(SPOTS, BOUNDS)
    inner = calibration_points(SPOTS)
    border = pts[len(inner) :]
    assert len(border) == 3 * 2 + 4 * 2 + 4  # rows' ends, columns' ends, corners
    edge = 3.0 - BORDER_MARGIN_M
    assert any(np.allclose(p, (-edge, 0.0)) for p in border)
    assert any(np.allclose(p, (0.75, 2.0 - BORDER_MARGIN_M)) for p in border)
    assert any(np.allclose(p, (edge, -(2.0 - BORDER_MARGIN_M))) for p in border)
    assert np.all(np.abs(border[:, 0]) <= edge + 1e-9)


@pytest.mark.parametrize("n", [1])
def test_a_single_spot_has_no_midpoints(n):
    assert len(calibration_points(SPOTS[:n])) == n


def test_border_places_need_ordered_bounds():
    with pytest.raises(ValueError, match="min < max"):
        calibration_points(SPOTS, (3.0, -3.0, -2.0, 2.0))


GOOD = GoodnessCalibration(np.zeros(len(SPOTS)), np.ones(len(SPOTS)), np.ones(len(SPOTS)), 0.7)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: calibrate_goodness(SPOTS, SPOTS, np.zeros((len(SPOTS), 2))), "shape"),
        (lambda: calibrate_goodness(SPOTS[:, :1], SPOTS, np.zeros((12, 12))), "shape"),
        (lambda: calibrate_goodness(SPOTS, np.zeros((0, 2)), np.zeros((0, 12))), "empty"),
        (lambda: calibrate_goodness(SPOTS, SPOTS, np.full((12, 12), np.nan)), "NaN"),
        (lambda: calibrate_goodness(SPOTS, SPOTS, np.zeros((12, 12)), ()), "at least one"),
        (lambda: calibrate_goodness(SPOTS, SPOTS, np.zeros((12, 12)), (0.0,)), "length_scales_m"),
        (lambda: locate_by_goodness(np.zeros(2), SPOTS, None, BOUNDS), "shape"),
        (lambda: locate_by_goodness(np.zeros(12), SPOTS, None, BOUNDS), "GoodnessCalibration"),
        (lambda: locate_by_goodness(np.zeros(12), SPOTS, GOOD[:3], BOUNDS), "GoodnessCalibration"),
        (
            lambda: locate_by_goodness(np.zeros(12), SPOTS, GOOD._replace(a=np.zeros(3)), BOUNDS),
            "calibration.a",
        ),
        (
            lambda: locate_by_goodness(
                np.zeros(12), SPOTS, GOOD._replace(sigma=np.zeros(12)), BOUNDS
            ),
            "sigma must be > 0",
        ),
        (
            lambda: locate_by_goodness(np.zeros(12), SPOTS, GOOD._replace(length_m=-1.0), BOUNDS),
            "length_m",
        ),
        (lambda: locate_by_goodness(np.zeros(12), SPOTS, GOOD, (0.0, 1.0)), "shape"),
        (lambda: locate_by_goodness(np.zeros(12), SPOTS, GOOD, (1.0, 0.0, 0.0, 1.0)), "min < max"),
        (lambda: locate_by_goodness(np.zeros(12), SPOTS, GOOD, BOUNDS, 0.0), "grid_step_m"),
        (lambda: goodness_log_likelihood(np.zeros(12), SPOTS, GOOD, np.zeros((3, 3))), "shape"),
        (lambda: goodness_log_likelihood([np.inf] * 12, SPOTS, GOOD, np.zeros((3, 2))), "finite"),
        (lambda: calibration_points(SPOTS, (0.0, 1.0)), "shape"),
        (lambda: calibration_points(np.full((2, 2), np.nan)), "finite"),
        (lambda: calibration_points("spots"), "array of numbers"),
    ],
)
def test_bad_inputs_are_clear_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()
