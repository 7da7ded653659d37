"""The scripted homing policy acts on the tracker's estimates only (known answers)."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.agents.scripted import ScriptedHomingPolicy


def velocity(forward_m_s=0.0, turn_deg_s=0.0, pan_deg=0.0):
    """A stand-in for the env's velocity_action: the commands, readable."""
    return np.array([forward_m_s, 0.0, turn_deg_s, pan_deg, 0.0])


def obs(home_fwd, home_left, spread=5.0):
    return {"home_vector": np.array([home_fwd, home_left]), "heading_spread": np.array([spread])}


def policy(**kwargs):
    return ScriptedHomingPolicy(velocity, dt_s=0.1, **kwargs)


def test_settles_first_then_walks_to_home_ahead():
    p = policy(settle_time_s=1.0)
    for _ in range(10):  # 1 s of settling: no body motion, head scanning
        a = p.predict(obs(2.0, 0.0))
        assert a[0] == 0.0 and a[2] == 0.0
    a = p.predict(obs(2.0, 0.0))
    assert a[0] == pytest.approx(0.25) and a[2] == pytest.approx(0.0)  # full walking speed


def test_turns_towards_home_on_the_left_without_walking():
    p = policy(settle_time_s=0.0)
    a = p.predict(obs(0.0, 1.0))  # home 90 deg to the left
    assert a[0] == 0.0 and a[2] == pytest.approx(60.0)  # turn left at the cap


def test_waits_while_the_heading_is_unsure():
    p = policy(settle_time_s=0.0, max_spread_deg=30.0)
    a = p.predict(obs(2.0, 0.0, spread=90.0))
    assert a[0] == 0.0 and a[2] == 0.0 and a[3] != 0.0  # scanning with the head


def test_stands_at_home_with_hysteresis():
    p = policy(settle_time_s=0.0, home_tolerance_m=0.1, rearm_factor=2.5)
    assert p.predict(obs(0.05, 0.0))[0] == 0.0  # arrived
    assert p.predict(obs(0.2, 0.0))[0] == 0.0  # jitter within 2.5 x 0.1 m: stay
    assert p.predict(obs(0.3, 0.0))[0] > 0.0  # clearly away: walk again
    p.reset()
    assert p.predict(obs(0.2, 0.0))[0] > 0.0


def test_the_head_looks_ahead_while_walking_unless_told_to_scan():
    ahead = policy(settle_time_s=0.0)
    assert {float(ahead.predict(obs(2.0, 0.0))[3]) for _ in range(8)} == {0.0}
    scanning = policy(settle_time_s=0.0, walk_scan_deg=(-60.0, 0.0, 60.0, 0.0))
    actions = [scanning.predict(obs(2.0, 0.0)) for _ in range(8)]
    assert all(a[0] > 0 for a in actions)  # walking all the while
    assert [float(a[3]) for a in actions[:4]] == [0.0, 60.0, 0.0, -60.0]


def test_an_unsure_belief_turns_to_look_instead_of_walking_or_standing():
    p = policy(settle_time_s=0.0, look_std_m=0.3, look_turn_deg_s=45.0)
    unsure = {**obs(2.0, 0.0), "position_std": np.array([0.5, 0.1])}
    a = p.predict(unsure)
    assert a[0] == 0.0 and a[2] == pytest.approx(45.0)  # turning on the spot, not still
    assert not ScriptedHomingPolicy.is_still(a)
    sure = {**obs(2.0, 0.0), "position_std": np.array([0.1, 0.1])}
    assert p.predict(sure)[0] > 0.0  # walks home once the belief is narrow
    settling = policy(settle_time_s=1.0, look_std_m=0.3)
    assert settling.predict(unsure)[2] == 0.0  # the settling time comes first


def test_for_env_needs_a_velocity_action():
    class NoScaling:
        unwrapped = object()

    with pytest.raises(ValueError, match="velocity_action"):
        ScriptedHomingPolicy.for_env(NoScaling())


@pytest.mark.parametrize(
    "kwargs",
    [
        {"dt_s": 0.0},
        {"home_tolerance_m": -0.1},
        {"head_scan_deg": ()},
        {"head_scan_deg": (100.0,)},
        {"walk_scan_deg": ()},
        {"walk_scan_deg": (float("nan"),)},
        {"walk_scan_deg": "left"},
        {"look_std_m": 0.0},
        {"look_turn_deg_s": float("inf")},
        {"rearm_factor": 0.5},
        {"settle_time_s": float("nan")},
    ],
)
def test_bad_parameters(kwargs):
    with pytest.raises(ValueError):
        ScriptedHomingPolicy(velocity, **kwargs)
    with pytest.raises(ValueError):
        ScriptedHomingPolicy("fast")


class AliasingWorld:
    """A kinematic robot whose tracker aliases: facing within ±30° of east it reports
    "home" wherever it is; at other headings it reports 0.6 × the true position. Over a
    full turn that averages to half the true position (the full-turn average of the
    atlas' eq. 30 shrinks like that 1-2 m from home)."""

    def __init__(self, x, y, heading_deg):
        self.x, self.y, self.h = x, y, heading_deg

    def obs(self, odometry=(0.0, 0.0, 0.0)):
        alias = abs((self.h + 180.0) % 360.0 - 180.0) <= 30.0
        px, py = (0.0, 0.0) if alias else (0.6 * self.x, 0.6 * self.y)
        th = np.radians(self.h)
        dx, dy = -px, -py  # home at the origin
        fwd, left = dx * np.cos(th) + dy * np.sin(th), -dx * np.sin(th) + dy * np.cos(th)
        return {
            "home_vector": np.array([fwd, left]),
            "heading_spread": np.array([2.0]),
            "heading": np.array([np.cos(th), np.sin(th)]),
            "odometry": np.array(odometry, np.float64),
        }

    def step(self, action, dt=0.1):
        fwd, turn = float(action[0]) * dt, float(action[2]) * dt
        th = np.radians(self.h)
        self.x += fwd * np.cos(th)
        self.y += fwd * np.sin(th)
        self.h = (self.h + turn) % 360.0
        return self.obs((fwd, 0.0, turn))


