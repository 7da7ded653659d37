"""A spot's map re-drawn for a nearby position: the compass corrected for parallax.

The paper's map holds, per 4.5° sector, what the robot saw in that direction from the
spot where it learned (eq. 1, 6). A step away from the spot, a nearby wall is seen in
another direction, a far one in nearly the same: the map no longer fits, which is why the
heading error grows with the distance from the spot (paper fig. 4). If the map knows how
far each sector's wall point is, it can be re-drawn for any nearby position: every sector
moves to the direction its wall point has from there (:meth:`ParallaxMap.at`).

The distances are learned without any geometry: the robot also learns short turns a
little away from the spot (the spot-grid mode's turns around a spot), and each sector's
distance is the one at which the spot's histograms, moved to where each of those turns
would see them, fit that turn best (:func:`learn_depths`). The turns around the spot are
kept as maps of their own and are re-drawn with the spot's turn, from where each was
taken.

The warp needs the position: at the true position it removes most of the error that is
left 0.35 m from a spot in a small room; with a position 0.5 m off it is no better than
the spot's plain map (``scripts/parallax_diagnostic.py``, README).

>>> around = [((0.5, 0), east), ((-0.5, 0), west)]              # doctest: +SKIP
>>> pm = ParallaxMap.learn((0, 0), spot_map, around)               # doctest: +SKIP
>>> pm.at((0.3, -0.2)).estimate(image, camera).heading_deg         # doctest: +SKIP
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from vc_gym.compass.camera import Camera
from vc_gym.compass.visual_compass import VisualCompass

__all__ = ["DEPTH_CANDIDATES_M", "ParallaxMap", "learn_depths", "sector_of"]

#: Distances tried for a sector's wall point (metres, geometric steps): 0.4 m to 8 m.
DEPTH_CANDIDATES_M = np.geomspace(0.4, 8.0, 40)

#: Closest a wall point may come to a position it is seen from (metres).
_MIN_RANGE_M = 0.1

#: Fixed-point iterations that find what a ray from an off-spot position hits.
_RAY_ITERATIONS = 6


def sector_of(dx: np.ndarray, dy: np.ndarray, sector_deg: float) -> np.ndarray:
    """The map sector a direction ``(dx, dy)`` falls in (sector ``k`` covers
    ``[k·Δφ, (k+1)·Δφ)`` degrees counter-clockwise from ``+x``)."""
    n = int(round(360.0 / sector_deg))
    deg = np.degrees(np.arctan2(dy, dx)) % 360.0
    return np.floor(deg / sector_deg).astype(np.intp) % n


def _point(name: str, value: Sequence[float]) -> np.ndarray:
    p = np.asarray(value, dtype=np.float64)
    if p.shape != (2,) or not np.all(np.isfinite(p)):
        raise ValueError(f"{name} must be two finite numbers (x, y) in metres, got {value!r}")
    return p


def _checked_maps(
    pairs: Sequence[tuple[Sequence[float], VisualCompass]], what: str, like: VisualCompass
) -> list[tuple[np.ndarray, VisualCompass]]:
    """``[(point, map)]`` with every map learned with ``like``'s config."""
    out = []
    for k, item in enumerate(pairs):
        try:
            point, m = item
        except (TypeError, ValueError):
            raise ValueError(f"{what}[{k}] must be ((x, y), VisualCompass)") from None
        if not isinstance(m, VisualCompass) or not m.is_learned:
            raise ValueError(f"{what}[{k}]: the map must be a learned VisualCompass")
        if m.config != like.config:
            raise ValueError(f"{what}[{k}]: the map has another CompassConfig")
        if not m.shares_colors(like):
            raise ValueError(f"{what}[{k}]: the map was learned with other colour classes")
        out.append((_point(f"{what}[{k}] position", point), m))
    if not out:
        raise ValueError(f"{what} must hold at least one map")
    return out


def _learned(spot_map: VisualCompass) -> VisualCompass:
    if not isinstance(spot_map, VisualCompass) or not spot_map.is_learned:
        raise ValueError("the spot's map must be a learned VisualCompass")
    return spot_map


def _added(maps) -> VisualCompass:
    """The sum of an iterable of fresh maps (the others are merged into the first)."""
    maps = iter(maps)
    out = next(maps)
    for m in maps:
        out.merge(m)
    return out


