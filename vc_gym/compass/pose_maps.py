"""The likelihood of many poses at once: every spot's map re-drawn for positions near it.

A tracker with a belief over ``(x, y, θ)`` asks, every frame, how well the frame fits
each of hundreds of poses. :class:`PoseMaps` answers that with the parallax-corrected
maps of :mod:`vc_gym.compass.parallax`: the frame is scored against the map of the spot
nearest each pose, re-drawn for the pose's position (eq. 5, 16 with each direction
scored against the spot sector that sees the same wall point from there).

Two things make it cheap enough for a particle filter:

* the frame's terms under each spot's map (one value per heading phase, relative
  sector and map sector) are computed once per frame (:meth:`PoseMaps.frame`); a pose
  then costs one gather per sector in view;
* which spot sector a direction sector sees from a position is precomputed on a
  lattice of positions around each spot (``lattice_m`` apart, out to ``reach_m``), so
  no ray is traced while tracking.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vc_gym.compass.atlas import CompassAtlas
from vc_gym.compass.camera import Camera
from vc_gym.compass.likelihood import _group_scores
from vc_gym.compass.parallax import ParallaxMap
from vc_gym.compass.scan_geometry import ScanGeometry
from vc_gym.validation import positive_float

__all__ = ["MAX_LATTICE_STEPS", "FrameTerms", "PoseMaps", "around_groups"]

#: Most lattice steps from a spot to the edge of its square (``reach_m / lattice_m``):
#: the lattice is precomputed, ``(2 · 200 + 1)²`` cells a spot.
MAX_LATTICE_STEPS = 200


def around_groups(names: Sequence[str]) -> dict[str, list[str]]:
    """Spots and the turns learned around them, by name.

    An entry named ``"NAME.x"`` whose ``NAME`` is also an entry is a turn learned around
    spot ``NAME`` (:class:`~vc_gym.envs.learning.GridLearning` with
    ``keep_around=True``); every other entry is a spot of its own.

    Returns
    -------
    dict
        ``{spot: [spot, turns around it ...]}`` in the order of ``names``.
    """
    names = [str(n) for n in names]
    known = set(names)
    groups: dict[str, list[str]] = {}
    for n in names:
        head, dot, _ = n.rpartition(".")
        if not (dot and head in known):
            groups.setdefault(n, [n])
    for n in names:
        head, dot, _ = n.rpartition(".")
        if dot and head in known:
            groups[head].append(n)
    return groups


@dataclass(frozen=True)
class FrameTerms:
    """One frame's terms under some spots' maps (:meth:`PoseMaps.frame`).

    Attributes
    ----------
    spots : numpy.ndarray
        ``(M,)`` the spot indices scored, in the order of ``per_group``'s map axis.
    per_group : numpy.ndarray or None
        ``(P, K, M, S)``: the log-ratio of the frame's columns of heading phase ``p``
        and relative sector ``k`` under sector ``s`` of spot ``m``'s centred map;
        ``None`` if the frame saw nothing (every pose then fits equally).
    geometry : ScanGeometry
        The frame's scan geometry.
    """

    spots: np.ndarray
    per_group: np.ndarray | None
    geometry: ScanGeometry

    @property
    def has_evidence(self) -> bool:
        """Whether the frame says anything about the pose."""
        return self.per_group is not None


class PoseMaps:
    """Every spot's map, re-drawn for any position near it (beyond the paper).

    Parameters
    ----------
    spots : sequence of ParallaxMap
        One per spot, all with one config and colour classes.
    lattice_m : float
        Spacing of the precomputed positions (default 0.1 m: a wall 1 m away moves by
        under 3°, less than a sector, between neighbours).
    reach_m : float
        Half-width of the square of precomputed positions around each spot; a position
        farther out is scored as at the square's edge.

    Notes
    -----
    The log-likelihood of a pose is the sum, over the sectors in view, of the frame's
    term under the nearest spot's :meth:`~ParallaxMap.centred` map sector that sees the
    same wall point from the pose's position. Poses near different spots are scored
    against different maps; the maps share their colour classes and were learned the
    same way, so their answers compare (as eq. 28 compares spots).
    """

    def __init__(self, spots: Sequence[ParallaxMap], lattice_m: float = 0.1, reach_m: float = 1.5):
        spots = list(spots)
        if not spots or not all(isinstance(s, ParallaxMap) for s in spots):
            raise ValueError("spots must be a non-empty sequence of ParallaxMap")
        self.lattice_m = positive_float("lattice_m", lattice_m)
        self.reach_m = positive_float("reach_m", reach_m)
        if self.reach_m / self.lattice_m > MAX_LATTICE_STEPS:
            raise ValueError(
                f"reach_m / lattice_m must be at most {MAX_LATTICE_STEPS} (the lattice is "
                "precomputed), got "
                f"{self.reach_m} / {self.lattice_m}"
            )
        self.maps = tuple(s.centred() for s in spots)
        first = self.maps[0]
        if any(m.config != first.config or not m.shares_colors(first) for m in self.maps):
            raise ValueError("the spots' maps must share one CompassConfig and colour classes")
        if first.config.exposure == "map":
            raise ValueError('PoseMaps does not support exposure="map" (a gain per map sector)')
        self.config = first.config
        self.positions = np.array([s.spot for s in spots], dtype=np.float64)
        #: The spots' names (their atlas names with :meth:`from_atlas`).
        self.names = tuple(f"spot{k}" for k in range(len(spots)))
        half = int(round(self.reach_m / self.lattice_m))
        self._half = half
        axis = np.arange(-half, half + 1) * self.lattice_m
        gx, gy = np.meshgrid(axis, axis, indexing="ij")
        offsets = np.c_[gx.ravel(), gy.ravel()]
        dtype = np.int16 if self.config.n_sectors < 2**15 else np.int32
        #: ``(n_spots, cells, S)``: the spot sector each direction sector sees from a cell
        self._sector_maps = np.stack(
            [s.sector_maps(s.spot + offsets).astype(dtype) for s in spots]
        )
        deltas = [m._log_tables()[:2] for m in self.maps]
        self._delta_t = np.stack([d for d, _ in deltas], axis=1)  # (c²n, M, S)
        self._base = np.stack([b for _, b in deltas])  # (M, S)

    @classmethod
    def from_atlas(
        cls, atlas: CompassAtlas, lattice_m: float = 0.1, reach_m: float = 1.5
    ) -> PoseMaps:
        """The pose maps of an atlas: every spot with the turns learned around it
        (:func:`around_groups`) as one :class:`ParallaxMap` (wall distances learned from
        those turns; a spot without any keeps its map as it is)."""
        if not isinstance(atlas, CompassAtlas):
            raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
        index = {n: k for k, n in enumerate(atlas.names)}
        groups = around_groups(atlas.names)
        spots = []
        for name, members in groups.items():
            k = index[name]
            spot, spot_map = atlas.positions[k], atlas.compasses[k]
            around = [
                (atlas.positions[index[m]] - spot, atlas.compasses[index[m]]) for m in members[1:]
            ]
            if around:
                spots.append(ParallaxMap.learn(spot, spot_map, around))
            else:
                far = np.full(spot_map.config.n_sectors, 1e3)  # nothing moves: the plain map
                spots.append(ParallaxMap(spot, far, [(spot, spot_map)]))
        out = cls(spots, lattice_m, reach_m)
        out.names = tuple(groups)
        return out

    def __len__(self) -> int:
        return len(self.maps)

    def nearest(self, xy: np.ndarray) -> np.ndarray:
        """``(N,)`` index of the spot nearest each of ``(N, 2)`` positions."""
        return np.argmin(self._squared_distances(xy), axis=1)

    def nearest_two(self, xy: np.ndarray) -> np.ndarray:
        """``(N, 2)`` indices of the two spots nearest each of ``(N, 2)`` positions,
        nearest first (one column if there is only one spot)."""
        return np.argsort(self._squared_distances(xy), axis=1)[:, :2]

    def _squared_distances(self, xy: np.ndarray) -> np.ndarray:
        """``(N, n_spots)`` squared distances of positions from the spots."""
        d = xy[:, None, :] - self.positions[None, :, :]
        return np.einsum("nmk,nmk->nm", d, d)

    def frame(
        self,
        image: np.ndarray,
        camera: Camera,
        spots: Sequence[int] | np.ndarray | None = None,
        gain: float | None = None,
    ) -> FrameTerms:
        """The frame's terms under the maps of ``spots`` (default: every spot).

        ``gain`` is the session's light, as in :meth:`VisualCompass.log_likelihood`.
        """
        which = (
            np.arange(len(self.maps))
            if spots is None
            else np.unique(np.asarray(spots, dtype=np.intp))
        )
        if which.size == 0 or which.min() < 0 or which.max() >= len(self.maps):
            raise ValueError(f"spots must be indices in [0, {len(self.maps)}), got {spots!r}")
        first = self.maps[0]
        first._checked(image, camera, need_map=True)
        g = first._gain_for(image, camera, first._checked_gain(gain))
        geom, counts, total = first._sector_features(image, camera, g)
        maps = None if which.size == len(self.maps) else which
        per_group = _group_scores(self.config, geom, counts, total, self._delta_t, self._base, maps)
        return FrameTerms(which, per_group, geom)

    def log_likelihood(
        self,
        terms: FrameTerms,
        xy: np.ndarray,
        camera_heading_deg: np.ndarray,
        spot: np.ndarray | None = None,
    ) -> np.ndarray:
        """Log-likelihood of the frame of ``terms`` for camera poses (eq. 5, 16).

        Parameters
        ----------
        terms : FrameTerms
            The frame (:meth:`frame`); it must hold every spot used.
        xy : numpy.ndarray
            ``(N, 2)`` positions, world metres.
        camera_heading_deg : numpy.ndarray
            ``(N,)`` headings of the camera's optical axis (body heading plus head
            pan), degrees; read on the compass' heading grid.
        spot : numpy.ndarray, optional
            ``(N,)`` the spot whose map scores each pose; default :meth:`nearest`.

        Returns
        -------
        numpy.ndarray
            ``(N,)`` float64, divided by ``config.temperature``; zeros if the frame saw
            nothing.
        """
        xy = np.asarray(xy, dtype=np.float64)
        heading = np.asarray(camera_heading_deg, dtype=np.float64)
        if xy.ndim != 2 or xy.shape[1] != 2 or heading.shape != (xy.shape[0],):
            raise ValueError(
                f"xy must be (N, 2) and camera_heading_deg (N,), got {xy.shape}, {heading.shape}"
            )
        if not (np.all(np.isfinite(xy)) and np.all(np.isfinite(heading))):
            raise ValueError("poses must be finite")
        n = xy.shape[0]
        if terms.per_group is None or n == 0:
            return np.zeros(n)
        spot = self.nearest(xy) if spot is None else np.asarray(spot, dtype=np.intp)
        local = np.searchsorted(terms.spots, spot)
        local = np.minimum(local, terms.spots.size - 1)
        if not np.array_equal(terms.spots[local], spot):
            raise ValueError("terms do not hold every spot asked for: pass them to frame()")
        cell = self._cells(xy - self.positions[spot])
        rows = self._sector_maps[spot, cell]  # (N, S)
        geom, cfg = terms.geometry, self.config
        h = np.rint(heading / cfg.heading_step_deg).astype(np.int64) % cfg.n_headings
        phase, s0 = geom.heading_phase[h], geom.heading_sector[h]
        k = np.arange(geom.n_rel)
        direction = (s0[:, None] + k[None, :] + geom.kmin) % cfg.n_sectors  # (N, K)
        sectors = rows[np.arange(n)[:, None], direction]
        ll = terms.per_group[phase[:, None], k[None, :], local[:, None], sectors].sum(axis=1)
        return ll / cfg.temperature if cfg.temperature != 1.0 else ll

    def heading_log_likelihood(self, terms: FrameTerms, spot: int) -> np.ndarray:
        """``(n_headings,)``: the frame's log-likelihood of every camera heading at the
        position of ``spot`` itself (its centred map; eq. 5, 16)."""
        cfg = self.config
        headings = np.arange(cfg.n_headings) * cfg.heading_step_deg
        xy = np.broadcast_to(self.positions[spot], (headings.size, 2))
        return self.log_likelihood(terms, xy, headings, np.full(headings.size, spot))

    def _cells(self, offsets: np.ndarray) -> np.ndarray:
        """Lattice cell of each offset from its spot (clipped to the square)."""
        half, side = self._half, 2 * self._half + 1
        ij = np.clip(np.rint(offsets / self.lattice_m).astype(np.int64), -half, half) + half
        return ij[:, 0] * side + ij[:, 1]
