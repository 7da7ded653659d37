"""Seeded 360° panoramas with known geometry, and pinhole views rendered from them.

The visual compass is tested, demonstrated and benchmarked on camera views whose true
heading is known. This module holds the :class:`Panorama` type and makes such views:
:func:`equirectangular` wraps a real equirectangular photo, and :func:`render_view` cuts
out the image a :class:`~vc_gym.compass.camera.Camera` would
see at a given yaw and pitch. :func:`vc_gym.worlds.panorama_painters.make_panorama`
paints procedural, seamless panoramas (an indoor room or an outdoor scene) from a numpy
random generator.

Conventions
-----------
Angles are in degrees, counter-clockwise positive seen from above (the convention of
:mod:`vc_gym.angles` and :mod:`vc_gym.compass.camera`).

A panorama is an ``(H, W, 3)`` ``uint8`` RGB image covering 360° of azimuth, seen from
inside like a real panorama photo: moving right in the image turns *clockwise*.
Column ``x`` (pixel centre at ``x + 0.5``) looks at azimuth::

    a(x) = azimuth0_deg - 360 * (x + 0.5) / W        (mod 360)

and row ``y`` (centre ``y + 0.5``) looks at elevation (equirectangular rows)::

    e(y) = elev_top_deg - (elev_top_deg - elev_bottom_deg) * (y + 0.5) / H

so ``azimuth0_deg`` is the azimuth of the *left edge* of column 0 (and of the right edge
of column ``W - 1``: the image wraps there).

A camera pixel ``(u, v)`` of a ``w x h`` view has the camera-frame ray
``x = (u - cx) / f`` (right), ``y_up = (cy - v) / f`` (up), forward ``1``, with
``f = (w / 2) / tan(hfov / 2)`` and ``(cx, cy)`` the principal point (default image
centre ``((w - 1) / 2, (h - 1) / 2)``). Pitching the camera up by ``θ`` gives the world
ray ``forward = cos θ - sin θ * y_up``, ``up = sin θ + cos θ * y_up``, ``left = -x``,
which looks at::

    azimuth   = yaw + atan2(left, forward)
    elevation = atan2(up, hypot(forward, left))

These rays come from :func:`vc_gym.worlds.rays.ray_grid`, which the ray-cast room
(:mod:`vc_gym.worlds.room`) shares. (:meth:`Camera.column_offsets_deg` is the azimuth
part of this at a given row.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral

import cv2
import numpy as np

from vc_gym.angles import wrap360
from vc_gym.compass.camera import Camera
from vc_gym.exposure import gain_table
from vc_gym.images import check_image
from vc_gym.validation import finite_float, int_at_least, positive_float
from vc_gym.worlds.rays import REMAP_MAX_SIDE, ray_grid

__all__ = ["Panorama", "equirectangular", "render_view"]

# Rows of replicated border each interpolation needs once the sample rows are clamped to
# [0, H - 1]: linear reads row floor(y) + 1 only with weight 0 at y = H - 1 (so wrapping
# is harmless), cubic reads 1 row before and 2 after, Lanczos 3 before and 4 after.
_VERTICAL_PAD = {
    cv2.INTER_NEAREST: 0,
    cv2.INTER_LINEAR: 0,
    cv2.INTER_CUBIC: 2,
    cv2.INTER_LANCZOS4: 4,
}


# --------------------------------------------------------------------------- Panorama


@dataclass(frozen=True, eq=False)
class Panorama:
    """A 360° panorama image together with the directions its pixels look at.

    Column ``x`` looks at azimuth ``a(x) = azimuth0_deg - 360 (x + 0.5) / W`` (mod 360,
    degrees, CCW positive: moving right in the image turns clockwise, as in a real
    panorama photo seen from inside). Row ``y`` looks at elevation
    ``e(y) = elev_top_deg - (elev_top_deg - elev_bottom_deg) (y + 0.5) / H``.

    Parameters
    ----------
    image : numpy.ndarray
        ``(H, W, 3)`` ``uint8`` RGB image covering 360° of azimuth. It is not copied;
        do not modify it while the panorama is in use.
    elev_top_deg, elev_bottom_deg : float
        Elevation of the top edge of row 0 and of the bottom edge of row ``H - 1``;
        ``-90 <= elev_bottom_deg < elev_top_deg <= 90``.
    azimuth0_deg : float
        Azimuth of the left edge of column 0 (degrees).

    Raises
    ------
    ValueError
        If the image is not an RGB ``uint8`` array or the elevations are invalid.

    Notes
    -----
    Equality and hashing are by identity (the image is a numpy array).
    """

    image: np.ndarray
    elev_top_deg: float = 45.0
    elev_bottom_deg: float = -45.0
    azimuth0_deg: float = 0.0

    def __post_init__(self) -> None:
        check_image(self.image, "panorama image")
        top = finite_float("elev_top_deg", self.elev_top_deg)
        bottom = finite_float("elev_bottom_deg", self.elev_bottom_deg)
        if not (-90.0 <= top <= 90.0 and -90.0 <= bottom <= 90.0):
            raise ValueError(
                f"elev_top_deg and elev_bottom_deg must be in [-90, 90], got {top}, {bottom}"
            )
        if not top > bottom:
            raise ValueError(
                f"elev_top_deg must be greater than elev_bottom_deg, got {top} <= {bottom}"
            )
        object.__setattr__(self, "elev_top_deg", top)
        object.__setattr__(self, "elev_bottom_deg", bottom)
        object.__setattr__(self, "azimuth0_deg", finite_float("azimuth0_deg", self.azimuth0_deg))

    @property
    def width(self) -> int:
        """Number of columns ``W``."""
        return int(self.image.shape[1])

    @property
    def height(self) -> int:
        """Number of rows ``H``."""
        return int(self.image.shape[0])

    def azimuth_of_column(self, x: np.ndarray | float) -> np.ndarray | float:
        """Azimuth in ``[0, 360)`` that column ``x`` (may be fractional) looks at."""
        return wrap360(self.azimuth0_deg - 360.0 * (np.asarray(x, dtype=float) + 0.5) / self.width)

    def column_of_azimuth(self, azimuth_deg: np.ndarray | float) -> np.ndarray | float:
        """Fractional column (pixel-centre coordinates, in ``[0, W)``) of an azimuth.

        Coordinate ``W - 0.5`` is the wrap between column ``W - 1`` and column 0.
        """
        offset = wrap360(self.azimuth0_deg - np.asarray(azimuth_deg, dtype=float))
        out = np.mod(np.asarray(offset) * (self.width / 360.0) - 0.5, self.width)
        return float(out) if np.ndim(out) == 0 else out

    def elevation_of_row(self, y: np.ndarray | float) -> np.ndarray | float:
        """Elevation (degrees) that row ``y`` (may be fractional) looks at."""
        span = self.elev_top_deg - self.elev_bottom_deg
        out = self.elev_top_deg - span * (np.asarray(y, dtype=float) + 0.5) / self.height
        return float(out) if np.ndim(out) == 0 else out

    def row_of_elevation(self, elevation_deg: np.ndarray | float) -> np.ndarray | float:
        """Fractional row (pixel-centre coordinates) of an elevation; not clamped."""
        span = self.elev_top_deg - self.elev_bottom_deg
        e = np.asarray(elevation_deg, dtype=float)
        out = (self.elev_top_deg - e) * (self.height / span) - 0.5
        return float(out) if np.ndim(out) == 0 else out


def equirectangular(image: np.ndarray, azimuth0_deg: float = 0.0) -> Panorama:
    """Wrap a real full-sphere equirectangular photo as a :class:`Panorama`.

    Parameters
    ----------
    image : numpy.ndarray
        ``(H, W, 3)`` ``uint8`` **RGB** image (convert ``cv2.imread`` output with
        ``cv2.cvtColor(img, cv2.COLOR_BGR2RGB)``) whose rows span elevation +90° (top
        edge) to -90° (bottom edge) and whose columns span 360° of azimuth, turning
        clockwise to the right (the usual layout of 360° cameras). Usually ``W = 2H``.
    azimuth0_deg : float
        Azimuth of the left edge of column 0. If the centre column of the photo should
        be azimuth ``A``, pass ``A + 180``.

    Returns
    -------
    Panorama
        ``Panorama(image, elev_top_deg=90, elev_bottom_deg=-90, azimuth0_deg=...)``;
        the image is not copied.
    """
    return Panorama(image, elev_top_deg=90.0, elev_bottom_deg=-90.0, azimuth0_deg=azimuth0_deg)


# ------------------------------------------------------------------------ render_view


def render_view(
    pano: Panorama,
    camera: Camera,
    width: int = 208,
    height: int = 160,
    *,
    illumination: float = 1.0,
    interpolation: int = cv2.INTER_LINEAR,
) -> np.ndarray:
    """Render the pinhole view ``camera`` sees inside panorama ``pano``.

    Every output pixel ``(u, v)`` gets the camera ray of the module conventions
    (``x = (u - cx) / f`` right, ``y_up = (cy - v) / f`` up, pitched by
    ``camera.pitch_deg``), whose azimuth ``camera.yaw_deg + atan2(left, forward)`` and
    elevation ``atan2(up, hypot(forward, left))`` are looked up in the panorama at
    column ``(azimuth0 - azimuth) W / 360 - 0.5`` (wrapping around 360°) and row
    ``(elev_top - elevation) H / (elev_top - elev_bottom) - 0.5``. Rays above or below
    the panorama's elevation band get its top or bottom row (edge replication).

    Parameters
    ----------
    pano : Panorama
        The scene.
    camera : Camera
        Horizontal field of view, yaw (optical axis direction, degrees CCW), pitch
        (positive up) and optional principal point.
    width, height : int
        Size of the rendered image, ``>= 2``. The Aibo camera is 208 x 160.
    illumination : float
        Scale of the linear-light intensity, ``> 0``: the rendered sRGB values are
        converted to linear light, multiplied, converted back and clipped (0.5 = half
        the light; values above 1 saturate). Applied after sampling.
    interpolation : int
        ``cv2.INTER_NEAREST``, ``cv2.INTER_LINEAR`` (default), ``cv2.INTER_CUBIC`` or
        ``cv2.INTER_LANCZOS4``. No anti-aliasing filter is applied: when the panorama
        has much finer angular resolution than the view, fine texture aliases, as in a
        real camera without optical low-pass.

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB image.

    Raises
    ------
    ValueError
        On a size below 2, a non-finite or non-positive illumination, an unsupported
        interpolation, or a panorama side of 32767 pixels or more (a ``cv2.remap``
        limit; downscale the panorama first).
    TypeError
        If ``pano`` is not a :class:`Panorama` or ``camera`` not a ``Camera``.
    """
    if not isinstance(pano, Panorama):
        raise TypeError(f"pano must be a Panorama, got {type(pano).__name__}")
    if not isinstance(camera, Camera):
        raise TypeError(f"camera must be a Camera, got {type(camera).__name__}")
    width = int_at_least("width", width, 2)
    height = int_at_least("height", height, 2)
    illum = positive_float("illumination", illumination)
    if (
        isinstance(interpolation, bool)
        or not isinstance(interpolation, Integral)
        or interpolation not in _VERTICAL_PAD
    ):
        raise ValueError(
            "interpolation must be cv2.INTER_NEAREST, INTER_LINEAR, INTER_CUBIC or "
            f"INTER_LANCZOS4, got {interpolation!r}"
        )
    pw, ph = pano.width, pano.height
    interpolation = int(interpolation)
    pad = _VERTICAL_PAD[interpolation]
    if pw > REMAP_MAX_SIDE or ph + 2 * pad > REMAP_MAX_SIDE:
        raise ValueError(
            f"panorama of {pw}x{ph} pixels is too large for cv2.remap (sides must be < 32767)"
            "; downscale it first"
        )

    rays = ray_grid(camera, width, height)
    az_offset, elevation = rays.azimuth_offset_deg, rays.elevation_deg
    # column = (azimuth0 - yaw - offset) W / 360 - 0.5, wrapped into [0, W)
    shift = math.fmod(pano.azimuth0_deg - float(camera.yaw_deg), 360.0)
    scale = pw / 360.0
    map_x = np.mod((shift - az_offset) * scale - 0.5, pw).astype(np.float32)
    span = pano.elev_top_deg - pano.elev_bottom_deg
    map_y = (pano.elev_top_deg - elevation) * (ph / span) - 0.5
    np.clip(map_y, 0.0, ph - 1.0, out=map_y)  # vertical clamp = edge replication

    src = np.ascontiguousarray(pano.image)
    if pad:
        # the kernel reaches `pad` rows beyond the clamped position: replicate them
        src = cv2.copyMakeBorder(src, pad, pad, 0, 0, cv2.BORDER_REPLICATE)
        map_y += pad
    # BORDER_WRAP wraps both axes; vertically the clamp above keeps every tap inside
    # (linear interpolation at the last row gives the wrapped row a weight of exactly 0)
    out = cv2.remap(
        src,
        map_x,
        map_y.astype(np.float32),
        interpolation,
        borderMode=cv2.BORDER_WRAP,
    )
    if illum != 1.0:
        out = cv2.LUT(out, gain_table(illum))
    return out
