"""Measuring where the tracker's estimate puts home, with a tracker whose error is known."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import vc_gym  # noqa: F401
from vc_gym.envs.homing import HomingFeatures
from vc_gym.localization import TrackerState
from vc_gym.sim import HeadCameraSpec
from vc_gym.training.feature_expert import HomingFeatureExpert
from vc_gym.training.home_offset import MIN_STOPS, centre_home_offset, measure_home_offset

FAST = {
    "learn_time_s": 0.2,
    "max_homing_s": 3.0,
    "stop_time_s": 0.3,
    "min_walk_s": 0.0,
    "camera": HeadCameraSpec(52, 40, 56.9),  # the tracker reads the true pose
}
BIAS = (0.12, -0.07)


class BiasedOracle:
    """A tracker that reads the robot's true pose and reports its position off by
    ``bias`` (a tracker whose home lies at ``-bias`` from the true one); with ``scale``
    the reported position is ``bias + scale × true``, an error that changes across the
    field (zero at ``bias / (1 - scale)``) and is ``bias`` at the true home only."""

    def __init__(self, bias=BIAS, scale=1.0):
        self.bias = np.asarray(bias, np.float64)
        self.scale = float(scale)
        self.room = None  # set once the env exists

    def reset(self, atlas, camera, dt_s):
        self.n_spots = len(atlas)

    def update(self, image, head_pan_deg, odometry):
        x, y, yaw = self.room.robot.pose
        belief = np.full(36, 1 / 36)
        return TrackerState(
            heading_deg=float(yaw) % 360.0,
            heading_spread_deg=1.0,
            position=tuple(float(v) for v in self.bias + self.scale * np.array([x, y])),
            position_std_m=(0.01, 0.01),
            goodness=np.ones(self.n_spots),
            belief=belief,
            atlas_position=(float(x), float(y)),
        )


class StopAtOnce:
    """An "expert" that stops wherever it stands (its stops lie where it was put)."""

    def predict(self, features):
        return np.array([-1.0, 0.0, 1.0], np.float32)


@pytest.fixture(scope="module")
def place(tmp_path_factory):
    """One place's atlas file, learned once for every env of this module."""
    return {"atlas_file": str(tmp_path_factory.mktemp("place") / "p.npz"), "learning_seed": 0}


@pytest.fixture
def make(place):
    envs = []

    def build(tracker, **kwargs):
        env = gym.make("vc_gym/Homing-v0", tracker=lambda: tracker, **{**FAST, **place, **kwargs})
        tracker.room = env.unwrapped.room
        envs.append(env)
        return env

    yield build
    for env in envs:
        env.close()


@pytest.mark.slow
def test_the_offset_is_the_trackers_error_at_the_stops(make):
    measured = measure_home_offset(make(BiasedOracle()), MIN_STOPS, seed=3, expert=StopAtOnce())
    np.testing.assert_allclose(measured.offset_m, BIAS, atol=1e-6)
    np.testing.assert_allclose(measured.spread_m, (0.0, 0.0), atol=1e-6)
    assert measured.stops == measured.episodes == MIN_STOPS
    d = measured.to_dict()
    assert d["home_offset_m"] == [0.12, -0.07] and d["stops"] == MIN_STOPS
    assert d["per_place_m"] == [[0.12, -0.07]]


@pytest.mark.slow
def test_places_are_pooled_and_reported_one_by_one(make):
    envs = [make(BiasedOracle((0.1, 0.0))), make(BiasedOracle((0.3, -0.2)))]
    measured = measure_home_offset(envs, 3, seed=0, expert=StopAtOnce())
    np.testing.assert_allclose(measured.offset_m, (0.2, -0.1), atol=1e-6)  # median of 6
    np.testing.assert_allclose(measured.per_place_m, [(0.1, 0.0), (0.3, -0.2)], atol=1e-6)
    np.testing.assert_allclose(measured.spread_m, (0.1, 0.1), atol=1e-6)
    assert measured.episodes == measured.stops == 6


