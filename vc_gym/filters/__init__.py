"""Bayesian filters with pluggable sensor models (paper sections 3.5-3.6).

Filters never import the compass: any object with ``heading_log_likelihood`` (a
:class:`HeadingSensor`) or ``pose_log_likelihood`` (a :class:`PoseSensor`) plugs in.
The compass does through :class:`vc_gym.localization.CompassHeadingSensor` and
:class:`vc_gym.localization.AtlasPoseSensor`.
"""

from vc_gym.filters.estimates import HeadingEstimate
from vc_gym.filters.heading_grid import RULES, HeadingGridFilter, mixing_lambda
from vc_gym.filters.heading_kalman import KalmanHeadingFilter
from vc_gym.filters.particle_filter import ParticleFilter, PoseEstimate
from vc_gym.filters.sensor_protocol import HeadingSensor, PoseSensor, check_log_likelihood
from vc_gym.filters.synthetic_sensors import GaussianPoseSensor, VonMisesHeadingSensor
from vc_gym.filters.translational import TranslationalFilter, weighted_spot_position

__all__ = [
    "RULES",
    "GaussianPoseSensor",
    "HeadingEstimate",
    "HeadingGridFilter",
    "HeadingSensor",
    "KalmanHeadingFilter",
    "ParticleFilter",
    "PoseEstimate",
    "PoseSensor",
    "TranslationalFilter",
    "VonMisesHeadingSensor",
    "check_log_likelihood",
    "mixing_lambda",
    "weighted_spot_position",
]
