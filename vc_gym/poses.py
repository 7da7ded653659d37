"""Planar poses: the one place where robot-frame motion meets the world frame (SE(2)).

A pose is ``(x, y, θ)`` in metres and degrees (world frame: x east, y north, θ CCW
from x). Odometry is ``(forward, left, turn)``: metres in the robot's frame at the
start of the motion, and degrees. Dead reckoning, the filters' motion updates and the
home vector all go through these functions.
"""

from __future__ import annotations

import math

from vc_gym.angles import wrap360

__all__ = ["body_to_world", "check_pose", "compose", "world_to_body"]


def check_pose(pose: object) -> tuple[float, float, float]:
    """``pose`` as three finite floats ``(x m, y m, θ deg)``.

    Raises
    ------
    ValueError
        If ``pose`` is not three numbers, or one of them is NaN or infinite.
    """
    try:
        x, y, theta = (float(v) for v in pose)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise ValueError(f"pose must be (x, y, heading_deg), got {pose!r}") from None
    if not all(math.isfinite(v) for v in (x, y, theta)):
        raise ValueError(f"pose must be 3 finite numbers, got {pose!r}")
    return x, y, theta


def body_to_world(forward: float, left: float, heading_deg: float) -> tuple[float, float]:
    """Rotate a robot-frame displacement into the world frame.

    Parameters
    ----------
    forward, left : float
        Displacement along the robot's heading and to its left, metres.
    heading_deg : float
        The robot's heading, degrees CCW from the world x axis.

    Returns
    -------
    tuple of float
        ``(dx, dy)`` in the world frame.
    """
    th = math.radians(heading_deg)
    c, s = math.cos(th), math.sin(th)
    return forward * c - left * s, forward * s + left * c


def world_to_body(dx: float, dy: float, heading_deg: float) -> tuple[float, float]:
    """Inverse of :func:`body_to_world`: a world displacement as ``(forward, left)``."""
    th = math.radians(heading_deg)
    c, s = math.cos(th), math.sin(th)
    return dx * c + dy * s, -dx * s + dy * c


def compose(
    pose: tuple[float, float, float], odometry: tuple[float, float, float]
) -> tuple[float, float, float]:
    """Dead reckoning: move ``pose`` by robot-frame ``odometry`` (paper eq. 19-21).

    The translation is applied in the frame of ``pose`` (eq. 21), then the turn is
    added (eq. 20); the heading of the result is wrapped to ``[0, 360)``.
    """
    x, y, th = pose
    fwd, left, turn = odometry
    dx, dy = body_to_world(fwd, left, th)
    return x + dx, y + dy, float(wrap360(th + turn))
