"""Full-field localisation: the calibration and both estimates on known answers, and the
experiment end to end at --quick."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vc_gym.cli import main
from vc_gym.experiments.studies.localization import (
    BORDER_MARGIN_M,
    calibrate,
    calibration_points,
    locate_calibrated,
    locate_eq30,
    locate_nearest,
)

SPOTS = np.array([[x, y] for x in (-2.25, -0.75, 0.75, 2.25) for y in (-1.5, 0.0, 1.5)])
BOUNDS = (-3.0, 3.0, -2.0, 2.0)


def scores_at(xy, a, b, length):
    d = np.hypot(*(SPOTS - np.asarray(xy)).T)
    return a - b * (1.0 - np.exp(-d / length))


def test_calibration_recovers_a_known_falloff_and_locates_noise_free_frames():
    rng = np.random.default_rng(0)
    a = rng.uniform(-0.12, -0.06, len(SPOTS))
    b = rng.uniform(0.15, 0.25, len(SPOTS))
    where = calibration_points(SPOTS)
    scores = np.array([scores_at(p, a, b, 0.7) for p in where])
    scores += rng.normal(0.0, 0.002, scores.shape)
    fa, fb, sigma, length = calibrate(SPOTS, where, scores)
    assert length == 0.7
    np.testing.assert_allclose(fa, a, atol=0.01)
    np.testing.assert_allclose(fb, b, atol=0.02)
    assert np.all(sigma < 0.01)
    for true in ((0.3, -0.4), (-1.9, 1.1), (2.6, 1.8)):
        mean, std = locate_calibrated(
            scores_at(true, a, b, 0.7), SPOTS, (fa, fb, sigma, length), BOUNDS
        )
        assert np.hypot(*(mean - true)) < 0.1
        assert np.all(std < 0.2)


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


def test_nearest_signatures_interpolate_between_places():
    rng = np.random.default_rng(1)
    a = rng.uniform(-0.12, -0.06, len(SPOTS))
    b = rng.uniform(0.15, 0.25, len(SPOTS))
    places = calibration_points(SPOTS, BOUNDS)
    sig = np.array([scores_at(p, a, b, 0.7) for p in places])
    sigma = np.full(len(SPOTS), 0.02)
    # at a calibration place: that place exactly, with the floor spread
    mean, std = locate_nearest(sig[5], places, sig, sigma)
    np.testing.assert_allclose(mean, places[5], atol=1e-6)
    # between places: no farther than the places' spacing (0.75 m) allows, and the
    # spread says it is between places
    for true in ((-0.375, 0.0), (0.3, 0.4), (-2.6, 1.8), (1.9, -0.2)):
        mean, std = locate_nearest(scores_at(true, a, b, 0.7), places, sig, sigma)
        assert np.hypot(*(mean - true)) < 0.4 and np.max(std) > 0.1
    with pytest.raises(ValueError, match="k must"):
        locate_nearest(sig[0], places, sig, sigma, k=0)
    with pytest.raises(ValueError, match="sigma"):
        locate_nearest(sig[0], places, sig, -sigma)
    with pytest.raises(ValueError, match="shape"):
        locate_nearest(sig[0][:3], places, sig, sigma)


def test_eq30_picks_the_best_spot_when_sharp():
    s = np.full(len(SPOTS), -0.3)
    s[4] = -0.1
    np.testing.assert_allclose(locate_eq30(s, SPOTS, 100.0), SPOTS[4], atol=1e-6)
    np.testing.assert_allclose(
        locate_eq30(np.zeros(len(SPOTS)), SPOTS, 30.0), (0.0, 0.0), atol=1e-9
    )


@pytest.mark.parametrize(
    "call",
    [
        lambda: locate_eq30(np.zeros(3), SPOTS, 30.0),  # one score per spot
        lambda: locate_eq30(np.full(len(SPOTS), np.nan), SPOTS, 30.0),
        lambda: locate_eq30(np.zeros(len(SPOTS)), SPOTS, 0.0),
        lambda: calibrate(SPOTS, SPOTS, np.zeros((len(SPOTS), 2))),
        lambda: calibrate(SPOTS[:, :1], SPOTS, np.zeros((len(SPOTS), len(SPOTS)))),
        lambda: locate_calibrated(np.zeros(2), SPOTS, None, BOUNDS),
        lambda: calibration_points(SPOTS, (0.0, 1.0)),
        lambda: calibration_points(np.full((2, 2), np.nan)),
    ],
)
def test_bad_inputs_are_clear_errors(call):
    with pytest.raises(ValueError, match="shape|finite|sharpness"):
        call()


def test_the_experiment_end_to_end(tmp_path, capsys):
    assert main(["experiment", "localization", "--quick", "--out", str(tmp_path)]) == 0
    r = json.loads((tmp_path / "results.json").read_text())
    assert set(r["methods"]) == {"paper", "calibrated", "turn_calibrated", "turn_nearest"}
    n = len(r["true_positions"])
    for name, m in r["methods"].items():
        assert len(m["estimates"]) == n > 0 and m["mean_error_m"] >= 0
        if name != "paper":
            assert 0.0 <= m["within_2_sigma"] <= 1.0
    assert (tmp_path / "localization.png").read_bytes()[:4] == b"\x89PNG"
    assert "calibrated" in capsys.readouterr().out


def test_more_than_one_scene_is_refused(tmp_path, capsys):
    argv = ["experiment", "localization", "--quick", "--scenes", "robolab,office"]
    assert main([*argv, "--out", str(tmp_path)]) == 2
    assert "one scene" in capsys.readouterr().err


@pytest.mark.parametrize("n", [1])
def test_a_single_spot_has_no_midpoints(n):
    assert len(calibration_points(SPOTS[:n])) == n


def test_border_places_need_ordered_bounds():
    with pytest.raises(ValueError, match="min < max"):
        calibration_points(SPOTS, (3.0, -3.0, -2.0, 2.0))
