"""Deprecated alias of :mod:`vc_gym.heading_sensors` (kept for one release).

The other heading sensors moved to :mod:`vc_gym.heading_sensors`, a name that does not
read as reinforcement-learning baselines.
"""

import warnings

from vc_gym.heading_sensors import *  # noqa: F403
from vc_gym.heading_sensors import __all__  # noqa: F401

warnings.warn(
    "vc_gym.baselines is deprecated: import vc_gym.heading_sensors instead",
    DeprecationWarning,
    stacklevel=2,
)
