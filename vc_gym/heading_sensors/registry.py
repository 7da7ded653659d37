"""Heading sensors chosen by a name, a ``{"type": name, **kwargs}`` dict or a callable.

The names the experiments and the command line use (``--sensor image_difference``):
the visual compass itself (``"visual_compass"``, its
:class:`~vc_gym.compass.CompassConfig` fields as dict keys) and every baseline.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from vc_gym.compass import CompassConfig, ImageCompass, VisualCompass
from vc_gym.deprecation import renamed
from vc_gym.heading_sensors.feature import FeatureCompass
from vc_gym.heading_sensors.image_difference import ImageDifferenceCompass
from vc_gym.heading_sensors.magnetic import NoisyMagneticCompass
from vc_gym.heading_sensors.sector_color import SectorColorCompass
from vc_gym.plugins import make_plugin, register_plugin

__all__ = [
    "DEPRECATED_SENSOR_NAMES",
    "SENSORS",
    "SensorSpec",
    "current_sensor_name",
    "make_sensor",
    "register_sensor",
    "visual_compass",
]


def visual_compass(**config: Any) -> VisualCompass:
    """A fresh :class:`~vc_gym.compass.VisualCompass` with ``CompassConfig(**config)``
    (the paper's values by default)."""
    return VisualCompass(CompassConfig(**config))


#: Sensor factories by name (:func:`register_sensor` adds to it).
SENSORS: dict[str, Callable[..., Any]] = {
    "visual_compass": visual_compass,
    "image_difference": ImageDifferenceCompass,
    "sector_color": SectorColorCompass,
    "feature": FeatureCompass,
    "magnetic": NoisyMagneticCompass,
}

#: Deprecated sensor names and the name each stands for: :func:`make_sensor` and
#: :func:`~vc_gym.heading_sensors.load_sensor` accept them for one release, with a
#: ``DeprecationWarning``.
DEPRECATED_SENSOR_NAMES: dict[str, str] = {"sector_colour": "sector_color"}

SensorSpec = str | Mapping[str, Any] | Callable[[], Any]


def _is_sensor(obj: object) -> bool:
    return isinstance(obj, (ImageCompass, NoisyMagneticCompass)) or (
        hasattr(obj, "heading_log_likelihood") and not isinstance(obj, type)
    )


def current_sensor_name(name: Any, stacklevel: int = 2) -> Any:
    """``name``, or the name a deprecated sensor name stands for (with a
    ``DeprecationWarning`` pointing ``stacklevel`` frames up, as
    :func:`warnings.warn`'s); anything else, or a deprecated name registered again, is
    returned as is."""
    if isinstance(name, str) and name in SENSORS:
        return name
    return renamed("sensor name", name, DEPRECATED_SENSOR_NAMES, stacklevel + 1)


def register_sensor(name: str, factory: Callable[..., Any], overwrite: bool = False) -> None:
    """Make ``factory(**kwargs)`` available as ``make_sensor(name)`` / ``{"type": name}``."""
    register_plugin(SENSORS, "sensor", name, factory, overwrite)


def make_sensor(spec: SensorSpec | Any = "visual_compass") -> Any:
    """Build a heading sensor the HighwayEnv way.

    Parameters
    ----------
    spec : str, dict, callable or sensor
        ``"visual_compass"`` (the paper's compass), ``"image_difference"``,
        ``"sector_color"``, ``"feature"``, ``"magnetic"`` or a name given to
        :func:`register_sensor`; ``"package.module:factory"``; ``{"type": name,
        **kwargs}`` (e.g. ``{"type": "visual_compass", "exposure": "mean"}``); a
        callable with no arguments; or a sensor, returned as is.

    Raises
    ------
    ValueError
        An unknown name (the message lists the known ones), bad arguments, or a
        factory that returns no sensor.
    """
    if isinstance(spec, str):
        spec = current_sensor_name(spec)
    elif isinstance(spec, Mapping) and isinstance(spec.get("type"), str):
        name = current_sensor_name(spec["type"])
        spec = spec if name == spec["type"] else {**spec, "type": name}
    return make_plugin(
        spec,
        SENSORS,
        "sensor",
        _is_sensor,
        "heading log-likelihoods (learn/log_likelihood/estimate or heading_log_likelihood)",
    )
