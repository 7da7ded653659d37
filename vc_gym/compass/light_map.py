"""How bright the world is in each direction, for ``CompassConfig(exposure="map")``.

The per-frame correction of ``exposure="mean"`` scales every frame to one mean level,
but a frame's mean level depends on what it looks at (sky or trees, a window or a
shelf: one to two stops on the real photo sets) as much as on the light. A map that
also remembers the mean linear light of every sector knows how bright the view at a
candidate heading *should* be, so the gain that undoes a change of light can be
computed for each heading separately, and each heading is then scored with its own
gain (a profile likelihood over the unknown gain). At the true heading that gain is
within a few tenths of a stop of the true change of light on the real photo sets.
"""

from __future__ import annotations

import numpy as np

from vc_gym.exposure import GAIN_STEP_STOPS, quantized_stops

# the gain steps live in vc_gym.exposure (shared with SessionLight); named here too
__all__ = ["GAIN_STEP_STOPS", "LightMap", "quantized_stops"]


class LightMap:
    """Mean linear light per sector, learned with the colour-transition map.

    Parameters
    ----------
    n_sectors : int
        Sectors of the compass map (``CompassConfig.n_sectors``).
    """

    def __init__(self, n_sectors: int):
        self.level_sum = np.zeros(n_sectors, dtype=np.float64)
        self.columns = np.zeros(n_sectors, dtype=np.float64)

    def add(self, sectors: np.ndarray, levels: np.ndarray) -> None:
        """Add scanned columns looking into ``sectors`` with mean light ``levels``."""
        n = self.level_sum.size
        self.level_sum += np.bincount(sectors, weights=levels, minlength=n)
        self.columns += np.bincount(sectors, minlength=n)

    def clear(self) -> None:
        """Forget everything learned."""
        self.level_sum[:] = 0.0
        self.columns[:] = 0.0

    def merge(self, other: LightMap) -> None:
        """Add ``other``'s sums (maps of the same sectors)."""
        self.level_sum += other.level_sum
        self.columns += other.columns

    def resampled(self, source: np.ndarray) -> LightMap:
        """A light map whose sector ``s`` holds a copy of sector ``source[s]``."""
        out = LightMap(self.level_sum.size)
        out.level_sum = self.level_sum[source]
        out.columns = self.columns[source]
        return out

    def regrouped(self, target: np.ndarray) -> LightMap:
        """A light map whose sector ``t`` holds the sums of every sector ``s`` with
        ``target[s] == t`` (sectors no source lands on stay unlit)."""
        n = self.level_sum.size
        out = LightMap(n)
        out.level_sum = np.bincount(target, weights=self.level_sum, minlength=n)
        out.columns = np.bincount(target, weights=self.columns, minlength=n)
        return out

    def heading_gains(
        self,
        levels: np.ndarray,
        first_col: np.ndarray,
        stop_col: np.ndarray,
        n_rel: int,
        heading_phase: np.ndarray,
        sector_of: np.ndarray,
    ) -> np.ndarray:
        """Gain per candidate heading that brings the frame to the learned light.

        Parameters
        ----------
        levels : numpy.ndarray
            ``(U,)`` mean linear light of the frame's scanned columns.
        first_col, stop_col : numpy.ndarray
            ``(P * n_rel,)``: the scanned columns ``[first, stop)`` that fall into
            relative sector ``k`` at heading phase ``p`` (row ``p * n_rel + k``).
        n_rel : int
            Relative sectors per phase.
        heading_phase : numpy.ndarray
            ``(H,)`` phase of every candidate heading.
        sector_of : numpy.ndarray
            ``(n_rel, H)`` map sector that relative sector ``k`` looks into at heading ``h``.

        Returns
        -------
        numpy.ndarray
            ``(H,)`` gains: the learned mean light of the sectors in view (weighted by
            the frame's columns in each) over the frame's mean light in those columns.
            1 where the view holds no learned sector or the frame is black.
        """
        cum = np.zeros(levels.size + 1)
        np.cumsum(levels, out=cum[1:])
        light = (cum[stop_col] - cum[first_col]).reshape(-1, n_rel)  # (P, K)
        ncols = (stop_col - first_col).reshape(-1, n_rel).astype(np.float64)
        known = self.columns[sector_of] > 0  # (K, H)
        mean = np.divide(
            self.level_sum, self.columns, out=np.zeros_like(self.level_sum), where=self.columns > 0
        )
        w_known = known.T  # (H, K)
        expected = (mean[sector_of].T * ncols[heading_phase] * w_known).sum(axis=1)
        seen = (light[heading_phase] * w_known).sum(axis=1)
        ok = (expected > 0) & (seen > 0)
        return np.where(ok, expected / np.where(ok, seen, 1.0), 1.0)