def run_until_still(p, world, steps=1200):
    o = world.obs()
    still = 0
    for _ in range(steps):
        a = p.predict(o)
        still = still + 1 if ScriptedHomingPolicy.is_still(a) else 0
        if still >= 50:  # the task's 5 s stop rule
            return True
        o = world.step(a)
    return False


def test_paper_policy_stops_where_one_view_aliases_with_home():
    world = AliasingWorld(-1.2, 0.6, 0.0)
    assert run_until_still(policy(settle_time_s=0.0), world)
    assert np.hypot(world.x, world.y) > 1.3  # never moved


def test_verify_home_turns_and_walks_out_of_an_alias():
    p = policy(settle_time_s=0.0, verify_home=True, verify_gain=2.0, max_verifications=6)
    world = AliasingWorld(-1.2, 0.6, 0.0)
    assert run_until_still(p, world)
    assert p.phase == "done"
    assert np.hypot(world.x, world.y) < 0.15  # home
    first = p.checks[0]  # the first full turn points home: half of (+1.2, -0.6)
    assert first == pytest.approx((0.6, -0.3), abs=0.05)
    assert np.hypot(*p.checks[-1]) <= p.verify_tolerance_m


def test_verify_home_stops_after_max_verifications():
    p = policy(settle_time_s=0.0, verify_home=True, verify_gain=0.2, max_verifications=2)
    world = AliasingWorld(-1.2, 0.6, 0.0)
    assert run_until_still(p, world)
    assert len(p.checks) == 2 and p.phase == "done"


def test_verify_home_at_home_stops_after_one_turn():
    p = policy(settle_time_s=0.0, verify_home=True)
    world = AliasingWorld(0.02, -0.03, 90.0)
    assert run_until_still(p, world)
    assert len(p.checks) == 1 and np.hypot(world.x, world.y) < 0.05


class SureWorld(AliasingWorld):
    """The aliasing robot whose tracker also states a position standard deviation."""

    def __init__(self, x, y, heading_deg, std_m):
        super().__init__(x, y, heading_deg)
        self.std_m = std_m

    def obs(self, odometry=(0.0, 0.0, 0.0)):
        return {**super().obs(odometry), "position_std": np.array([self.std_m, self.std_m])}


def test_a_sure_belief_at_home_stops_without_the_checking_turn():
    p = policy(settle_time_s=0.0, verify_home=True, sure_std_m=0.3)
    world = SureWorld(0.02, -0.03, 90.0, std_m=0.25)
    assert run_until_still(p, world)
    assert p.phase == "done" and p.checks == []
    assert world.h == 90.0  # never turned


def test_an_unsure_belief_at_home_still_checks():
    p = policy(settle_time_s=0.0, verify_home=True, sure_std_m=0.3)
    world = SureWorld(0.02, -0.03, 90.0, std_m=0.5)
    assert run_until_still(p, world)
    assert len(p.checks) == 1


@pytest.mark.parametrize("bad", [0.0, -0.1, float("nan"), "0.3"])
def test_sure_std_must_be_a_positive_distance(bad):
    with pytest.raises(ValueError, match="sure_std_m"):
        policy(verify_home=True, sure_std_m=bad)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"verify_home": "yes"},
        {"verify_tolerance_m": 0.0},
        {"verify_gain": float("inf")},
        {"max_verifications": 0},
        {"max_verifications": 2.5},
        {"verify_turn_deg_s": -10.0},
    ],
)
def test_bad_verification_parameters(kwargs):
    with pytest.raises(ValueError):
        ScriptedHomingPolicy(velocity, **kwargs)


class BiasedWorld(AliasingWorld):
    """A kinematic robot whose tracker reports its true position off by ``bias``: the
    tracker's home lies at ``-bias``."""

    def __init__(self, x, y, heading_deg, bias):
        super().__init__(x, y, heading_deg)
        self.bias = bias

    def obs(self, odometry=(0.0, 0.0, 0.0)):
        px, py = self.x + self.bias[0], self.y + self.bias[1]
        th = np.radians(self.h)
        fwd, left = -px * np.cos(th) - py * np.sin(th), px * np.sin(th) - py * np.cos(th)
        return {
            "home_vector": np.array([fwd, left]),
            "heading_spread": np.array([2.0]),
            "heading": np.array([np.cos(th), np.sin(th)]),
            "odometry": np.array(odometry, np.float64),
        }


@pytest.mark.parametrize("verify_home", [False, True])
def test_home_offset_makes_the_goal_the_true_home(verify_home):
    bias = (0.15, -0.2)
    world = BiasedWorld(1.0, -0.5, 90.0, bias)
    assert run_until_still(policy(settle_time_s=0.0, verify_home=verify_home), world)
    assert np.hypot(world.x + bias[0], world.y + bias[1]) <= 0.1  # at the tracker's home
    world = BiasedWorld(1.0, -0.5, 90.0, bias)
    p = policy(settle_time_s=0.0, verify_home=verify_home, home_offset_m=bias)
    assert run_until_still(p, world)
    assert np.hypot(world.x, world.y) <= 0.1  # at the true home


@pytest.mark.parametrize("bad", [(2.0, 0.0), (float("nan"), 0.0), (0.1,), "0,0"])
def test_home_offset_must_be_a_nearby_point(bad):
    with pytest.raises(ValueError, match="home_offset_m"):
        policy(home_offset_m=bad)
