"""Colour-class changes along the horizon band of a frame, kept at their columns: bearings.

The compass of the paper counts the colour-class transitions of a frame per 4.5° sector
(section 3.4, eq. 11-12) and so forgets where in the sector each one was. A pixel of the
208-pixel head camera spans 0.27°; an edge between two coloured surfaces (a door frame,
a poster's side, a wall corner) sits at one column. This module keeps those columns.

In a band of rows just above the horizon every column gets the colour class most of its
band pixels have; runs of one class at least ``min_run_px`` wide are *solid*, and every
change from one solid run to the next (across at most ``max_gap_px`` columns of other
classes) is an event: the pair of classes ``(left, right)`` in the image and the column
of the change, found to a fraction of a pixel from the share of band rows that still
show the left class in the columns around it (a slanted or blurred edge gives a
fractional column). With the camera model, the column is a bearing relative to the
camera's yaw: :class:`FrameBearings`.

One band sees the few edges that cross it. :func:`bands_bearings` reads several bands
stacked up the wall (:data:`DEFAULT_BANDS_DEG`: from the skirting to a poster's top)
and keeps each change with its band: an edge seen in one band is a landmark of that band,
so a poster's side and the door frame below it are told apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vc_gym.compass.camera import Camera
from vc_gym.compass.colors import ColorClasses
from vc_gym.exposure import gain_table
from vc_gym.images import check_image
from vc_gym.validation import int_at_least, positive_float

__all__ = [
    "DEFAULT_BANDS_DEG",
    "DEFAULT_BAND_DEG",
    "MAX_BANDS",
    "SAME_CHANGE_DEG",
    "FrameBearings",
    "bands_bearings",
    "check_band",
    "check_bands",
    "frame_bearings",
]

#: Elevations (degrees above the horizon) of the band whose columns are read: the walls
#: just above eye height, where a wall of 0.5 m or more fills every column to 3 m away.
DEFAULT_BAND_DEG = (0.5, 4.0)
#: The bands :func:`bands_bearings` reads unless told: up the wall to 30° above the
#: horizon, where the posters and door frames are. In the simulated robolab they give
#: about 24 changes a frame against 5 for the lowest band alone.
DEFAULT_BANDS_DEG = ((0.5, 4.0), (4.0, 10.0), (10.0, 20.0), (20.0, 30.0))
#: Most bands a frame is read in (a landmark map file names its bands).
MAX_BANDS = 16
#: How far apart two readings' changes of one pair may lie and be the same change
#: (degrees: two pixels of the head camera).
SAME_CHANGE_DEG = 0.55


@dataclass(frozen=True)
class FrameBearings:
    """The colour-class changes of one frame along its horizon band.

    Attributes
    ----------
    offsets_deg : numpy.ndarray
        ``(K,)`` direction of each change relative to the camera's yaw, degrees, left
        positive (:meth:`Camera.column_offsets_deg`).
    left, right : numpy.ndarray
        ``(K,)`` colour classes on the image's left and right of the change.
    n_colors : int
        Number of colour classes.
    hfov_deg : float
        The camera's horizontal field of view (what a frame could see).
    band : numpy.ndarray
        ``(K,)`` index into ``bands`` of the band each change was seen in (default: 0).
    bands : tuple of (float, float)
        The bands read, elevations in degrees (default: :data:`DEFAULT_BAND_DEG` alone).
    """

    offsets_deg: np.ndarray
    left: np.ndarray
    right: np.ndarray
    n_colors: int
    hfov_deg: float
    band: np.ndarray | None = None
    bands: tuple[tuple[float, float], ...] = (DEFAULT_BAND_DEG,)

    def __post_init__(self) -> None:
        if self.band is None:
            object.__setattr__(self, "band", np.zeros(self.offsets_deg.shape, np.int64))

    def __len__(self) -> int:
        return int(self.offsets_deg.size)

    @property
    def pairs(self) -> np.ndarray:
        """``(K,)`` integer code of each change's band and ``(left, right)`` class pair:
        ``(band * n_colors + left) * n_colors + right``."""
        n = self.n_colors
        b = self.band.astype(np.int64)
        return (b * n + self.left.astype(np.int64)) * n + self.right.astype(np.int64)


def check_band(band_deg: object) -> tuple[float, float]:
    """``band_deg`` as two floats ``lo < hi`` in ``(-80, 80)`` degrees, else a ``ValueError``."""
    try:
        lo, hi = (float(v) for v in band_deg)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise ValueError(f"band_deg must be two elevations (degrees), got {band_deg!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and -80.0 < lo < hi < 80.0):
        raise ValueError(f"band_deg must be two elevations lo < hi in (-80, 80), got {band_deg}")
    return lo, hi


def check_bands(bands_deg: object) -> tuple[tuple[float, float], ...]:
    """``bands_deg`` as 1 to :data:`MAX_BANDS` bands (each :func:`check_band`)."""
    try:
        bands = tuple(check_band(b) for b in bands_deg)  # type: ignore[union-attr]
    except TypeError:
        raise ValueError(f"bands_deg must be a sequence of bands, got {bands_deg!r}") from None
    if not 1 <= len(bands) <= MAX_BANDS:
        raise ValueError(f"bands_deg must hold 1 to {MAX_BANDS} bands, got {len(bands)}")
    return bands


def bands_bearings(
    image: np.ndarray,
    camera: Camera,
    colors: ColorClasses,
    bands_deg: tuple[tuple[float, float], ...] = DEFAULT_BANDS_DEG,
    min_run_px: int = 3,
    max_gap_px: int = 3,
    gain: float = 1.0,
    dimmed_stops: tuple[float, ...] = (),
) -> FrameBearings:
    """The changes of :func:`frame_bearings` in every band of ``bands_deg``, each kept
    with its band (:attr:`FrameBearings.band`), the frame's linear light times ``gain``.

    For each ``s`` of ``dimmed_stops`` the frame is also read as a room ``s`` stops
    darker would show it, read back at the gain ``2**s`` (its 8-bit levels rounded as
    the darker frame's are), and a change only that reading shows (no change of the same
    band and pair within :data:`SAME_CHANGE_DEG` in the readings before) is added. The
    class of a surface whose colour lies on the border of two classes flips with a level
    of rounding: its edges then show another pair at the same bearing. Landmarks learned
    from such readings hold the edge under both pairs, so that a frame of the dimmer
    room read at its gain finds it.

    Raises
    ------
    ValueError
        On a bad image or band, more than :data:`MAX_BANDS` bands, or a dimming that is
        not a finite number of stops > 0.
    """
    bands = check_bands(bands_deg)
    dimmed = [positive_float("dimmed_stops", v) for v in dimmed_stops]
    found = _read_bands(image, camera, colors, bands, min_run_px, max_gap_px, gain)
    for stops in dimmed:
        darker = np.take(gain_table(2.0**-stops), image)  # checked by the reading above
        other = _read_bands(
            darker, camera, colors, bands, min_run_px, max_gap_px, gain * 2.0**stops
        )
        found = _joined(found, other)
    return found


def _read_bands(
    image: np.ndarray,
    camera: Camera,
    colors: ColorClasses,
    bands: tuple[tuple[float, float], ...],
    min_run_px: int,
    max_gap_px: int,
    gain: float,
) -> FrameBearings:
    """:func:`frame_bearings` in every band (checked), the changes kept with their band."""
    found = [
        frame_bearings(image, camera, colors, band, min_run_px, max_gap_px, gain) for band in bands
    ]
    return FrameBearings(
        np.concatenate([f.offsets_deg for f in found]),
        np.concatenate([f.left for f in found]),
        np.concatenate([f.right for f in found]),
        colors.n_colors,
        float(camera.hfov_deg),
        np.concatenate([np.full(len(f), b, np.int64) for b, f in enumerate(found)]),
        bands,
    )


def _joined(changes: FrameBearings, other: FrameBearings) -> FrameBearings:
    """``changes`` and the changes of ``other`` it lacks (no change of the same band and
    class pair within :data:`SAME_CHANGE_DEG`)."""
    same = other.pairs[:, None] == changes.pairs[None, :]
    near = np.abs(other.offsets_deg[:, None] - changes.offsets_deg[None, :]) <= SAME_CHANGE_DEG
    new = ~np.any(same & near, axis=1)
    return FrameBearings(
        np.concatenate([changes.offsets_deg, other.offsets_deg[new]]),
        np.concatenate([changes.left, other.left[new]]),
        np.concatenate([changes.right, other.right[new]]),
        changes.n_colors,
        changes.hfov_deg,
        np.concatenate([changes.band, other.band[new]]),
        changes.bands,
    )


def _band_rows(camera: Camera, width: int, height: int, band_deg: tuple[float, float]) -> slice:
    """The image rows of ``band_deg`` (checked by the caller)."""
    lo, hi = band_deg
    f = camera.focal_px(width)
    horizon = camera.horizon_row(width, height)
    top = horizon - f * math.tan(math.radians(hi))
    bottom = horizon - f * math.tan(math.radians(lo))
    r0, r1 = max(0, math.ceil(top)), min(height, math.floor(bottom) + 1)
    return slice(r0, max(r0, r1))


def frame_bearings(
    image: np.ndarray,
    camera: Camera,
    colors: ColorClasses,
    band_deg: tuple[float, float] = DEFAULT_BAND_DEG,
    min_run_px: int = 3,
    max_gap_px: int = 3,
    gain: float = 1.0,
) -> FrameBearings:
    """The colour-class changes of ``image`` along its horizon band, as bearings.

    Parameters
    ----------
    image : numpy.ndarray
        ``(H, W, 3)`` uint8 RGB frame.
    camera : Camera
        The camera that took it (field of view, pitch, principal point); its yaw is not
        used: the offsets are relative to it.
    colors : ColorClasses
        The colour classes of the map (eq. 7's ``g``).
    band_deg : tuple of float
        Elevations above the horizon, degrees, of the band's lower and upper edge
        (clipped to the image).
    min_run_px : int
        Narrowest run of one class that counts as a surface.
    max_gap_px : int
        Widest stretch of other classes between two surfaces whose change is still
        one event (a blurred or anti-aliased edge); wider, no event.
    gain : float
        Multiplies the frame's linear light before the pixels are classified (e.g. the
        session's light, :class:`~vc_gym.exposure.SessionLight`, so that a dimmer room
        shows the classes it was learned in).

    Returns
    -------
    FrameBearings
        Empty when the band lies outside the image.
    """
    img = check_image(image, "image")
    int_at_least("min_run_px", min_run_px, 1)
    int_at_least("max_gap_px", max_gap_px, 0)
    gain = positive_float("gain", gain)
    height, width = img.shape[:2]
    n = colors.n_colors
    band = (check_band(band_deg),)
    rows = _band_rows(camera, width, height, band[0])
    empty = np.zeros(0, np.int64)
    if rows.stop - rows.start < 1:
        return FrameBearings(np.zeros(0), empty, empty, n, camera.hfov_deg, bands=band)
    pixels = img[rows] if gain == 1.0 else np.take(gain_table(gain), img[rows])
    classes = colors.classify(pixels).astype(np.int64)  # (R, W)
    # how many band rows show each class, per column
    counts = np.bincount((classes * width + np.arange(width)).ravel(), minlength=n * width)
    share = counts.reshape(n, width) / classes.shape[0]
    column_class = np.argmax(share, axis=0)
    # runs of one class: [start, end) column ranges
    cut = np.flatnonzero(column_class[1:] != column_class[:-1]) + 1
    starts = np.concatenate(([0], cut))
    ends = np.concatenate((cut, [width]))
    solid = np.flatnonzero(ends - starts >= min_run_px)
    positions, lefts, rights = [], [], []
    for a, b in zip(solid[:-1], solid[1:], strict=True):
        left, right = column_class[starts[a]], column_class[starts[b]]
        gap = starts[b] - ends[a]
        if left == right or gap > max_gap_px:
            continue
        # from the last column of the left surface to the first of the right one: the
        # share of band rows still showing the left class, of those showing either
        u = np.arange(ends[a] - 1, starts[b] + 1)
        both = share[left, u] + share[right, u]
        p_left = np.where(both > 0, share[left, u] / np.maximum(both, 1e-12), 0.5)
        edge = u[0] + float(np.sum(p_left))  # in pixel-edge coordinates
        positions.append(edge - 0.5)  # pixel centres lie at integer columns
        lefts.append(left)
        rights.append(right)
    offsets = camera.column_offsets_deg(np.asarray(positions, np.float64), width, height)
    return FrameBearings(
        np.asarray(offsets, np.float64).reshape(-1),
        np.asarray(lefts, np.int64),
        np.asarray(rights, np.int64),
        n,
        float(camera.hfov_deg),
        bands=band,
    )
