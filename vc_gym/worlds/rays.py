"""Per-pixel camera rays: the one pinhole model both world renderers cast.

A pixel ``(u, v)`` of a ``W x H`` view has the camera-frame ray ``x = (u - cx) / f``
(right), ``y_up = (cy - v) / f`` (up), forward ``1``, with ``f = (W / 2) / tan(hfov / 2)``
and ``(cx, cy)`` the principal point (:meth:`Camera.center`: the image centre
``((W - 1) / 2, (H - 1) / 2)`` unless given). Pitching the camera up by ``θ`` gives, in
the frame turned by the yaw but not pitched (``forward`` along the yaw, ``left`` 90°
counter-clockwise from it, ``up``)::

    forward = cos θ - sin θ * y_up
    up      = sin θ + cos θ * y_up
    left    = -x

so the ray looks at azimuth ``yaw + atan2(left, forward)`` and elevation
``atan2(up, hypot(forward, left))`` (degrees). At zero pitch this is docs/design.md's
``direction(u) = yaw - degrees(atan((u - cx) / f))``: a column right of the principal
point looks at a *smaller* yaw. :meth:`Camera.column_offsets_deg` is the azimuth part at
one row.

:func:`vc_gym.worlds.render_view` looks the angles up in a panorama;
:func:`vc_gym.worlds.render_room_view` turns ``(forward, left)`` by the yaw and intersects
the rays with the room's walls.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np

from vc_gym.compass.camera import Camera
from vc_gym.validation import int_at_least

__all__ = ["REMAP_MAX_SIDE", "RayGrid", "ray_grid"]

#: Largest side (pixels) of an image ``cv2.remap`` samples from: it refuses
#: ``SHRT_MAX = 32767`` or more. Both renderers sample their texture along the rays with it.
REMAP_MAX_SIDE = 32766


class RayGrid(NamedTuple):
    """The ray of every pixel of a view, relative to the camera's yaw.

    All fields are read-only ``(H, W)`` ``float64`` arrays, shared between calls with the
    same intrinsics, pitch and size. ``forward`` and ``up`` vary only down the rows and
    ``left`` only across the columns, so these three are broadcast views of one row or
    column (index them freely; copy one before handing it to code that needs contiguous
    memory).

    Attributes
    ----------
    forward, left, up : numpy.ndarray
        Components of the (not normalised) ray in the frame turned by the yaw but not
        pitched: ``forward`` along the yaw, ``left`` 90° counter-clockwise of it, ``up``.
        World ``(dx, dy)`` is ``(forward, left)`` rotated by the yaw.
    azimuth_offset_deg : numpy.ndarray
        ``atan2(left, forward)`` in degrees: the ray's azimuth minus the camera's yaw
        (counter-clockwise positive, so negative right of the principal point).
    elevation_deg : numpy.ndarray
        ``atan2(up, hypot(forward, left))`` in degrees, positive up.
    """

    forward: np.ndarray
    left: np.ndarray
    up: np.ndarray
    azimuth_offset_deg: np.ndarray
    elevation_deg: np.ndarray


@functools.lru_cache(maxsize=32)
def _ray_grid(
    focal: float, pitch_deg: float, cx: float, cy: float, width: int, height: int
) -> RayGrid:
    x = (np.arange(width, dtype=float) - cx) / focal  # right
    y_up = (cy - np.arange(height, dtype=float)) / focal  # up
    theta = math.radians(pitch_deg)
    forward = (math.cos(theta) - math.sin(theta) * y_up)[:, None]  # (H, 1)
    up = (math.sin(theta) + math.cos(theta) * y_up)[:, None]  # (H, 1)
    left = -x[None, :]  # (1, W)
    shape = (height, width)
    azimuth_offset = np.degrees(np.arctan2(left, forward))
    elevation = np.broadcast_to(np.degrees(np.arctan2(up, np.hypot(forward, left))), shape)
    # the components vary along one axis only: keep them as (read-only) broadcast views
    grid = RayGrid(
        np.broadcast_to(forward, shape),
        np.broadcast_to(left, shape),
        np.broadcast_to(up, shape),
        azimuth_offset,
        np.ascontiguousarray(elevation),
    )
    for a in grid:
        a.flags.writeable = False
    return grid


def ray_grid(camera: Camera, width: int, height: int) -> RayGrid:
    """The ray of every pixel of a ``width x height`` view taken with ``camera``.

    Uses the camera's field of view, pitch and principal point; its yaw is not applied
    (the rays are relative to it), so views at different yaws share one cached grid.

    Parameters
    ----------
    camera : Camera
        Horizontal field of view, pitch and optional principal point.
    width, height : int
        Size of the view in pixels, ``>= 1``.

    Returns
    -------
    RayGrid
        Read-only ``(height, width)`` arrays ``forward``, ``left``, ``up``,
        ``azimuth_offset_deg`` and ``elevation_deg`` (see :class:`RayGrid`).

    Raises
    ------
    TypeError
        If ``camera`` is not a :class:`~vc_gym.compass.camera.Camera`.
    ValueError
        If a size is not an integer ``>= 1``.

    Examples
    --------
    The right edge of a 90° view looks 45° right of (clockwise from) the yaw:

    >>> rays = ray_grid(Camera(hfov_deg=90.0, principal_point=(99.0, 50.0)), 200, 101)
    >>> round(float(rays.azimuth_offset_deg[50, 199]), 9)  # column 199 is 100 px right
    -45.0
    """
    if not isinstance(camera, Camera):
        raise TypeError(f"camera must be a Camera, got {type(camera).__name__}")
    width = int_at_least("width", width, 1)
    height = int_at_least("height", height, 1)
    cx, cy = camera.center(width, height)
    return _ray_grid(
        float(camera.focal_px(width)),
        float(camera.pitch_deg),
        float(cx),
        float(cy),
        width,
        height,
    )