def test_with_the_measured_offset_the_goal_is_the_true_home(make):
    env = make(BiasedOracle(), home_offset_m=BIAS)
    obs, _ = env.reset(seed=4, options={"pose": (0.0, 0.0, 130.0)})  # at the true home
    home = obs[HomingFeatures.HOME_VECTOR] * HomingFeatures.METRES_SCALE
    position = obs[HomingFeatures.POSITION] * HomingFeatures.METRES_SCALE
    assert np.hypot(*home) < 0.02 and np.hypot(*position) < 0.02
    plain = make(BiasedOracle())  # without it the tracker's home is 14 cm away
    obs, _ = plain.reset(seed=4, options={"pose": (0.0, 0.0, 130.0)})
    home = obs[HomingFeatures.HOME_VECTOR] * HomingFeatures.METRES_SCALE
    assert np.hypot(*home) == pytest.approx(np.hypot(*BIAS), abs=0.02)


@pytest.mark.slow
def test_the_centred_goal_puts_the_experts_stops_at_the_true_home(make):
    """With an estimate that moves half as far as the robot, the goal read at the stops
    is twice the error at home and the stops overshoot; the second round going to it
    finds the slope (2) and the goal at which the stops centre on home (the bias)."""
    env = make(BiasedOracle(scale=0.5), max_homing_s=40.0)
    expert = HomingFeatureExpert(home_tolerance_m=0.02)  # stops within 4 cm of the goal
    first = measure_home_offset(env, MIN_STOPS, seed=6, expert=expert)
    np.testing.assert_allclose(first.offset_m, 2 * np.asarray(BIAS), atol=0.03)
    centred = centre_home_offset(env, first, MIN_STOPS, seed=6, expert=expert)
    assert centred.first_offset_m == first.offset_m and centred.centred_success_rate == 1.0
    assert centred.episodes == 2 * MIN_STOPS
    np.testing.assert_allclose(centred.slope, (2.0, 2.0), atol=0.4)
    # within the expert's tolerance (it stops on the near edge of a 4 cm circle)
    np.testing.assert_allclose(centred.offset_m, BIAS, atol=0.025)
    # going to twice the bias it stopped twice the bias out (the estimate's home, mirrored)
    np.testing.assert_allclose(centred.median_stop_m, 2 * np.asarray(BIAS), atol=0.03)
    assert env.get_wrapper_attr("home_offset_m") == (0.0, 0.0)  # the env is given back
    assert centred.to_dict()["slope"] == [round(v, 3) for v in centred.slope]
    with pytest.raises(ValueError, match="already centred"):
        centre_home_offset(env, centred, MIN_STOPS, seed=6)
    with pytest.raises(ValueError, match="at least one env"):
        centre_home_offset([], first, MIN_STOPS, seed=6)
    for bad in (0, 2.5, True):  # the same checks as the measurement's
        with pytest.raises(ValueError, match="episodes"):
            centre_home_offset(env, first, bad, seed=6)
    with pytest.raises(ValueError, match="Homing-v0"):
        centre_home_offset(gym.make("CartPole-v1"), first, MIN_STOPS, seed=6, expert=expert)


def test_bad_measurements_are_refused(make):
    with pytest.raises(ValueError, match="home_offset_m is \\(0, 0\\)"):
        measure_home_offset(make(BiasedOracle(), home_offset_m=(0.1, 0.0)), 5, seed=0)
    env = make(BiasedOracle())
    for bad in (0, 2.5, True):
        with pytest.raises(ValueError, match="episodes"):
            measure_home_offset(env, bad, seed=0)
    with pytest.raises(ValueError, match="at least one env"):
        measure_home_offset([], 5, seed=0)
    with pytest.raises(ValueError, match="Homing-v0"):
        measure_home_offset(gym.make("CartPole-v1"), MIN_STOPS, seed=0)

    class NeverStops:
        def predict(self, features):
            return np.array([0.5, 0.0, -1.0], np.float32)

    with pytest.raises(ValueError, match="stopped in only 0 of 5"):
        measure_home_offset(env, MIN_STOPS, seed=0, expert=NeverStops())
    lost = make(BiasedOracle(bias=(1.5, 0.0)))
    with pytest.raises(ValueError, match="lost"):
        measure_home_offset(lost, MIN_STOPS, seed=0, expert=StopAtOnce())
