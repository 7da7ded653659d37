"""How wrong the quadruped's odometry is: :class:`OdometryNoise`.

The :class:`~vc_gym.sim.robot.Quadruped` reports the motion its walking engine was told
to make; these settings say how that report is distorted (per-episode scale errors and
per-step noise). Plain data, with no PyBullet.
"""

from __future__ import annotations

from dataclasses import dataclass

from vc_gym.validation import finite_float

__all__ = ["OdometryNoise"]


@dataclass(frozen=True)
class OdometryNoise:
    """How wrong the robot's odometry is.

    Parameters
    ----------
    trans_scale : float
        Standard deviation of a per-episode multiplicative scale error on translations,
        drawn at :meth:`vc_gym.sim.robot.Quadruped.reset`: every reported translation is
        multiplied by ``1 + N(0, trans_scale)`` (clipped at 0).
    rot_scale : float
        The same for rotations.
    trans_std : float
        Per-step additive noise on the forward and left components, standard deviation
        in metres per metre of the step's commanded component.
    rot_std : float
        Per-step additive noise on the turn, degrees per degree of the step's turn.
    slip_std_m : float
        Per-step additive noise (metres) on forward and left, independent of the motion.
    """

    trans_scale: float = 0.05
    rot_scale: float = 0.05
    trans_std: float = 0.01
    rot_std: float = 0.02
    slip_std_m: float = 0.0

    def __post_init__(self) -> None:
        for name in ("trans_scale", "rot_scale", "trans_std", "rot_std", "slip_std_m"):
            value = finite_float(name, getattr(self, name))
            if value < 0:
                raise ValueError(f"{name} must be >= 0, got {value!r}")
