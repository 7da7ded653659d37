"""Learned turns placed anew (grid search, then turns and landmarks adjusted together),
in the striped ray-cast room whose colour edges are known exactly."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from striped_room import learned_views, striped_room, view

from vc_gym.compass.bearings import frame_bearings
from vc_gym.compass.landmarks import learn_landmarks
from vc_gym.compass.turn_placement import (
    NO_CORRECTION,
    LearnedTurn,
    _normal_equations,
    _schur_step,
    adjust_turns,
    place_turns,
)

AHEAD = 0.25  # the simulated robot's eye, ahead of its trunk's centre
TRUE = [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (1.5, 0.5)]


@pytest.fixture(scope="module")
def drifted():
    """Turns as the learning phase believes them: home as it was; every other turn up to
    0.3 m and 15° off where it stood, and its odometry counting the turn up to 1.5 %
    long or short. Returns the room's edges, the turns and each turn's error
    ``(dx, dy, dyaw, turn scale)`` (believed minus true; scale: counted over true)."""
    room, points = striped_room()
    colors, _ = learned_views((room, points))
    rng = np.random.default_rng(5)
    errors = [(0.0, 0.0, 0.0, 1.0)] + [
        (*rng.uniform(-0.3, 0.3, 2), rng.uniform(-15.0, 15.0), 1.0 + rng.uniform(-0.015, 0.015))
        for _ in TRUE[1:]
    ]
    turns = []
    for (x, y), (ex, ey, eyaw, scale) in zip(TRUE, errors, strict=True):
        frames = []
        for body in range(0, 360, 45):
            for pan in (-20.0, 0.0, 20.0):
                t = math.radians(body)
                img, cam = view(room, x + AHEAD * math.cos(t), y + AHEAD * math.sin(t), body + pan)
                frames.append((frame_bearings(img, cam, colors), eyaw + body * scale, pan))
        turns.append(LearnedTurn(x + ex, y + ey, tuple(frames)))
    return points, turns, np.array(errors)


def _gaps(positions: np.ndarray, points: np.ndarray) -> np.ndarray:
    d = positions[:, None, :] - points[None]
    return np.min(np.hypot(d[..., 0], d[..., 1]), axis=1)


def test_turns_whose_believed_poses_drifted_are_placed_anew(drifted):
    """The grid search finds each turn; the adjustment puts it back to its true pose and
    turn scale, and the landmarks of all turns on the true edges."""
    points, turns, errors = drifted
    landmarks, corrections = place_turns(turns, eye_forward_m=AHEAD)
    placed = np.array([(t.x, t.y) for t in turns]) + corrections[:, :2]
    np.testing.assert_array_equal(corrections[0, :3], 0.0)  # home is the map's frame
    assert landmarks.eye_forward_m == AHEAD  # a sensor sees them from there
    # measured: every turn within 0.3 cm, its heading within 0.05 deg, its scale 0.03 %
    np.testing.assert_allclose(placed, TRUE, atol=0.02)
    np.testing.assert_allclose(corrections[:, 2], -errors[:, 2], atol=0.3)
    np.testing.assert_allclose(corrections[:, 3] * errors[:, 3], 1.0, atol=0.003)
    gaps = _gaps(landmarks.positions, points)
    # measured: 27 of 27 edges, median 0.4 cm off, at most 1.5 cm
    assert len(landmarks) >= 0.8 * len(points) and np.max(gaps) < 0.03, np.sort(gaps)[-3:]
    # where the turns were believed to be, the same frames place the edges far worse
    believed = learn_landmarks([v for t in turns for v in t.views(AHEAD)])
    assert np.median(_gaps(believed.positions, points)) > 5 * np.median(gaps)


def test_the_landmarks_keep_the_light_their_frames_were_seen_at(drifted):
    """The session light of the turns' frame gains (median, in thirds of a stop), 1 when
    no turn read its frames' gains."""
    _, turns, _ = drifted
    assert place_turns(turns[:2], eye_forward_m=AHEAD)[0].light_gain == 1.0
    lit = [
        replace(t, frame_gains=(1.9, 2.1, 2.0, float("inf"))[: 3 + k])
        for k, t in enumerate(turns[:2])
    ]
    assert place_turns(lit, eye_forward_m=AHEAD)[0].light_gain == 2.0


