"""The compass map: transition histograms per sector, and how frames add to it.

The map holds counts ``m[sector, i·c + j, bin]`` (paper eq. 1, 6) and how many
learned frames saw each sector. A frame taken at a known heading adds one count per
sector in view and class pair, to the bin its relative frequency (eq. 11) falls in
(eq. 2). A map is counts, so maps add up, and a map re-drawn for other directions
moves or copies whole sectors.
"""

from __future__ import annotations

import numpy as np

from vc_gym.compass.features import log2_bin

__all__ = ["add_frame", "checked_sectors", "regrouped_counts"]


def add_frame(
    counts: np.ndarray, n_obs: np.ndarray, colcounts: np.ndarray, sectors: np.ndarray
) -> np.ndarray:
    """Add one frame to the map in place (eq. 6) and return the sectors it updated.

    Parameters
    ----------
    counts : numpy.ndarray
        ``(n_sectors, c², n_bins)`` float64 map, updated in place.
    n_obs : numpy.ndarray
        ``(n_sectors,)`` frames that saw each sector, updated in place.
    colcounts : numpy.ndarray
        ``(U, c²)`` transition counts of each scanned column (eq. 9).
    sectors : numpy.ndarray
        ``(U,)`` map sector each column looks into.

    Returns
    -------
    numpy.ndarray
        The sectors that saw at least one transition, each given one count per class
        pair (empty if the frame saw none; then nothing changes).
    """
    n_sectors, _, n_bins = counts.shape
    c2 = colcounts.shape[1]
    flat = (sectors[:, None] * c2 + np.arange(c2)[None, :]).ravel()
    per_sector = np.bincount(flat, weights=colcounts.ravel(), minlength=n_sectors * c2).reshape(
        n_sectors, c2
    )
    total = per_sector.sum(axis=1)
    seen = np.flatnonzero(total > 0)
    if seen.size == 0:
        return seen
    z = per_sector[seen] / total[seen, None]
    bins = log2_bin(z, n_bins)
    counts[seen[:, None], np.arange(c2)[None, :], bins] += 1.0
    n_obs[seen] += 1.0
    return seen


def regrouped_counts(
    counts: np.ndarray, n_obs: np.ndarray, target: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The map whose sector ``t`` holds the sum of every sector ``s`` with
    ``target[s] == t`` (eq. 6 is a sum); sectors no source lands on stay empty.

    Returns
    -------
    tuple of numpy.ndarray
        The new ``counts`` and ``n_obs`` (float64, shapes of the inputs).
    """
    n = counts.shape[0]
    out = np.zeros_like(counts)
    np.add.at(out, target, counts)
    return out, np.bincount(target, weights=n_obs, minlength=n).astype(np.float64)


def checked_sectors(
    name: str, sectors: np.ndarray, n_sectors: int, rows: bool = False
) -> np.ndarray:
    """``sectors`` as an integer array of map sectors: ``(n_sectors,)``, or
    ``(N, n_sectors)`` with ``rows``.

    Raises
    ------
    ValueError
        Naming ``name``, for another shape, a non-integer dtype or a sector outside
        ``[0, n_sectors)``.
    """
    n = n_sectors
    sectors = np.asarray(sectors)
    shape = f"(N, {n})" if rows else f"({n},)"
    if (
        sectors.ndim != (2 if rows else 1)
        or sectors.shape[-1] != n
        or not np.issubdtype(sectors.dtype, np.integer)
    ):
        raise ValueError(
            f"{name} must be an integer array of shape {shape}, got {sectors.dtype} {sectors.shape}"
        )
    if sectors.size and (sectors.min() < 0 or sectors.max() >= n):
        raise ValueError(
            f"{name} sectors must lie in [0, {n}), got {sectors.min()}..{sectors.max()}"
        )
    return sectors
