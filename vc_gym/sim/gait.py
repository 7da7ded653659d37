"""The trot of the quadruped: leg geometry, foot trajectories and inverse kinematics.

Pure functions of the gait phase and the body velocity, with no PyBullet: the
:class:`~vc_gym.sim.robot.Quadruped` sends their joint angles to the motors (physics
modes) or poses the legs with them (kinematic mode).

The gait is an open-loop trot of period :data:`GAIT_PERIOD_S`: diagonal legs (FR with RL,
FL with RR) move together, half a period apart (:data:`PHASE_OFFSET`). During the first
half of its cycle a foot is in stance and sweeps backwards at the velocity the body should
move with; during the second half it swings forwards along an arc raised by
:data:`FOOT_LIFT_M`. The trunk stays :data:`BODY_HEIGHT_M` above the floor.

Frames and units: positions in metres in the trunk frame (x forward, y left, z up), legs
in the a1's URDF order FR, FL, RR, RL, angles in radians (this module is internal to the
robot; the public API of :mod:`vc_gym.sim` uses degrees).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "BODY_HEIGHT_M",
    "FOOT_LIFT_M",
    "FOOT_XY",
    "GAIT_PERIOD_S",
    "HIP_OFFSET_M",
    "HIP_XY",
    "PHASE_OFFSET",
    "THIGH_M",
    "TOE_RADIUS_M",
    "arc_displacement",
    "gait_joint_angles",
    "leg_ik",
]

#: Nominal height of the trunk frame above the floor while standing and walking (m).
BODY_HEIGHT_M = 0.27

#: Period of one trot cycle (s).
GAIT_PERIOD_S = 0.3
#: Height of a swing foot at the top of its arc (m).
FOOT_LIFT_M = 0.06
#: Radius of the a1's spherical toe (m): the toe centre stands this far above the floor.
TOE_RADIUS_M = 0.02
#: Length of the thigh, and of the calf, which is the same (m).
THIGH_M = 0.2
#: Distance from the abduction axis to the thigh plane (m).
HIP_OFFSET_M = 0.08505
#: Hip (abduction) joint positions in the trunk frame, ``(4, 2)``, legs FR, FL, RR, RL.
HIP_XY = np.array([[0.183, -0.047], [0.183, 0.047], [-0.183, -0.047], [-0.183, 0.047]])
# side of each leg: +1 left, -1 right
_SIDE = np.array([-1.0, 1.0, -1.0, 1.0])
# feet stand 3 cm outside the thigh planes: a wider stance keeps combined turning and
# side-stepping from tipping the dynamic trot over
_STANCE_WIDEN_M = 0.03
_FOOT_Y = HIP_OFFSET_M + _STANCE_WIDEN_M
#: Nominal foot positions in the floor plane, relative to the trunk frame, ``(4, 2)``.
FOOT_XY = HIP_XY + np.stack([np.zeros(4), _SIDE * _FOOT_Y], axis=1)
#: Gait phase offset of each leg (trot: FR and RL together, FL and RR half a period later).
PHASE_OFFSET = np.array([0.0, 0.5, 0.5, 0.0])
# per leg: nominal foot (x, y), side, phase offset, as Python floats for the hot path
_LEGS = [
    ((float(xy[0]), float(xy[1])), float(side), float(offset))
    for xy, side, offset in zip(FOOT_XY, _SIDE, PHASE_OFFSET, strict=True)
]


def leg_ik(px: float, py: float, pz: float, side: float) -> tuple[float, float, float]:
    """Joint angles that put a foot at a position relative to its hip.

    Analytic inverse kinematics of the a1 leg: abduction about x, then thigh and calf
    about y (both :data:`THIGH_M` long), knee bending backwards. Pure Python, because it
    runs for every leg at every control tick.

    Parameters
    ----------
    px, py, pz : float
        Foot position relative to the leg's hip (abduction) joint, in the trunk frame (m).
    side : float
        +1 for a left leg, -1 for a right one.

    Returns
    -------
    (float, float, float)
        Abduction, thigh and calf angles (rad). A position out of reach gives the
        nearest reachable pose (fully stretched or folded knee).
    """
    l1 = side * HIP_OFFSET_M
    zp = -math.sqrt(max(py * py + pz * pz - l1 * l1, 1e-9))
    q1 = math.atan2(pz, py) - math.atan2(zp, l1)
    cos_knee = (px * px + zp * zp - 2.0 * THIGH_M**2) / (2.0 * THIGH_M**2)
    q3 = -math.acos(min(max(cos_knee, -1.0), 1.0))
    q2 = math.atan2(-px, -zp) - 0.5 * q3
    return q1, q2, q3


def gait_joint_angles(phase: float, vx: float, vy: float, wz: float) -> list[float]:
    """The 12 leg joint angles of the trot at a gait phase and body velocity.

    Stance feet sweep backwards at the velocity the body should move with, including the
    rotation about the trunk centre; swing feet return along a raised arc. With no motion
    commanded the robot stands on all four feet at their nominal positions.

    Parameters
    ----------
    phase : float
        Gait phase in ``[0, 1)`` (fraction of :data:`GAIT_PERIOD_S`).
    vx, vy : float
        Body velocity forwards and to the left (m/s).
    wz : float
        Turn rate, counter-clockwise positive (rad/s).

    Returns
    -------
    list of float
        ``(abduction, thigh, calf)`` of each leg in the order FR, FL, RR, RL (rad).
    """
    moving = abs(vx) + abs(vy) + 0.2 * abs(wz) > 1e-6
    half = 0.5 * GAIT_PERIOD_S
    depth = -(BODY_HEIGHT_M - TOE_RADIUS_M)
    angles: list[float] = []
    for (fx, fy), side, offset in _LEGS:
        px, py, pz = 0.0, side * _FOOT_Y, depth
        if moving:
            s = (phase + offset) % 1.0
            if s < 0.5:  # stance: straight back at the ground speed, +1/2 .. -1/2
                along = 0.5 - 2.0 * s
            else:  # swing: forwards along a raised arc, -1/2 .. +1/2
                u = 2.0 * s - 1.0
                along = 0.5 * (1.0 - math.cos(math.pi * u)) - 0.5
                pz += FOOT_LIFT_M * math.sin(math.pi * u)
            # foot velocity relative to the ground-fixed body motion: v + w x r
            px = along * (vx - wz * fy) * half
            py += along * (vy + wz * fx) * half
        angles.extend(leg_ik(px, py, pz, side))
    return angles


def arc_displacement(vx: float, vy: float, wz: float, t: float) -> tuple[float, float, float]:
    """Displacement after moving with a constant body velocity.

    Parameters
    ----------
    vx, vy : float
        Body velocity forwards and to the left (m/s), in the body frame.
    wz : float
        Turn rate, counter-clockwise positive (rad/s).
    t : float
        Duration (s).

    Returns
    -------
    (float, float, float)
        Forward (m), left (m) and turn (rad), in the body frame at the start: the exact
        circular arc, or the straight line when the turn is (almost) zero.
    """
    th = wz * t
    if abs(th) < 1e-9:
        return vx * t, vy * t, th
    s, c = math.sin(th), math.cos(th)
    return (vx * s + vy * (c - 1.0)) / wz, (vx * (1.0 - c) + vy * s) / wz, th
