"""A baseline as the heading sensor of a tracker on the homing task.

``{"type": SENSOR_GRID, "sensor": "feature", "sensor_file": "home.npz"}`` (the type is
``"vc_gym.heading_sensors.tracking:sensor_grid_tracker"``) is the paper's grid tracker whose
heading filter reads a saved baseline (or a visual compass of its own) instead of the
atlas; position still comes from the atlas' spots (eq. 30). The spec is plain JSON, so
it travels to worker processes and comes from the command line
(``vc-gym experiment homing --sensor feature``).
"""

from __future__ import annotations

import os
from typing import Any

from vc_gym.compass import ImageCompass, VisualCompass
from vc_gym.heading_sensors.base import BaselineCompass
from vc_gym.heading_sensors.registry import SENSORS, current_sensor_name
from vc_gym.localization import GridTracker

__all__ = ["IMAGE_SENSORS", "SENSOR_GRID", "load_sensor", "sensor_grid_tracker"]

#: The tracker type of :func:`sensor_grid_tracker` in a tracker spec.
SENSOR_GRID = f"{__name__}:sensor_grid_tracker"


def _loader(name: str) -> Any:
    name = current_sensor_name(name, stacklevel=3)  # warns the caller of load_sensor
    if name == "visual_compass":
        return VisualCompass
    cls = SENSORS.get(name)
    if _is_baseline(cls):
        return cls
    raise ValueError(
        f"sensor {name!r} is not an image sensor that can be saved; image sensors: "
        f"{image_sensor_names()}"
    )


def _is_baseline(factory: object) -> bool:
    return isinstance(factory, type) and issubclass(factory, BaselineCompass)


def image_sensor_names() -> list[str]:
    """Names in :data:`~vc_gym.heading_sensors.SENSORS` a tracker can read images with."""
    return sorted(n for n in SENSORS if n == "visual_compass" or _is_baseline(SENSORS[n]))


#: The image sensors registered when this module was imported.
IMAGE_SENSORS = tuple(image_sensor_names())


def load_sensor(name: str, path: str | os.PathLike) -> ImageCompass:
    """Load a saved image sensor of kind ``name`` (``"feature"``, ``"visual_compass"``...).

    Raises
    ------
    ValueError
        ``name`` is not a saveable image sensor (the message lists them).
    MapFileError
        The file cannot be read as that sensor (it names the file and why).
    """
    return _loader(name).load(path)


def sensor_grid_tracker(sensor: str, sensor_file: str, **grid_options: Any) -> GridTracker:
    """The grid tracker with the saved sensor ``sensor_file`` (of kind ``sensor``) as
    its heading sensor; ``grid_options`` go to :class:`~vc_gym.localization.GridTracker`."""
    return GridTracker(heading_sensor=load_sensor(sensor, sensor_file), **grid_options)
