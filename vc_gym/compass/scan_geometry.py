"""Which scanned columns fall into which sector, for one camera and image size.

A frame's features are its colour-class transitions grouped by the direction each
scanned column looks at (paper eq. 13-14). Which pixels are scanned and which columns
fall into which sector depends on the camera, the image size and the candidate
heading, never on pixel values, so a compass computes it once per camera and size and
keeps it (:class:`ScanGeometryCache`).

A candidate heading ``φ = s0·Δ + phase`` (``Δ`` the sector width, ``0 <= phase < Δ``)
puts a column at offset ``r`` from the optical axis into sector
``s0 + floor((phase + r) / Δ)``. Headings that share a phase group the columns alike,
so the features are computed per phase and *relative* sector ``k``, and a heading only
says at which map sector ``s0`` relative sector 0 starts.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from vc_gym.compass.camera import Camera
from vc_gym.compass.config import CompassConfig
from vc_gym.compass.features import ScanGrid, scan_grid

__all__ = [
    "GEOMETRY_CACHE_SIZE",
    "ScanGeometry",
    "ScanGeometryCache",
    "column_sectors",
    "scan_geometry",
]

#: Cameras and image sizes a compass keeps the scan geometry of (least recently used
#: dropped first).
GEOMETRY_CACHE_SIZE = 16


@dataclass(frozen=True)
class ScanGeometry:
    """Everything about an image size and camera that does not depend on pixel values.

    Attributes
    ----------
    grid : ScanGrid
        The scanned rows and columns and the direction of each column.
    row_slice, col_slice : slice
        The scanned pixels as slices of the image: ``image[row_slice, col_slice]``.
    first_col, stop_col : numpy.ndarray
        ``(P * K,)`` each: the scanned columns ``first[r] <= u < stop[r]`` fall into
        relative sector ``k`` at phase ``p``, ``r = p * K + k`` (columns look at
        monotonically falling directions, so each is a contiguous run).
    kmin : int
        Relative sector of the leftmost column at the smallest phase (may be negative).
    n_rel : int
        ``K``, relative sectors per phase.
    heading_phase : numpy.ndarray
        ``(n_headings,)`` phase index of each candidate heading.
    heading_sector : numpy.ndarray
        ``(n_headings,)`` map sector ``s0`` of each heading's optical axis.
    roll_index : numpy.ndarray
        ``(K, S)``: map sector ``(s0 + k + kmin) mod S`` of relative sector ``k`` when
        the optical axis is in sector ``s0``.
    """

    grid: ScanGrid
    row_slice: slice
    col_slice: slice
    first_col: np.ndarray
    stop_col: np.ndarray
    kmin: int
    n_rel: int
    heading_phase: np.ndarray
    heading_sector: np.ndarray
    roll_index: np.ndarray


def scan_geometry(
    camera: Camera, width: int, height: int, config: CompassConfig, headings: np.ndarray
) -> ScanGeometry:
    """The scan geometry of ``width`` x ``height`` frames of ``camera`` (eq. 13-14).

    Parameters
    ----------
    camera : Camera
        Intrinsics and pitch (its yaw is not used: every heading is a candidate).
    width, height : int
        Image size in pixels.
    config : CompassConfig
        Gives the scanning grid steps and the sector width.
    headings : numpy.ndarray
        The candidate headings in degrees (:attr:`VisualCompass.headings_deg`).

    Returns
    -------
    ScanGeometry
        The scanned pixels and, for every heading phase, which columns fall into which
        relative sector.

    Raises
    ------
    RuntimeError
        If the scanned columns do not look at falling directions (a camera model
        that breaks the design's convention).
    """
    row_step, col_step = config.grid_steps
    grid = scan_grid(camera, width, height, row_step, col_step)
    if grid.rows.size:
        row_slice = slice(int(grid.rows[0]), int(grid.rows[-1]) + 1, row_step)
    else:
        row_slice = slice(0, 0)
    col_slice = slice(int(grid.cols[0]), width, col_step)
    delta = config.sector_deg
    s_total = config.n_sectors
    # heading = s0 * delta + phase, 0 <= phase < delta; a column at offset r then
    # falls into sector s0 + floor((phase + r) / delta)
    s0 = np.floor(headings / delta + 1e-9).astype(np.int64)
    phase = np.round(headings - s0 * delta, 9)
    phases, heading_phase = np.unique(phase, return_inverse=True)
    k = np.floor((phases[:, None] + grid.offsets_deg[None, :]) / delta).astype(np.int64)
    kmin = int(k.min())
    n_rel = int(k.max()) - kmin + 1
    n_p, n_u = k.shape
    # the columns of one (phase, relative sector) are a contiguous run: their counts
    # are a difference of cumulative sums (a product with a 0/1 matrix instead makes
    # OpenBLAS start a second thread that then spins on a core of its own)
    rows = np.arange(n_p)[:, None] * n_rel + (k - kmin)  # (P, U)
    if np.any(np.diff(k, axis=1) > 0):
        raise RuntimeError("scan columns must look at falling directions")
    first_col = np.zeros(n_p * n_rel, dtype=np.intp)
    stop_col = np.zeros(n_p * n_rel, dtype=np.intp)
    cols = np.broadcast_to(np.arange(n_u), rows.shape)
    np.maximum.at(stop_col, rows.ravel(), cols.ravel() + 1)
    first_col[:] = n_u
    np.minimum.at(first_col, rows.ravel(), cols.ravel())
    empty = stop_col == 0
    first_col[empty] = 0
    roll = (np.arange(s_total)[None, :] + np.arange(n_rel)[:, None] + kmin) % s_total
    return ScanGeometry(
        grid=grid,
        row_slice=row_slice,
        col_slice=col_slice,
        first_col=first_col,
        stop_col=stop_col,
        kmin=kmin,
        n_rel=n_rel,
        heading_phase=heading_phase.astype(np.intp),
        heading_sector=s0 % s_total,
        roll_index=roll,
    )


class ScanGeometryCache:
    """The :func:`scan_geometry` of the last :data:`GEOMETRY_CACHE_SIZE` cameras and
    image sizes a compass saw (a compass usually sees one or two).

    Parameters
    ----------
    config : CompassConfig
        The compass' config.
    headings : numpy.ndarray
        Its candidate headings in degrees.
    """

    def __init__(self, config: CompassConfig, headings: np.ndarray):
        self._config = config
        self._headings = headings
        self._cache: OrderedDict[tuple, ScanGeometry] = OrderedDict()

    def get(self, camera: Camera, width: int, height: int) -> ScanGeometry:
        """The scan geometry of ``width`` x ``height`` frames of ``camera``."""
        key = (width, height, camera.hfov_deg, camera.pitch_deg, camera.principal_point)
        geom = self._cache.get(key)
        if geom is not None:
            self._cache.move_to_end(key)
            return geom
        geom = scan_geometry(camera, width, height, self._config, self._headings)
        self._cache[key] = geom
        if len(self._cache) > GEOMETRY_CACHE_SIZE:
            self._cache.popitem(last=False)
        return geom

    def __len__(self) -> int:
        return len(self._cache)


def column_sectors(
    yaw_deg: float, offsets_deg: np.ndarray, sector_deg: float, n_sectors: int
) -> np.ndarray:
    """Map sector each scanned column looks into when the camera's yaw is known.

    Parameters
    ----------
    yaw_deg : float
        Direction of the optical axis (degrees).
    offsets_deg : numpy.ndarray
        ``(U,)`` direction of each scanned column relative to the yaw
        (:attr:`ScanGrid.offsets_deg`).
    sector_deg : float
        Sector width ``Δφ_sensor``.
    n_sectors : int
        Sectors of the full circle.

    Returns
    -------
    numpy.ndarray
        ``(U,)`` ``int64`` sectors in ``[0, n_sectors)``.
    """
    return np.floor((yaw_deg + offsets_deg) / sector_deg + 1e-9).astype(np.int64) % n_sectors
