import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from vc_gym.compass import Camera, log2_bin
from vc_gym.compass.features import column_transition_counts, scan_grid


@given(st.floats(min_value=0.0, max_value=1.0), st.integers(min_value=2, max_value=20))
def test_log2_bin_holds_its_interval(z, n):
    k = int(log2_bin(np.array(z), n))
    assert 0 <= k < n
    if k < n - 1:
        assert 2.0 ** -(k + 1) < z <= 2.0**-k
    else:  # the last bin holds its own interval and everything below it, zero included
        assert z <= 2.0 ** -(n - 1)


@given(st.integers(min_value=0, max_value=30), st.integers(min_value=2, max_value=32))
def test_log2_bin_exact_at_powers_of_two(k, n):
    z = 2.0**-k
    assert int(log2_bin(np.array(z), n)) == min(k, n - 1)


@given(st.lists(st.floats(min_value=0.0, max_value=1.0), min_size=2, max_size=50))
def test_log2_bin_is_monotone(zs):
    z = np.sort(np.array(zs))
    b = log2_bin(z, 8)
    assert np.all(np.diff(b) <= 0)  # larger frequency -> smaller (or same) bin index


def test_log2_bin_zero_goes_to_last():
    assert log2_bin(np.array([0.0, 1.0, 0.5, 0.26, 0.25]), 8).tolist() == [7, 0, 1, 1, 2]


def test_column_transitions_bottom_to_top():
    # column 0: class 2 at the top over class 1 below -> one 1->2 transition (below->above)
    classes = np.array([[2, 0], [1, 0], [1, 0]], dtype=np.uint8)
    counts = column_transition_counts(classes, n_colors=3, count_same_class=True)
    assert counts.shape == (2, 9)
    assert counts[0, 1 * 3 + 2] == 1  # 1 (below) -> 2 (above)
    assert counts[0, 1 * 3 + 1] == 1  # 1 -> 1 (no change)
    assert counts[1, 0] == 2
    no_same = column_transition_counts(classes, n_colors=3, count_same_class=False)
    assert no_same[0].sum() == 1 and no_same[1].sum() == 0


def test_scan_grid_only_above_horizon_and_coverage():
    for pitch in (-15.0, 0.0, 15.0):
        cam = Camera(pitch_deg=pitch)
        g = scan_grid(cam, 208, 160, 2, 2)
        assert g.rows.max() < cam.horizon_row(208, 160)
        assert np.all(np.diff(g.rows) == 2) and np.all(np.diff(g.cols) == 2)
        assert g.cols.size == 104
    looking_down = scan_grid(Camera(pitch_deg=-60.0), 208, 160, 2, 2)
    assert looking_down.rows.size == 0 and looking_down.n_transitions == 0


def test_scan_grid_offsets_follow_camera():
    cam = Camera(hfov_deg=60.0)
    g = scan_grid(cam, 200, 100, 1, 1)
    assert g.offsets_deg[0] == pytest.approx(30.0, abs=0.5)
    assert g.offsets_deg[-1] == pytest.approx(-30.0, abs=0.5)
    assert np.all(np.diff(g.offsets_deg) < 0)


def test_change_ratio_is_one_for_independent_pixels_and_small_for_regions():
    from vc_gym.compass.features import NOISE_CHANGE_RATIO, change_ratio

    rng = np.random.default_rng(0)
    independent = rng.integers(0, 5, (60, 100))
    assert change_ratio(independent, 5) == pytest.approx(1.0, abs=0.05)
    skewed = rng.choice(3, size=(60, 100), p=[0.8, 0.15, 0.05])  # still independent
    assert change_ratio(skewed, 3) == pytest.approx(1.0, abs=0.08)
    bands = np.repeat(np.arange(6) % 3, 10)[:, None] * np.ones((1, 100), int)  # 6 bands
    # 5 changes in 59 row pairs, against 2/3 for independent pixels
    assert change_ratio(bands, 3) == pytest.approx((5 / 59) / (2 / 3))
    assert change_ratio(bands, 3) < NOISE_CHANGE_RATIO <= change_ratio(independent, 5) + 0.1
    assert change_ratio(np.zeros((10, 10), int), 3) == 0.0  # one class
    assert change_ratio(np.zeros((1, 10), int), 3) == 0.0  # one row
