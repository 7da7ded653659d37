"""Other heading sensors under the visual compass' protocol (the paper's section 6).

Each learns at a spot from frames with a known yaw and answers a log-likelihood over
headings, like :class:`~vc_gym.compass.VisualCompass` (the
:class:`~vc_gym.compass.ImageCompass` surface), so the same filters, trackers and
experiments take them (``vc-gym experiment sensors``):

* :class:`ImageDifferenceCompass` — the rotational image difference (Zeil et al.;
  Labrosse's visual compass), every shift at once by FFT;
* :class:`SectorColorCompass` — mean colour per sector (Porta & Kröse);
* :class:`FeatureCompass` — ORB keypoints learned with their direction;
* :class:`NoisyMagneticCompass` — a magnetometer: true heading, noise and a local
  disturbance field (no camera).

The tracker ``{"type": SENSOR_GRID, "sensor": name, "sensor_file": path}`` is the grid
tracker with a saved image sensor as its heading sensor.

>>> from vc_gym.heading_sensors import make_sensor                          # doctest: +SKIP
>>> sensor = make_sensor("image_difference")                         # doctest: +SKIP
>>> for image, yaw in frames: sensor.learn(image, Camera(yaw_deg=yaw))  # doctest: +SKIP
>>> sensor.estimate(new_image, Camera()).heading_deg                 # doctest: +SKIP
"""

from vc_gym.deprecation import moved_names
from vc_gym.heading_sensors import sector_color as _sector_color
from vc_gym.heading_sensors.base import BaselineCompass, FrameScore
from vc_gym.heading_sensors.feature import FeatureCompass
from vc_gym.heading_sensors.image_difference import ImageDifferenceCompass
from vc_gym.heading_sensors.magnetic import (
    DisturbanceSource,
    MagnetometerCompass,
    NoisyMagneticCompass,
)
from vc_gym.heading_sensors.registry import (
    DEPRECATED_SENSOR_NAMES,
    SENSORS,
    current_sensor_name,
    make_sensor,
    register_sensor,
)
from vc_gym.heading_sensors.sector_color import SectorColorCompass
from vc_gym.heading_sensors.strip import StripGrid, angular_strip
from vc_gym.heading_sensors.tracking import (
    IMAGE_SENSORS,
    SENSOR_GRID,
    load_sensor,
    sensor_grid_tracker,
)

__all__ = [
    "DEPRECATED_SENSOR_NAMES",
    "IMAGE_SENSORS",
    "SENSORS",
    "SENSOR_GRID",
    "BaselineCompass",
    "DisturbanceSource",
    "FeatureCompass",
    "FrameScore",
    "ImageDifferenceCompass",
    "MagnetometerCompass",
    "NoisyMagneticCompass",
    "SectorColorCompass",
    "StripGrid",
    "angular_strip",
    "current_sensor_name",
    "load_sensor",
    "make_sensor",
    "register_sensor",
    "sensor_grid_tracker",
]

# deprecated: SectorColourCompass, the British spelling of SectorColorCompass, served for
# one release
__getattr__ = moved_names(__name__, {"SectorColourCompass": (_sector_color, "SectorColorCompass")})