def learn_depths(
    spot_map: VisualCompass,
    around: Sequence[tuple[Sequence[float], VisualCompass]],
    candidates_m: np.ndarray = DEPTH_CANDIDATES_M,
) -> np.ndarray:
    """Distance of each sector's wall point from the spot, learned from turns around it.

    For a candidate distance ``d`` the wall point of spot sector ``s`` lies at
    ``d·(cos θ_s, sin θ_s)``; a turn taken at offset ``o`` sees it in sector
    ``s' = sector(d·u(θ_s) − o)``. The score of ``d`` is the expected log-probability of
    that turn's sector ``s'`` histograms under the spot's sector ``s`` (the terms of
    eq. 5, 16), summed over the turns that saw ``s'``; each sector takes the best ``d``.

    Parameters
    ----------
    spot_map : VisualCompass
        The map learned at the spot.
    around : sequence of ((dx, dy), VisualCompass)
        Maps of turns taken at offsets ``(dx, dy)`` metres from the spot (world frame),
        learned with the spot's config and colour classes; 0.5 m away works.
    candidates_m : numpy.ndarray
        Distances to try, metres, positive and finite; the default is
        :data:`DEPTH_CANDIDATES_M`.

    Returns
    -------
    numpy.ndarray
        ``(n_sectors,)`` distances in metres. A sector no turn tells anything about keeps
        the largest candidate (far away: it barely moves).

    Raises
    ------
    ValueError
        An unlearned map, a turn with another config, a bad offset or candidates.
    """
    turns = _checked_maps(around, "around", _learned(spot_map))
    cand = np.asarray(candidates_m, dtype=np.float64)
    if cand.ndim != 1 or cand.size == 0 or not np.all(np.isfinite(cand)) or cand.min() <= 0:
        raise ValueError("candidates_m must be a non-empty 1-D array of positive distances")
    cfg = spot_map.config
    n = cfg.n_sectors
    theta = np.radians((np.arange(n) + 0.5) * cfg.sector_deg)
    log_p = spot_map.sector_log_probabilities()  # (S, pairs, bins)
    rows = np.arange(n)[:, None]
    score = np.zeros((n, cand.size))
    for (ox, oy), m in turns:
        seen = m.sector_observations
        # fit[s, t]: mean log-probability of the turn's sector-t frames under spot sector s
        fit = np.einsum("sqb,tqb->st", log_p, m.map_counts) / np.maximum(seen, 1)[None, :]
        s2 = sector_of(
            cand[None, :] * np.cos(theta)[:, None] - ox,
            cand[None, :] * np.sin(theta)[:, None] - oy,
            cfg.sector_deg,
        )
        score += np.where(seen[s2] > 0, fit[rows, s2], 0.0)
    best = cand[np.argmax(score, axis=1)]
    best[~np.any(score != 0.0, axis=1)] = cand.max()
    return best


