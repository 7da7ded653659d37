"""How frames add to the map (eq. 6) and how its sectors are re-indexed."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass.features import log2_bin
from vc_gym.compass.sector_map import add_frame, checked_sectors, regrouped_counts

N_SECTORS, C2, N_BINS = 6, 4, 5


def test_a_frame_adds_one_count_per_pair_to_each_sector_it_saw():
    counts = np.zeros((N_SECTORS, C2, N_BINS))
    n_obs = np.zeros(N_SECTORS)
    colcounts = np.array([[1, 3, 0, 0], [0, 4, 0, 0], [0, 0, 0, 0]], np.float32)
    seen = add_frame(counts, n_obs, colcounts, np.array([2, 2, 5]))
    np.testing.assert_array_equal(seen, [2])  # sector 5's column saw no transition
    np.testing.assert_array_equal(n_obs, [0, 0, 1, 0, 0, 0])
    z = np.array([1, 7, 0, 0]) / 8  # the relative frequencies of eq. 11
    expected = np.zeros((C2, N_BINS))
    expected[np.arange(C2), log2_bin(z, N_BINS)] = 1.0
    np.testing.assert_array_equal(counts[2], expected)
    assert counts.sum() == C2


def test_a_frame_without_transitions_changes_nothing():
    counts = np.ones((N_SECTORS, C2, N_BINS))
    n_obs = np.ones(N_SECTORS)
    seen = add_frame(counts, n_obs, np.zeros((3, C2), np.float32), np.array([0, 1, 2]))
    assert seen.size == 0
    assert counts.sum() == N_SECTORS * C2 * N_BINS and n_obs.sum() == N_SECTORS


def test_regrouping_adds_the_sectors_that_land_together():
    rng = np.random.default_rng(0)
    counts = rng.integers(0, 5, (N_SECTORS, C2, N_BINS)).astype(np.float64)
    n_obs = np.arange(N_SECTORS, dtype=np.float64)
    target = np.array([1, 1, 0, 3, 3, 3])
    out, obs = regrouped_counts(counts, n_obs, target)
    np.testing.assert_array_equal(out[1], counts[0] + counts[1])
    np.testing.assert_array_equal(out[3], counts[3] + counts[4] + counts[5])
    assert not out[[2, 4, 5]].any()  # no source lands there
    np.testing.assert_array_equal(obs, [2, 1, 0, 12, 0, 0])
    assert obs.dtype == np.float64


@pytest.mark.parametrize(
    ("sectors", "rows", "message"),
    [
        (np.arange(5), False, r"target must be an integer array of shape \(6,\)"),
        (np.arange(6.0), False, "integer array"),
        (np.full(6, 6), False, r"sectors must lie in \[0, 6\)"),
        (np.arange(6), True, r"shape \(N, 6\)"),
    ],
)
def test_bad_sector_arrays_are_refused(sectors, rows, message):
    with pytest.raises(ValueError, match=message):
        checked_sectors("target", sectors, N_SECTORS, rows=rows)


def test_good_sector_arrays_pass():
    np.testing.assert_array_equal(
        checked_sectors("t", [0, 5, 1, 2, 3, 4], N_SECTORS), [0, 5, 1, 2, 3, 4]
    )
    assert checked_sectors("t", np.zeros((2, 6), np.int32), N_SECTORS, rows=True).shape == (2, 6)
