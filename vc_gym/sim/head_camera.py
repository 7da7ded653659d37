"""Rendering what a camera at a given eye pose sees, in a PyBullet client.

The projection matches :class:`vc_gym.compass.Camera`: horizontal field of view
``hfov``, square pixels, principal point at the image centre, so a column ``u`` looks at
``yaw - atan((u - cx) / f)`` with ``f = (W/2) / tan(hfov/2)``. PyBullet's projection
takes the *vertical* field of view, ``2 atan(tan(hfov/2) H / W)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from vc_gym.exposure import gain_table

__all__ = ["HeadCameraSpec", "render_camera", "vertical_fov_deg"]

NEAR_M = 0.02
FAR_M = 80.0


def vertical_fov_deg(hfov_deg: float, width: int, height: int) -> float:
    """Vertical field of view of a pinhole camera with square pixels."""
    return math.degrees(2.0 * math.atan(math.tan(math.radians(hfov_deg) / 2.0) * height / width))


@dataclass(frozen=True)
class HeadCameraSpec:
    """Size and field of view of the robot's camera (default: the Sony Aibo ERS-7)."""

    width: int = 208
    height: int = 160
    hfov_deg: float = 56.9

    def __post_init__(self) -> None:
        if int(self.width) < 2 or int(self.height) < 2:
            raise ValueError(f"camera size must be at least 2x2, got {self.width}x{self.height}")
        if not (math.isfinite(self.hfov_deg) and 0 < self.hfov_deg < 180):
            raise ValueError(f"hfov_deg must be in (0, 180), got {self.hfov_deg}")

    def projection(self, bc) -> list[float]:
        """PyBullet projection matrix of this camera."""
        fov_v = vertical_fov_deg(self.hfov_deg, self.width, self.height)
        return bc.computeProjectionMatrixFOV(fov_v, self.width / self.height, NEAR_M, FAR_M)


def render_camera(
    bc,
    spec: HeadCameraSpec,
    eye: tuple[float, float, float],
    yaw_deg: float,
    pitch_deg: float,
    *,
    projection: list[float] | None = None,
    light_direction: tuple[float, float, float] | None = None,
    illumination: float = 1.0,
) -> np.ndarray:
    """Render an RGB image (``(H, W, 3)`` uint8, a fresh array) from ``eye``.

    Parameters
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client to render in (ER_TINY_RENDERER, no shadows).
    spec : HeadCameraSpec
        Image size and horizontal field of view.
    eye : tuple of float
        Camera position (m).
    yaw_deg, pitch_deg : float
        Direction of the optical axis (CCW from +x; positive pitch looks up).
    projection : list of float, optional
        Cached ``spec.projection(bc)``.
    light_direction : tuple of float, optional
        Direction of the scene light.
    illumination : float
        Scales the light in linear units (1 = normal, 0.5 = half the light), applied
        to the rendered image as a camera with fixed exposure would record it.
    """
    y, p = math.radians(yaw_deg), math.radians(pitch_deg)
    fwd = (math.cos(p) * math.cos(y), math.cos(p) * math.sin(y), math.sin(p))
    up = (-math.sin(p) * math.cos(y), -math.sin(p) * math.sin(y), math.cos(p))
    target = (eye[0] + fwd[0], eye[1] + fwd[1], eye[2] + fwd[2])
    view = bc.computeViewMatrix(eye, target, up)
    proj = spec.projection(bc) if projection is None else projection
    kwargs = {}
    if light_direction is not None:
        kwargs["lightDirection"] = list(light_direction)
    _, _, rgba, _, _ = bc.getCameraImage(
        spec.width,
        spec.height,
        view,
        proj,
        renderer=bc.ER_TINY_RENDERER,
        shadow=0,
        flags=bc.ER_NO_SEGMENTATION_MASK,
        **kwargs,
    )
    rgb = np.ascontiguousarray(
        np.asarray(rgba, dtype=np.uint8).reshape(spec.height, spec.width, 4)[:, :, :3]
    )
    if illumination != 1.0:
        rgb = cv2.LUT(rgb, gain_table(illumination))
    return rgb
