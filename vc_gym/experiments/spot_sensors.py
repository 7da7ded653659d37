"""Image sensors taught a learning turn at a spot: what the sensor experiment and the
homing experiment's ``--sensor`` share."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import Any

import numpy as np

from vc_gym.compass import Camera, VisualCompass
from vc_gym.deprecation import moved_names
from vc_gym.experiments.views import learning_turn
from vc_gym.heading_sensors import make_sensor
from vc_gym.jobs.workers import worker_cache
from vc_gym.sim.aibo_room import AiboRoomEnv

__all__ = ["fit_colors", "room", "spot_sensor_job", "teach"]


def fit_colors(sensor: Any, frames: Sequence[tuple[np.ndarray, Camera]]) -> None:
    """A visual compass first fits its colour classes on one frame per learning
    direction (as the robot does); other sensors need nothing."""
    if isinstance(sensor, VisualCompass) and sensor.colors is None:
        sensor.fit_colors([img for img, _ in frames[:: max(1, len(frames) // 8)]])


# deprecated: fit_colours, the British spelling of fit_colors, served for one release
__getattr__ = moved_names(__name__, {"fit_colours": (sys.modules[__name__], "fit_colors")})


def teach(sensor: Any, frames: Sequence[tuple[np.ndarray, Camera]]) -> None:
    """Teach ``sensor`` the ``(image, camera)`` frames (colour classes first, if it has
    any)."""
    fit_colors(sensor, frames)
    for image, camera in frames:
        sensor.learn(image, camera)


def room(scene: str, light: float) -> AiboRoomEnv:
    """The room of ``scene`` at ``light``, kept by the worker (:func:`worker_cache`)."""
    return worker_cache(
        ("room", scene, float(light)), lambda: AiboRoomEnv(scene=scene, illumination=light)
    )


def spot_sensor_job(
    scene: str, sensor: Any, spot: list[float], learn_frames: int, seed: int, path: str
) -> dict[str, Any]:
    """Job: teach a fresh ``sensor`` (a spec) a learning turn at ``spot`` of ``scene``
    (:func:`~vc_gym.experiments.views.learning_turn`) and save it to ``path``."""
    built = make_sensor(sensor)
    teach(built, learning_turn(room(scene, 1.0), spot, learn_frames, seed))
    return {"path": str(built.save(path))}
