"""The axes every top view of the field shares (its outline, limits and equal aspect),
and the rendered room to draw them on."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.patches import Rectangle

__all__ = ["field_axes", "scene_top_view"]


def field_axes(ax: Any, field_bounds: tuple[float, float, float, float]) -> None:
    """Draw the field's outline on ``ax``, with a margin, equal aspect and metre labels."""
    x0, x1, y0, y1 = field_bounds
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="0.3", lw=1.2))
    pad = 0.3
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(y0 - pad, y1 + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def scene_top_view(
    scene: str, size_px: int = 360
) -> tuple[np.ndarray, tuple[float, float, float, float]]:
    """A registered scene rendered from above without the robot, and the floor it shows.

    Returns
    -------
    image : numpy.ndarray
        ``(size_px, size_px, 3)`` uint8 RGB, north up
        (:class:`~vc_gym.sim.top_view.TopView`'s background).
    extent : (xmin, xmax, ymin, ymax)
        For ``ax.imshow(image, extent=extent)``, world metres.
    """
    from vc_gym.sim.aibo_room import AiboRoomEnv
    from vc_gym.sim.top_view import TopView

    room = AiboRoomEnv(scene=scene)
    try:
        room.reset(seed=0)
        room.robot.set_visible(False)
        view = TopView(room.client, room.scene, room.scene.light_direction, size_px=size_px)
        return view.background, view.extent
    finally:
        room.close()
