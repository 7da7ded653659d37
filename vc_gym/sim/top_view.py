"""A top view of a scene with the robot, its heading and its camera's field of view."""

from __future__ import annotations

import math

import cv2
import numpy as np

from vc_gym.sim.head_camera import HeadCameraSpec, render_camera

__all__ = ["TopView"]

_HEIGHT_M = 40.0  # camera height: far enough that the view is nearly orthographic
_MARGIN_M = 0.3


class TopView:
    """Renders the scene from above once, then draws the robot on a copy per call.

    Parameters
    ----------
    bc : BulletClient
        The scene's client.
    scene : Scene
        The scene (its ``room_bounds`` set the view; bodies in ``scene.ceiling_ids``,
        if any, are hidden while the background is rendered).
    light_direction : tuple of float, optional
        The scene light.
    size_px : int
        Height and width of the view.
    """

    def __init__(self, bc, scene, light_direction=None, size_px: int = 360):
        x0, x1, y0, y1 = scene.room_bounds
        self.center = ((x0 + x1) / 2.0, (y0 + y1) / 2.0)
        half = max(x1 - x0, y1 - y0) / 2.0 + _MARGIN_M
        self.size = int(size_px)
        hfov = 2.0 * math.degrees(math.atan(half / _HEIGHT_M))
        spec = HeadCameraSpec(self.size, self.size, hfov)
        self.focal = (self.size / 2.0) / (half / _HEIGHT_M)
        hidden = tuple(getattr(scene, "ceiling_ids", ()))
        colors = {}
        for body in hidden:
            colors[body] = [d[7] for d in bc.getVisualShapeData(body)]
            for d in bc.getVisualShapeData(body):
                bc.changeVisualShape(body, d[1], rgbaColor=[*d[7][:3], 0.0])
        try:
            eye = (self.center[0], self.center[1], _HEIGHT_M)
            # looking straight down with +y up in the image and +x to the right
            self.background = render_camera(
                bc, spec, eye, 90.0, -89.999, light_direction=light_direction
            )
        finally:
            for body, rgba in colors.items():
                for d, c in zip(bc.getVisualShapeData(body), rgba, strict=True):
                    bc.changeVisualShape(body, d[1], rgbaColor=list(c))
        self.field_bounds = scene.field_bounds

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """``(xmin, xmax, ymin, ymax)`` of the floor the view shows, world metres (for
        matplotlib's ``imshow(view.background, extent=view.extent)``)."""
        half = (self.size / 2.0) / self.focal * _HEIGHT_M
        cx, cy = self.center
        return (cx - half, cx + half, cy - half, cy + half)

    def to_px(self, x: float, y: float, z: float = 0.0) -> tuple[int, int]:
        """Pixel of the world point ``(x, y, z)``."""
        d = _HEIGHT_M - z
        c = (self.size - 1) / 2.0
        return (
            int(round(c + self.focal * (x - self.center[0]) / d)),
            int(round(c - self.focal * (y - self.center[1]) / d)),
        )

    def draw(
        self,
        x: float,
        y: float,
        yaw_deg: float,
        camera_yaw_deg: float,
        hfov_deg: float,
        trail: np.ndarray | None = None,
    ) -> np.ndarray:
        """The background with the robot at ``(x, y, yaw)`` and its camera's view wedge."""
        img = self.background.copy()
        fx0, fx1, fy0, fy1 = self.field_bounds
        cv2.rectangle(img, self.to_px(fx0, fy0), self.to_px(fx1, fy1), (255, 255, 0), 1)
        if trail is not None and len(trail) > 1:
            pts = np.array([self.to_px(px, py) for px, py in trail], np.int32)
            cv2.polylines(img, [pts], False, (255, 128, 0), 1, cv2.LINE_AA)
        # field of view: two rays of 2 m from the robot
        for side in (-0.5, 0.5):
            a = math.radians(camera_yaw_deg + side * hfov_deg)
            end = self.to_px(x + 2.0 * math.cos(a), y + 2.0 * math.sin(a))
            cv2.line(img, self.to_px(x, y), end, (255, 255, 255), 1, cv2.LINE_AA)
        # body: a 0.45 x 0.3 m rectangle, heading arrow
        c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
        corners = [(0.225, 0.15), (0.225, -0.15), (-0.225, -0.15), (-0.225, 0.15)]
        pts = np.array(
            [self.to_px(x + c * u - s * v, y + s * u + c * v) for u, v in corners], np.int32
        )
        cv2.fillPoly(img, [pts], (220, 40, 40))
        tip = self.to_px(x + 0.5 * c, y + 0.5 * s)
        cv2.arrowedLine(img, self.to_px(x, y), tip, (255, 255, 255), 2, cv2.LINE_AA, tipLength=0.3)
        return img
