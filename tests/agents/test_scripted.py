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
        {"rearm_factor": 0.5},
        {"settle_time_s": float("nan")},
    ],
)
def test_bad_parameters(kwargs):
    with pytest.raises(ValueError):
        ScriptedHomingPolicy(velocity, **kwargs)
    with pytest.raises(ValueError):
        ScriptedHomingPolicy("fast")
