"""Tests of the trot kinematics (vc_gym.sim.gait): pure functions, no PyBullet."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.sim.gait import (
    BODY_HEIGHT_M,
    FOOT_LIFT_M,
    FOOT_XY,
    GAIT_PERIOD_S,
    HIP_OFFSET_M,
    HIP_XY,
    PHASE_OFFSET,
    THIGH_M,
    TOE_RADIUS_M,
    arc_displacement,
    gait_joint_angles,
    leg_ik,
)

SIDES = (-1.0, 1.0, -1.0, 1.0)  # FR, FL, RR, RL
STAND_Z = -(BODY_HEIGHT_M - TOE_RADIUS_M)


def _leg_fk(q1: float, q2: float, q3: float, side: float) -> np.ndarray:
    """Foot position relative to the hip of an a1 leg with these joint angles."""
    x = -THIGH_M * math.sin(q2) - THIGH_M * math.sin(q2 + q3)
    z = -THIGH_M * math.cos(q2) - THIGH_M * math.cos(q2 + q3)
    y = side * HIP_OFFSET_M
    c, s = math.cos(q1), math.sin(q1)
    return np.array([x, c * y - s * z, s * y + c * z])


def _feet(angles: list[float]) -> np.ndarray:
    """``(4, 3)`` foot positions relative to the hips for the 12 gait angles."""
    return np.array([_leg_fk(*angles[3 * i : 3 * i + 3], SIDES[i]) for i in range(4)])


def test_leg_ik_reaches_the_foot_position():
    rng = np.random.default_rng(0)
    for side in (-1.0, 1.0):
        for _ in range(50):
            target = np.array(
                [rng.uniform(-0.1, 0.1), side * rng.uniform(0.05, 0.15), rng.uniform(-0.3, -0.15)]
            )
            q = leg_ik(*target, side)
            np.testing.assert_allclose(_leg_fk(*q, side), target, atol=1e-12)
            assert q[2] <= 0.0  # the knee bends backwards


def test_leg_ik_out_of_reach_stretches_the_leg():
    q1, q2, q3 = leg_ik(0.0, HIP_OFFSET_M, -1.0, 1.0)
    assert q3 == pytest.approx(0.0, abs=1e-12)
    assert all(math.isfinite(q) for q in (q1, q2, q3))


@pytest.mark.parametrize("phase", [0.0, 0.3, 0.8])
def test_standing_puts_every_foot_at_its_nominal_position(phase):
    angles = gait_joint_angles(phase, 0.0, 0.0, 0.0)
    assert len(angles) == 12 and all(isinstance(a, float) for a in angles)
    feet = _feet(angles)
    np.testing.assert_allclose(feet[:, :2], FOOT_XY - HIP_XY, atol=1e-12)
    np.testing.assert_allclose(feet[:, 2], STAND_Z, atol=1e-12)
    assert angles == gait_joint_angles(0.0, 0.0, 0.0, 0.0)


def test_trot_moves_diagonal_legs_together():
    assert list(PHASE_OFFSET) == [0.0, 0.5, 0.5, 0.0]
    for phase in np.linspace(0.0, 0.95, 7):
        feet = _feet(gait_joint_angles(float(phase), 0.3, 0.0, 0.0))
        other = _feet(gait_joint_angles(float((phase + 0.5) % 1.0), 0.3, 0.0, 0.0))
        # FR and RL (and FL and RR) share a phase; FL is FR half a period later
        np.testing.assert_allclose(feet[0, [0, 2]], feet[3, [0, 2]], atol=1e-12)
        np.testing.assert_allclose(feet[1, [0, 2]], feet[2, [0, 2]], atol=1e-12)
        np.testing.assert_allclose(feet[1, [0, 2]], other[0, [0, 2]], atol=1e-12)


@pytest.mark.parametrize("vx, vy, wz", [(0.4, 0.0, 0.0), (0.0, -0.2, 0.0), (0.2, 0.1, 1.2)])
def test_stance_feet_sweep_back_at_the_body_velocity(vx, vy, wz):
    s1, s2 = 0.05, 0.35  # both in the stance half of FR's cycle (offset 0)
    a = _feet(gait_joint_angles(s1, vx, vy, wz))
    b = _feet(gait_joint_angles(s2, vx, vy, wz))
    velocity = (b[0] - a[0]) / ((s2 - s1) * GAIT_PERIOD_S)
    fx, fy = FOOT_XY[0]
    # the foot stays on the ground while moving at -(v + w x r) relative to the trunk
    np.testing.assert_allclose(velocity[:2], [-(vx - wz * fy), -(vy + wz * fx)], atol=1e-9)
    np.testing.assert_allclose([a[0, 2], b[0, 2]], STAND_Z, atol=1e-12)


def test_swing_foot_is_lifted_mid_swing():
    feet = _feet(gait_joint_angles(0.75, 0.3, 0.0, 0.0))
    assert feet[0, 2] == pytest.approx(STAND_Z + FOOT_LIFT_M, abs=1e-12)  # FR mid-swing
    assert feet[1, 2] == pytest.approx(STAND_Z, abs=1e-12)  # FL mid-stance
    assert feet[0, 0] == pytest.approx(0.0, abs=1e-12)  # half-way forwards


def test_arc_displacement():
    assert arc_displacement(0.3, -0.1, 0.0, 2.0) == (pytest.approx(0.6), pytest.approx(-0.2), 0.0)
    dx, dy, th = arc_displacement(0.0, 0.0, 1.5, 2.0)
    assert (dx, dy, th) == (pytest.approx(0.0, abs=1e-15), pytest.approx(0.0, abs=1e-15), 3.0)
    # a quarter circle of radius 2/pi
    dx, dy, th = arc_displacement(1.0, 0.0, math.pi / 2, 1.0)
    np.testing.assert_allclose([dx, dy, th], [2 / math.pi, 2 / math.pi, math.pi / 2])


def test_arc_displacement_composes_in_the_plane():
    vx, vy, wz = 0.4, 0.15, -0.9
    x1, y1, t1 = arc_displacement(vx, vy, wz, 0.7)
    x2, y2, t2 = arc_displacement(vx, vy, wz, 0.5)
    c, s = math.cos(t1), math.sin(t1)
    composed = [x1 + c * x2 - s * y2, y1 + s * x2 + c * y2, t1 + t2]
    np.testing.assert_allclose(composed, arc_displacement(vx, vy, wz, 1.2), atol=1e-12)
