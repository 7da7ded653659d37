"""HomingFeatureExpert: the paper's homing rule on Homing-v0 feature vectors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.agents import HomingFeatureExpert
from vc_gym.envs.homing import STOP_THRESHOLD, HomingFeatures


def features(home_fwd: float, home_left: float, spread_deg: float = 5.0, spots: int = 4):
    f = np.zeros(HomingFeatures.GOODNESS_START + spots + 1, np.float32)
    f[HomingFeatures.HOME_VECTOR] = np.array([home_fwd, home_left]) / HomingFeatures.METRES_SCALE
    f[HomingFeatures.HEADING] = (1.0, 0.0)
    f[HomingFeatures.SPREAD] = spread_deg / HomingFeatures.SPREAD_SCALE_DEG
    return f


def test_walks_straight_to_a_home_ahead():
    walk, turn, stop = HomingFeatureExpert().predict(features(1.0, 0.0))
    assert walk == pytest.approx(0.25 / 0.4) and turn == 0.0 and stop < STOP_THRESHOLD


@pytest.mark.parametrize("left", [1.0, -1.0])
def test_turns_on_the_spot_towards_a_home_to_the_side(left):
    walk, turn, stop = HomingFeatureExpert().predict(features(0.0, left))
    assert walk <= 0.0 and turn == math.copysign(1.0, left) and stop < STOP_THRESHOLD


def test_turns_in_proportion_and_slows_down_near_home():
    walk, turn, _ = HomingFeatureExpert(max_turn_deg_s=90.0).predict(
        features(0.2 * math.cos(math.radians(10)), 0.2 * math.sin(math.radians(10)))
    )
    assert turn == pytest.approx(25.0 / 90.0, abs=1e-5)  # 2.5 x 10 degrees
    assert walk == pytest.approx(0.8 * 0.2 / 0.4, abs=1e-5)


def test_stops_at_home_and_waits_while_the_heading_is_unsure():
    expert = HomingFeatureExpert(home_tolerance_m=0.1)
    assert expert.predict(features(0.05, 0.03))[2] > STOP_THRESHOLD
    walk, turn, stop = expert.predict(features(2.0, 0.0, spread_deg=60.0))
    assert walk <= 0.0 and turn == 0.0 and stop < STOP_THRESHOLD


def test_a_batch_gives_one_action_per_row():
    rows = np.stack([features(1.0, 0.0), features(0.0, 0.0)])
    out = HomingFeatureExpert().predict(rows)
    assert out.shape == (2, 3) and out.dtype == np.float32 and out[1, 2] > STOP_THRESHOLD


@pytest.mark.parametrize("bad", [np.zeros(3), np.full(12, np.nan), np.zeros((2, 2, 12))])
def test_bad_features_are_rejected(bad):
    with pytest.raises(ValueError, match="feature vector"):
        HomingFeatureExpert().predict(bad)


@pytest.mark.parametrize("kwargs", [{"max_forward": 0}, {"home_tolerance_m": -1}])
def test_bad_settings_are_rejected(kwargs):
    with pytest.raises(ValueError):
        HomingFeatureExpert(**kwargs)


def with_previous(f: np.ndarray, walk: float, turn: float, stop: float = -1.0) -> np.ndarray:
    return np.concatenate([f, np.array([walk, turn, stop], np.float32)])


@pytest.mark.parametrize("last_turn", [1.0, -1.0])
def test_with_its_last_action_it_keeps_turning_while_home_is_behind(last_turn):
    expert = HomingFeatureExpert(previous_action=True)
    # home 1 m behind, a little to the left: the bearing's sign says turn left (+)
    behind_left = features(-1.0, 0.05)
    assert HomingFeatureExpert().predict(behind_left)[1] == pytest.approx(1.0)
    _, turn, stop = expert.predict(with_previous(behind_left, -1.0, last_turn))
    assert turn == pytest.approx(last_turn) and stop < STOP_THRESHOLD
    # not turning before (e.g. after a reset or while settling): the bearing decides
    assert expert.predict(with_previous(behind_left, -1.0, 0.0))[1] == pytest.approx(1.0)
    # once home is no longer behind, the bearing decides again
    ahead_right = features(1.0, -0.5)
    assert expert.predict(with_previous(ahead_right, -1.0, 1.0))[1] < 0


def test_with_its_last_action_the_rest_is_unchanged():
    plain, with_last = HomingFeatureExpert(), HomingFeatureExpert(previous_action=True)
    for fwd, left, spread in [(1.0, 0.0, 5.0), (0.05, 0.0, 5.0), (1.0, 0.3, 60.0), (0.2, 1.0, 5)]:
        f = features(fwd, left, spread)
        np.testing.assert_array_equal(
            plain.predict(f), with_last.predict(with_previous(f, 0.3, 0.8))
        )
    with pytest.raises(ValueError, match="previous_action"):
        HomingFeatureExpert(previous_action="yes")


def test_walks_at_its_fastest_speed_far_from_home():
    walk, _, _ = HomingFeatureExpert(max_speed_m_s=0.4).predict(features(2.0, 0.0))
    assert walk == pytest.approx(1.0)  # max_forward 0.4 m/s
    walk, _, _ = HomingFeatureExpert(max_speed_m_s=0.4).predict(features(0.3, 0.0))
    assert walk == pytest.approx(0.8 * 0.3 / 0.4, abs=1e-5)  # slower when close, as before


def with_spread(f: np.ndarray, spread_m: float, spots: int = 4) -> np.ndarray:
    spread = np.full(2, spread_m / HomingFeatures.POSITION_STD_SCALE_M, np.float32)
    out = np.concatenate([f, spread])
    assert out[HomingFeatures.position_std_slice(spots)].tolist() == spread.tolist()
    return out


def test_does_not_stop_at_home_while_the_position_is_unsure():
    expert = HomingFeatureExpert(max_position_std_m=0.2)
    at_home = features(0.05, 0.0)
    walk, turn, stop = expert.predict(with_spread(at_home, 0.5))
    assert stop < STOP_THRESHOLD and walk <= 0.0 and turn != 0.0  # turns in place, scanning
    assert expert.predict(with_spread(at_home, 0.1))[2] > STOP_THRESHOLD
    # away from home the spread changes nothing
    far = features(1.0, 0.0)
    np.testing.assert_array_equal(
        expert.predict(with_spread(far, 0.5)), HomingFeatureExpert().predict(far)
    )
    # the rule without the setting stops on the estimate alone
    assert HomingFeatureExpert().predict(with_spread(at_home, 0.5))[2] > STOP_THRESHOLD
    with pytest.raises(ValueError, match="position's spread"):
        expert.predict(features(0.05, 0.0, spots=1)[:-1])


@pytest.mark.parametrize(
    "kwargs",
    [{"max_speed_m_s": 0.5}, {"max_speed_m_s": 0.0}, {"max_position_std_m": -0.1}],
)
def test_bad_speed_and_spread_settings_are_rejected(kwargs):
    with pytest.raises(ValueError, match="max_speed_m_s|max_position_std_m"):
        HomingFeatureExpert(**kwargs)
