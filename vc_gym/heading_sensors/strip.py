"""Camera images resampled onto a grid of world directions (azimuth × elevation).

Several baselines compare what a camera sees in each *direction*, not at each pixel:
the rotational image difference compares panoramic strips, the sector colours average
over azimuth sectors. :func:`angular_strip` resamples a pinhole image (any size, focal
length, principal point or pitch, docs/design.md's camera conventions) onto azimuth offsets
``j * az_step`` from the camera's yaw (left positive, as :class:`~vc_gym.compass.Camera`)
and elevations ``e0, e0 + el_step, ...``. Directions the camera did not see are masked.
The image is first shrunk by area averaging to about one pixel per grid step, so the
bilinear lookup does not alias.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from vc_gym.angles import steps_in_circle
from vc_gym.compass import Camera
from vc_gym.validation import finite_float, positive_float

__all__ = ["MAX_ROWS", "MIN_AZ_STEP_DEG", "StripGrid", "angular_strip", "strip_offsets"]

#: Most elevation rows and finest azimuth step of a grid: a config, perhaps read from a
#: file, cannot make a strip or a panorama allocate more than 1000 x 36,000 samples.
MAX_ROWS = 1000
MIN_AZ_STEP_DEG = 0.01


@dataclass(frozen=True)
class StripGrid:
    """Grid of directions a strip samples.

    Parameters
    ----------
    az_step_deg : float
        Azimuth step (degrees); must divide 360.
    el_min_deg, el_max_deg : float
        Elevation band (degrees, positive up), ``-90 < min < max < 90``.
    el_step_deg : float
        Elevation step (degrees).
    """

    az_step_deg: float = 1.0
    el_min_deg: float = -20.0
    el_max_deg: float = 20.0
    el_step_deg: float = 2.0

    def __post_init__(self) -> None:
        az = positive_float("az_step_deg", self.az_step_deg)
        if az < MIN_AZ_STEP_DEG:
            raise ValueError(f"az_step_deg must be >= {MIN_AZ_STEP_DEG}, got {az}")
        if az > 45.0 or steps_in_circle(az) is None:
            raise ValueError(f"az_step_deg must divide 360 (and be <= 45), got {az}")
        lo = finite_float("el_min_deg", self.el_min_deg)
        hi = finite_float("el_max_deg", self.el_max_deg)
        if not -90.0 < lo < hi < 90.0:
            raise ValueError(f"need -90 < el_min_deg < el_max_deg < 90, got {lo}, {hi}")
        step = positive_float("el_step_deg", self.el_step_deg)
        if (hi - lo) / step >= MAX_ROWS:
            raise ValueError(
                f"el_step_deg={step} gives more than {MAX_ROWS} elevation rows in [{lo}, {hi}]"
            )

    @property
    def n_azimuths(self) -> int:
        """Azimuth bins over the full circle."""
        return int(round(360.0 / self.az_step_deg))

    @property
    def elevations_deg(self) -> np.ndarray:
        """The sampled elevations."""
        n = int(math.floor((self.el_max_deg - self.el_min_deg) / self.el_step_deg + 1e-9)) + 1
        return self.el_min_deg + np.arange(n) * self.el_step_deg


def strip_offsets(camera: Camera, width: int, grid: StripGrid) -> np.ndarray:
    """Integer azimuth offsets ``j`` (bins of ``az_step``, left positive) whose
    direction ``yaw + j * az_step`` can fall inside the camera's horizontal view."""
    half = camera.hfov_deg / 2.0
    if camera.principal_point is not None:
        # a crop's optical axis may lie off the image centre: widen to both edges
        f = camera.focal_px(width)
        cx = camera.principal_point[0]
        left = math.degrees(math.atan(cx / f))
        right = math.degrees(math.atan((width - 1 - cx) / f))
        lo, hi = -right, left
    else:
        lo, hi = -half, half
    # a pitched camera sees wider above and below the horizon: allow for it
    spread = 1.0 / max(math.cos(math.radians(abs(camera.pitch_deg) + 45.0)), 0.2)
    lo, hi = lo * spread, hi * spread
    j0 = int(math.floor(lo / grid.az_step_deg))
    j1 = int(math.ceil(hi / grid.az_step_deg))
    return np.arange(max(j0, -grid.n_azimuths // 2), min(j1, grid.n_azimuths // 2) + 1)


def angular_strip(
    image: np.ndarray, camera: Camera, grid: StripGrid, offsets: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Resample ``image`` onto directions ``(elevation, yaw-relative azimuth)``.

    Parameters
    ----------
    image : numpy.ndarray
        ``(H, W, 3)`` uint8 RGB (checked by the caller).
    camera : Camera
        Intrinsics and pitch (its yaw is not used: azimuths are relative to it).
    grid : StripGrid
        The directions.
    offsets : numpy.ndarray, optional
        Azimuth offsets in (possibly fractional) bins, left positive; default
        :func:`strip_offsets`.

    Returns
    -------
    strip : numpy.ndarray
        ``(n_elevations, n_offsets, 3)`` float32 RGB in ``[0, 255]`` (0 where masked).
    valid : numpy.ndarray
        ``(n_elevations, n_offsets)`` bool: the camera saw that direction.
    offsets : numpy.ndarray
        The azimuth offsets used.
    """
    h, w = image.shape[:2]
    if offsets is None:
        offsets = strip_offsets(camera, w, grid)
    offsets = np.asarray(offsets, dtype=np.float64)
    f = camera.focal_px(w)
    cx, cy = camera.center(w, h)
    # shrink to about one pixel per grid step (area averaging), keeping the geometry
    px_per_step = f * math.radians(min(grid.az_step_deg, grid.el_step_deg))
    scale = min(1.0, 1.0 / px_per_step) if px_per_step > 0 else 1.0
    if scale < 0.99:
        sw, sh = max(2, int(round(w * scale))), max(2, int(round(h * scale)))
        src = cv2.resize(image, (sw, sh), interpolation=cv2.INTER_AREA)
        sx, sy = sw / w, sh / h
    else:
        src, sx, sy = image, 1.0, 1.0
    alpha = np.radians(offsets * grid.az_step_deg)[None, :]  # left positive
    eps = np.radians(grid.elevations_deg)[:, None]
    # direction in (forward, left, up) of the yaw frame, then the pitched camera's frame
    fwd, left, up = np.cos(eps) * np.cos(alpha), np.cos(eps) * np.sin(alpha), np.sin(eps)
    p = math.radians(camera.pitch_deg)
    z = fwd * math.cos(p) + up * math.sin(p)
    x = -left
    y = -fwd * math.sin(p) + up * math.cos(p)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = cx + f * x / z
        v = cy - f * y / z
    valid = (z > 1e-6) & (u >= 0) & (u <= w - 1) & (v >= 0) & (v <= h - 1)
    # pixel centres of the shrunk image: (u + 0.5) * s - 0.5
    map_x = np.where(valid, (u + 0.5) * sx - 0.5, -1.0).astype(np.float32)
    map_y = np.where(valid, (v + 0.5) * sy - 0.5, -1.0).astype(np.float32)
    strip = cv2.remap(
        src, map_x, map_y, interpolation=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
    ).astype(np.float32)
    strip[~valid] = 0.0
    return strip, valid, offsets