class ParallaxMap:
    """A spot's map and the turns around it, re-drawn for any nearby position.

    Parameters
    ----------
    spot : (float, float)
        Where the spot's turn was learned, world metres.
    depths_m : numpy.ndarray
        ``(n_sectors,)`` distance of each sector's wall point from the spot, metres
        (:func:`learn_depths`, or a ray-cast room's true distances).
    parts : sequence of ((x, y), VisualCompass)
        Maps and the world positions they were learned at (the spot's turn and the
        turns around it), all with one config and colour classes.

    Notes
    -----
    The wall is the surface the distances describe around the spot. From a position
    ``p`` a direction ``θ`` hits it where the spot's distance in the direction of the
    hit equals the hit's distance from the spot (a few fixed-point steps). A part learned
    at ``o`` saw that wall point in the direction of ``W − o``; :meth:`at` moves each of
    its sectors there (:meth:`VisualCompass.regrouped`) and adds the parts up.
    """

    def __init__(
        self,
        spot: Sequence[float],
        depths_m: np.ndarray,
        parts: Sequence[tuple[Sequence[float], VisualCompass]],
    ):
        self.spot = _point("spot", spot)
        parts = list(parts)
        if not parts or not isinstance(parts[0], tuple) or len(parts[0]) != 2:
            raise ValueError("parts must be a non-empty sequence of ((x, y), VisualCompass)")
        self.parts = _checked_maps(parts, "parts", _learned(parts[0][1]))
        self.config = self.parts[0][1].config
        n = self.config.n_sectors
        depths = np.asarray(depths_m, dtype=np.float64)
        if depths.shape != (n,) or not np.all(np.isfinite(depths)) or depths.min() <= 0:
            raise ValueError(f"depths_m must be {n} positive finite distances in metres")
        self.depths_m = depths
        self._theta = np.radians((np.arange(n) + 0.5) * self.config.sector_deg)
        self._spot_wall = depths[:, None] * np.c_[np.cos(self._theta), np.sin(self._theta)]
        self._centred: VisualCompass | None = None

    @classmethod
    def learn(
        cls,
        spot: Sequence[float],
        spot_map: VisualCompass,
        around: Sequence[tuple[Sequence[float], VisualCompass]],
        candidates_m: np.ndarray = DEPTH_CANDIDATES_M,
    ) -> ParallaxMap:
        """Learn the distances from the turns ``around`` (offsets from the spot) and
        keep every turn as a part (see :func:`learn_depths`)."""
        spot = _point("spot", spot)
        depths = learn_depths(spot_map, around, candidates_m)
        parts = [(spot, spot_map)] + [(spot + _point("offset", o), m) for o, m in around]
        return cls(spot, depths, parts)

    def wall_points(self, position: Sequence[float]) -> np.ndarray:
        """``(n_sectors, 2)`` world points the sector centres look at from ``position``."""
        return self._walls(_point("position", position)[None])[0]

    def _walls(self, positions: np.ndarray) -> np.ndarray:
        """``(N, n_sectors, 2)`` :meth:`wall_points` of ``(N, 2)`` checked positions."""
        p = (positions - self.spot)[:, None, :]  # (N, 1, 2)
        d, th, sd = self.depths_m, self._theta, self.config.sector_deg
        ray = np.c_[np.cos(th), np.sin(th)]  # (S, 2)
        r = np.broadcast_to(d, (len(positions), d.size))
        for _ in range(_RAY_ITERATIONS):  # the spot's distance towards the point hit
            hit = p + r[..., None] * ray
            s = sector_of(hit[..., 0], hit[..., 1], sd)
            r = np.maximum(np.hypot(*np.moveaxis(self._spot_wall[s] - p, -1, 0)), _MIN_RANGE_M)
        return self.spot + p + r[..., None] * ray

    def at(self, position: Sequence[float]) -> VisualCompass:
        """The map re-drawn for a robot standing at ``position`` (world metres).

        Returns a new :class:`VisualCompass` (the parts' counts, each sector moved to
        the direction its wall point has from ``position``); use it like any map.
        """
        pos = _point("position", position)
        sd = self.config.sector_deg
        return _added(
            m.regrouped(sector_of(*(self.wall_points(origin) - pos).T, sd))
            for origin, m in self.parts
        )

    def centred(self) -> VisualCompass:
        """All parts re-drawn for the spot and added up (cached): every spot sector
        takes, from each part, the sector in which that part saw the sector's wall
        point (:meth:`VisualCompass.resampled`), so no sector is left unseen."""
        if self._centred is None:
            wall = self._spot_wall + self.spot
            sd = self.config.sector_deg
            self._centred = _added(
                m.resampled(sector_of(*(wall - origin).T, sd)) for origin, m in self.parts
            )
        return self._centred

    def sector_maps(self, positions: np.ndarray) -> np.ndarray:
        """``(N, n_sectors)``: for a camera at each position, the spot sector that sees
        the wall point of each direction sector (rows for
        :meth:`VisualCompass.log_likelihood_remapped`)."""
        pos = np.asarray(positions, dtype=np.float64)
        if pos.ndim != 2 or pos.shape[1] != 2 or not np.all(np.isfinite(pos)):
            raise ValueError(f"positions must be an (N, 2) array of finite metres, got {pos.shape}")
        rel = self._walls(pos) - self.spot
        return sector_of(rel[..., 0], rel[..., 1], self.config.sector_deg)

    def pose_log_likelihood(
        self, image: np.ndarray, camera: Camera, positions: np.ndarray
    ) -> np.ndarray:
        """Log-likelihood of every (position, heading): the :meth:`centred` map with
        each direction scored against the spot sector that sees the same wall point
        from that position (eq. 5, 16 with the parallax of each position).

        Parameters
        ----------
        image, camera
            As for :meth:`VisualCompass.log_likelihood`.
        positions : numpy.ndarray
            ``(N, 2)`` candidate positions, world metres.

        Returns
        -------
        numpy.ndarray
            ``(N, n_headings)``; rows of different positions are comparable (the same
            frame terms, each scored against one map sector).
        """
        return self.centred().log_likelihood_remapped(image, camera, self.sector_maps(positions))
