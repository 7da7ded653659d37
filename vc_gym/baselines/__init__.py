"""Deprecated alias of :mod:`vc_gym.heading_sensors` (kept for one release).

The other heading sensors moved to :mod:`vc_gym.heading_sensors`, a name that does not
read as reinforcement-learning baselines.
"""

import warnings

from vc_gym.deprecation import moved_names
from vc_gym.heading_sensors import *  # noqa: F403
from vc_gym.heading_sensors import __all__  # noqa: F401
from vc_gym.heading_sensors import sector_color as _sector_color

warnings.warn(
    "vc_gym.baselines is deprecated: import vc_gym.heading_sensors instead",
    DeprecationWarning,
    stacklevel=2,
)

# deprecated: SectorColourCompass, the British spelling of SectorColorCompass, served for
# one release
__getattr__ = moved_names(__name__, {"SectorColourCompass": (_sector_color, "SectorColorCompass")})
