"""LandmarkMap.log_likelihood, vectorised over changes and landmarks, against the
straightforward loop over the frame's changes it stands for."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.compass.bearings import FrameBearings
from vc_gym.compass.landmarks import LandmarkMap

BANDS = ((0.5, 4.0), (4.0, 10.0))
HFOV = 57.0


def _looped(lm: LandmarkMap, found: FrameBearings, eye, yaw, noise, outlier) -> np.ndarray:
    """Each change: the best landmark of its band and pair in view, or the floor."""
    total = np.zeros(len(eye))
    floor = math.log(outlier)
    for k in range(len(found)):
        m = lm.pairs == found.pairs[k]
        if not m.any():
            total += floor
            continue
        d = lm.positions[m][None] - eye[:, None]
        dist = np.maximum(np.hypot(d[..., 0], d[..., 1]), 0.05)
        predicted = np.angle(np.exp(1j * (np.arctan2(d[..., 1], d[..., 0]) - yaw[:, None])))
        var = noise**2 + (lm.std_m[m][None] / dist) ** 2
        err = np.angle(np.exp(1j * (math.radians(found.offsets_deg[k]) - predicted)))
        score = -0.5 * err**2 / var - 0.5 * np.log(var / noise**2)
        score = np.where(np.abs(predicted) <= math.radians(HFOV) / 2, score, -np.inf)
        total += np.logaddexp(score.max(axis=1), floor)
    return total


@pytest.mark.parametrize(("seed", "spread_m"), [(0, 1.0), (1, 1.0), (2, 0.02), (3, 0.02)])
def test_the_vectorised_likelihood_is_the_loop_over_changes(seed, spread_m):
    """Poses spread over the room, or a tracker's cloud of 2 cm and 1° (then most
    candidates are dropped unscored: too far off from every pose to count)."""
    rng = np.random.default_rng(seed)
    n, m, k = 4, 60, 15
    lm = LandmarkMap(
        rng.uniform(-3, 3, (m, 2)), rng.integers(0, 2 * n * n, m), rng.uniform(0, 0.05, m),
        np.full(m, 3), n, bands=BANDS,
    )  # fmt: skip
    found = FrameBearings(
        rng.uniform(-28, 28, k), rng.integers(0, n, k), rng.integers(0, n, k), n, HFOV,
        rng.integers(0, 2, k), BANDS,
    )  # fmt: skip
    eye = rng.uniform(-1, 1, 2) + rng.uniform(-spread_m, spread_m, (50, 2))
    yaw = rng.uniform(-3, 3) + rng.uniform(-3, 3, 50) * min(1.0, spread_m / 0.02 * 0.006)
    got = lm.log_likelihood(found, eye, yaw, 0.01, 0.05)
    np.testing.assert_allclose(got, _looped(lm, found, eye, yaw, 0.01, 0.05), atol=1e-9)
    # a change whose band and pair no landmark has costs the floor at every pose
    alone = FrameBearings(np.zeros(1), np.zeros(1, int), np.zeros(1, int), n, HFOV, None, BANDS)
    if not np.any(lm.pairs == alone.pairs[0]):
        np.testing.assert_allclose(lm.log_likelihood(alone, eye, yaw, 0.01, 0.05), math.log(0.05))