def test_the_adjustment_alone_beats_the_grid_search(drifted):
    """Without the adjustment the grid's 1 cm and 0.25° steps, and the turn scales it
    leaves alone, bound how well the turns are placed (measured: 3-7 cm off)."""
    _, turns, errors = drifted
    _, searched = place_turns(turns, eye_forward_m=AHEAD, adjust=False)
    assert np.all(searched[:, 3] == 1.0)
    landmarks = learn_landmarks(
        [v for t, c in zip(turns, searched, strict=True) for v in t.views(AHEAD, tuple(c))]
    )
    adjusted, positions = adjust_turns(turns, landmarks, searched, eye_forward_m=AHEAD)
    truth = np.array(TRUE) - np.array([(t.x, t.y) for t in turns])
    before = np.hypot(*(searched[1:, :2] - truth[1:]).T)
    after = np.hypot(*(adjusted[1:, :2] - truth[1:]).T)
    assert np.median(after) < 0.5 * np.median(before), (before, after)
    assert positions.shape == landmarks.positions.shape
    # the home turn is the map's frame: it never moves (only its turn scale may change)
    np.testing.assert_array_equal(adjusted[0, :3], 0.0)


def test_bad_input_is_refused(drifted):
    _, turns, _ = drifted
    with pytest.raises(ValueError, match="eye_forward_m"):
        place_turns([LearnedTurn(0.0, 0.0, ())], eye_forward_m=float("inf"))
    with pytest.raises(ValueError, match="no turns"):
        place_turns([])
    landmarks = learn_landmarks(turns[0].views(AHEAD), min_positions=2)
    with pytest.raises(ValueError, match="corrections"):
        adjust_turns(turns, landmarks, np.zeros((len(turns), 3)))
    bad = np.tile(NO_CORRECTION, (len(turns), 1))
    bad[1, 0] = np.nan
    with pytest.raises(ValueError, match="corrections"):
        adjust_turns(turns, landmarks, bad)
    with pytest.raises(ValueError, match="associations"):
        adjust_turns(turns, landmarks, np.tile(NO_CORRECTION, (len(turns), 1)), associations=0)


def test_a_turn_with_no_frames_or_a_map_with_no_landmarks_is_left_alone(drifted):
    _, turns, _ = drifted
    corrections = np.tile(NO_CORRECTION, (2, 1))
    empty = learn_landmarks(turns[0].views(AHEAD), min_positions=2)
    nothing = type(empty)(np.zeros((0, 2)), np.zeros(0, np.int64), np.zeros(0),
                          np.zeros(0, np.int64), empty.n_colors)  # fmt: skip
    out, positions = adjust_turns(turns[:2], nothing, corrections, eye_forward_m=AHEAD)
    np.testing.assert_array_equal(out, corrections)
    assert positions.shape == (0, 2)


def test_the_adjustment_step_eliminating_the_points_is_the_dense_solve():
    """The blocks of the normal equations and the step that eliminates the points give
    what the whole system, built residual by residual and solved densely, gives."""
    rng = np.random.default_rng(0)
    n_turns, n_points, n_res = 5, 7, 200
    turn, lm = rng.integers(0, n_turns, n_res), rng.integers(0, n_points, n_res)
    t_cols = 4 * turn[:, None] + np.arange(4)
    jac, r = rng.normal(size=(n_res, 6)), rng.normal(size=n_res)
    w = rng.uniform(0.2, 1.0, n_res)
    n_t = 4 * n_turns + 1  # the gain's column last
    a, b, d, g_t, g_p = _normal_equations(t_cols, lm, jac, w, r, n_t, n_points)
    a[-1, -1] += 1.0  # the gain's prior
    n = n_t + 2 * n_points
    cols = np.concatenate([t_cols, n_t + 2 * lm[:, None] + np.arange(2)], axis=1)
    h, g = np.zeros((n, n)), np.zeros(n)
    for k in range(n_res):
        h[np.ix_(cols[k], cols[k])] += w[k] * np.outer(jac[k], jac[k])
        g[cols[k]] += w[k] * r[k] * jac[k]
    h[n_t - 1, n_t - 1] += 1.0
    for damping in (1e-3, 1.0):
        x = np.linalg.solve(h + damping * np.diag(np.diag(h) + 1e-9), -g)
        x_t, x_p = _schur_step(a, b, d, g_t, g_p, damping)
        assert np.allclose(x_t, x[:n_t], atol=1e-12) and np.allclose(x_p, x[n_t:], atol=1e-12)
