"""Image features of the compass: colour-class transitions and their log-scaled bins.

Paper section 3.4: a transition ``i -> j`` is a change of colour class from ``i``
(below) to ``j`` (above) in vertical direction, counted above the horizon on a
scanning grid (eq. 9-10), grouped by the direction each column looks at (eq. 13-14)
and turned into relative frequencies per sector (eq. 11). Each relative frequency is
then put into one of ``n`` logarithmically scaled bins (eq. 2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vc_gym.compass.camera import Camera

__all__ = [
    "NOISE_CHANGE_RATIO",
    "log2_bin",
    "ScanGrid",
    "scan_grid",
    "column_transition_counts",
    "change_ratio",
]

#: A frame whose vertical class changes are at least this frequent, relative to
#: independent pixels with the same class frequencies (:func:`change_ratio`), has no
#: spatial structure: the frame is noise (snow, a broken feed) and says nothing about
#: the heading. Measured: camera frames of every simulated scene 0.09-0.75, the real
#: rotation crops (3 and 10 classes) up to 0.78 (grass); uniform noise 0.98-1.03.
NOISE_CHANGE_RATIO = 0.9


def log2_bin(z: np.ndarray, n_bins: int) -> np.ndarray:
    """Bin index of relative frequencies ``z`` in ``[0, 1]`` (paper eq. 2).

    Bin ``k`` (0-based) holds ``2^-(k+1) < z <= 2^-k``; the last bin ``n-1`` also
    holds every ``z <= 2^-(n-1)``, including zero. Exact at powers of two
    (uses ``frexp``, no logarithm rounding).

    Parameters
    ----------
    z : numpy.ndarray
        Relative frequencies, ``0 <= z <= 1``.
    n_bins : int
        Number of bins ``n >= 1``.

    Returns
    -------
    numpy.ndarray
        ``int64`` bin indices, same shape as ``z``.
    """
    z = np.asarray(z, dtype=np.float64)
    mant, expo = np.frexp(z)  # z = mant * 2**expo, mant in [0.5, 1) (0 for z == 0)
    k = -expo.astype(np.int64) + (mant == 0.5)
    k = np.where(z > 0, k, n_bins - 1)
    return np.clip(k, 0, n_bins - 1)


@dataclass(frozen=True)
class ScanGrid:
    """Pixels the compass reads in one image: grid rows above the horizon.

    Attributes
    ----------
    rows : numpy.ndarray
        Scanned rows, top to bottom, all above the horizon.
    cols : numpy.ndarray
        Scanned columns, left to right.
    offsets_deg : numpy.ndarray
        Direction of each scanned column relative to the camera yaw (left positive).
    """

    rows: np.ndarray
    cols: np.ndarray
    offsets_deg: np.ndarray

    @property
    def n_pixels(self) -> int:
        """Number of pixels read."""
        return int(self.rows.size * self.cols.size)

    @property
    def n_transitions(self) -> int:
        """Number of vertical neighbour pairs, i.e. transitions counted."""
        return int(max(self.rows.size - 1, 0) * self.cols.size)


def scan_grid(camera: Camera, width: int, height: int, row_step: int, col_step: int) -> ScanGrid:
    """Scanning grid of an image: every ``row_step``-th row above the horizon, every
    ``col_step``-th column, and the direction each column looks at.

    With pitch the rays of one column fan out in azimuth; the direction is taken at
    the middle of the scanned band (exact for zero pitch).
    """
    horizon = camera.horizon_row(width, height)
    last_row = min(height - 1, math.ceil(horizon) - 1)  # strictly above the horizon
    if last_row < 0:
        rows = np.zeros(0, dtype=np.intp)
    else:
        # anchor the grid at the horizon so that pitch shifts it consistently
        rows = np.arange(last_row, -1, -row_step, dtype=np.intp)[::-1]
    c0 = (width - 1 - ((width - 1) // col_step) * col_step) // 2
    cols = np.arange(c0, width, col_step, dtype=np.intp)
    mid = float(rows[0] + rows[-1]) / 2.0 if rows.size else None
    offsets = camera.column_offsets_deg(cols, width, height, row=mid)
    return ScanGrid(rows=rows, cols=cols, offsets_deg=offsets)


def column_transition_counts(
    classes: np.ndarray, n_colors: int, count_same_class: bool
) -> np.ndarray:
    """Count the vertical transitions per column of a class image (eq. 9).

    Parameters
    ----------
    classes : numpy.ndarray
        ``(R, U)`` class ids of the scanned grid, row 0 at the top.
    n_colors : int
        Number of classes ``c``.
    count_same_class : bool
        Whether ``i -> i`` pairs are counted.

    Returns
    -------
    numpy.ndarray
        ``(U, c*c)`` float32 counts; entry ``[u, i*c + j]`` counts pixels of column
        ``u`` whose class is ``i`` with class ``j`` directly above on the grid.
    """
    r, u = classes.shape
    c2 = n_colors * n_colors
    if r < 2:
        return np.zeros((u, c2), dtype=np.float32)
    below = classes[1:].astype(np.intp)
    above = classes[:-1]
    code = below * n_colors + above  # (R-1, U)
    flat = code + (np.arange(u, dtype=np.intp) * c2)[None, :]
    counts = np.bincount(flat.ravel(), minlength=u * c2).reshape(u, c2)
    if not count_same_class:
        counts[:, :: n_colors + 1] = 0
    return counts.astype(np.float32)


def change_ratio(classes: np.ndarray, n_colors: int) -> float:
    """How often the class changes between vertical neighbours, relative to chance.

    Parameters
    ----------
    classes : numpy.ndarray
        ``(R, U)`` class ids of the scanned grid.
    n_colors : int
        Number of classes ``c``.

    Returns
    -------
    float
        ``q / e``: ``q`` is the fraction of vertical neighbour pairs whose classes
        differ, ``e = 1 - Σ_k p_k²`` the fraction that would differ if the pixels were
        drawn independently with the frame's class frequencies ``p_k``. Images of a
        scene are made of regions and edges (well below 1); noise is near 1. Exactly 0
        if and only if no class changes between vertical neighbours (including a frame
        of one class or of fewer than two rows).
    """
    if classes.shape[0] < 2 or classes.size == 0:
        return 0.0
    q = float(np.count_nonzero(classes[1:] != classes[:-1])) / classes[1:].size
    p = np.bincount(classes.ravel(), minlength=n_colors) / classes.size
    e = 1.0 - float(np.dot(p, p))
    return q / e if e > 1e-12 else 0.0
