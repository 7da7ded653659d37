"""Pinhole camera model of the compass: which direction each image column looks at.

Conventions (docs/design.md): yaw in degrees, counter-clockwise positive seen from above;
``yaw`` is the direction of the optical axis, which is the centre column unless a
principal point is given. A column right of the principal point looks at a *smaller*
yaw: ``direction(u) = yaw - degrees(atan((u - cx) / f))`` with
``f = (W / 2) / tan(hfov / 2)``. Positive pitch looks up, which moves the horizon down
in the image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vc_gym.validation import finite_real as _finite

__all__ = [
    "Camera",
    "AIBO_HFOV_DEG",
    "AIBO_RESOLUTION",
    "MAX_ABS_YAW_DEG",
    "MAX_HFOV_DEG",
    "MIN_HFOV_DEG",
    "check_hfov",
]

#: Horizontal field of view of the Sony Aibo ERS-7 camera (degrees).
AIBO_HFOV_DEG = 56.9
#: Largest ``|yaw_deg|`` a camera takes: beyond it float64 holds the angle to worse than
#: a millionth of a degree, and further out the sectors would come out wrong.
MAX_ABS_YAW_DEG = 1e9
#: (width, height) of the Aibo ERS-7 camera image.
AIBO_RESOLUTION = (208, 160)
#: Narrowest horizontal field of view a camera may have (degrees): a long telephoto
#: lens sees about 2 degrees; below a degree a frame spans a fraction of one sector.
MIN_HFOV_DEG = 1.0
#: Widest horizontal field of view a pinhole camera may have (degrees): towards 180 the
#: focal length goes to zero and the edge columns' directions lose all precision.
MAX_HFOV_DEG = 179.0


def check_hfov(name: str, value: object) -> float:
    """``value`` as a field of view in degrees within ``[MIN_HFOV_DEG, MAX_HFOV_DEG]``,
    else a ``ValueError`` naming ``name`` and the range."""
    hfov = _finite(name, value)
    if not MIN_HFOV_DEG <= hfov <= MAX_HFOV_DEG:
        raise ValueError(
            f"{name} must be in [{MIN_HFOV_DEG:g}, {MAX_HFOV_DEG:g}] degrees, got {value!r}"
        )
    return hfov


@dataclass(frozen=True)
class Camera:
    """Intrinsics and orientation of the camera that took an image.

    Parameters
    ----------
    hfov_deg : float
        Horizontal field of view in degrees, in ``[MIN_HFOV_DEG, MAX_HFOV_DEG]``
        (1 to 179). Together with the
        image width it gives the focal length ``f = (W/2) / tan(hfov/2)`` (pixels;
        square pixels assumed).
    yaw_deg : float
        Direction of the optical axis in the world frame (degrees, CCW positive).
        Ignored by :meth:`VisualCompass.log_likelihood`, which tries every heading.
    pitch_deg : float
        Elevation of the optical axis, positive up, ``|pitch| < 90``.
    principal_point : tuple of float or None
        ``(cx, cy)`` in pixels; ``None`` means the image centre
        ``((W - 1) / 2, (H - 1) / 2)``. Use it for crops of a larger image: a crop
        keeps the focal length and shifts the principal point.
    """

    hfov_deg: float = AIBO_HFOV_DEG
    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    principal_point: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        check_hfov("hfov_deg", self.hfov_deg)
        if abs(_finite("yaw_deg", self.yaw_deg)) > MAX_ABS_YAW_DEG:
            # far out, float64 cannot hold a fraction of a degree: sectors would be wrong
            raise ValueError(f"|yaw_deg| must be <= {MAX_ABS_YAW_DEG:g}, got {self.yaw_deg!r}")
        pitch = _finite("pitch_deg", self.pitch_deg)
        if not -90.0 < pitch < 90.0:
            raise ValueError(f"pitch_deg must be in (-90, 90), got {pitch}")
        if self.principal_point is not None:
            pp = tuple(self.principal_point)
            if len(pp) != 2:
                raise ValueError(f"principal_point must be (cx, cy), got {self.principal_point!r}")
            object.__setattr__(
                self, "principal_point", (_finite("cx", pp[0]), _finite("cy", pp[1]))
            )

    @classmethod
    def from_focal(
        cls,
        focal_px: float,
        width: int,
        yaw_deg: float = 0.0,
        pitch_deg: float = 0.0,
        principal_point: tuple[float, float] | None = None,
    ) -> Camera:
        """Build a camera from a focal length in pixels and the image width."""
        return cls(cls.hfov_of_focal(focal_px, width), yaw_deg, pitch_deg, principal_point)

    @staticmethod
    def hfov_of_focal(focal_px: float, width: int) -> float:
        """The horizontal field of view (degrees) of a focal length in pixels for an image
        ``width`` pixels wide: ``2 atan(W / 2f)`` (not checked against the lens range)."""
        f = _finite("focal_px", focal_px)
        if f <= 0 or int(width) < 1:
            raise ValueError(f"focal_px and width must be positive, got {focal_px}, {width}")
        return 2.0 * math.degrees(math.atan((int(width) / 2.0) / f))

    def replace(self, **changes: object) -> Camera:
        """Return a copy with some fields changed (e.g. ``cam.replace(yaw_deg=90)``)."""
        from dataclasses import replace

        return replace(self, **changes)

    def focal_px(self, width: int) -> float:
        """Focal length in pixels for an image ``width`` pixels wide."""
        return (width / 2.0) / math.tan(math.radians(self.hfov_deg) / 2.0)

    def center(self, width: int, height: int) -> tuple[float, float]:
        """Principal point ``(cx, cy)`` for an image of the given size."""
        if self.principal_point is not None:
            return self.principal_point
        return (width - 1) / 2.0, (height - 1) / 2.0

    def horizon_row(self, width: int, height: int) -> float:
        """Image row (may be fractional or outside the image) where the horizon lies.

        Rows with smaller index are above the horizon. For a camera without roll the
        horizon is a horizontal line at ``cy + f tan(pitch)``.
        """
        _, cy = self.center(width, height)
        return cy + self.focal_px(width) * math.tan(math.radians(self.pitch_deg))

    def column_offsets_deg(
        self, columns: np.ndarray, width: int, height: int, row: float | None = None
    ) -> np.ndarray:
        """Direction of each column relative to the yaw, in degrees (left positive).

        Parameters
        ----------
        columns : numpy.ndarray
            Pixel columns ``u`` (may be fractional).
        width, height : int
            Image size.
        row : float, optional
            Row at which to evaluate the direction. With zero pitch every row of a
            column looks in the same direction; with pitch, rays above the horizon
            spread wider. Default: the horizon row.
        """
        cx, cy = self.center(width, height)
        f = self.focal_px(width)
        x = (np.asarray(columns, dtype=float) - cx) / f
        theta = math.radians(self.pitch_deg)
        # upward component of the ray in the camera frame; at the horizon it is -tan(pitch)
        y_up = -math.tan(theta) if row is None else (cy - row) / f
        forward = math.cos(theta) - math.sin(theta) * y_up
        return -np.degrees(np.arctan2(x, forward))

    def column_directions_deg(self, columns: np.ndarray, width: int, height: int) -> np.ndarray:
        """World direction (degrees, unwrapped) each column looks at, at the horizon."""
        return self.yaw_deg + self.column_offsets_deg(columns, width, height)
