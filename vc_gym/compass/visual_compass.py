"""The visual compass sensor model of Sturm & Visser (paper sections 3.1-3.4).

A :class:`VisualCompass` learns, at one spot, how often each colour-class transition
appears in each direction (a histogram map, eq. 1-2 and 6) and answers, for a new
camera image, a log-likelihood for every candidate heading (eq. 5, 15-16).
"""

from __future__ import annotations

import math
import os
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vc_gym.angles import circular_std_rows, peak_headings
from vc_gym.compass.camera import Camera
from vc_gym.compass.colors import MAX_LIGHT_LEVEL, ColorClasses
from vc_gym.compass.config import CompassConfig
from vc_gym.compass.features import (
    NOISE_CHANGE_RATIO,
    ScanGrid,
    change_ratio,
    column_transition_counts,
    log2_bin,
    scan_grid,
)
from vc_gym.compass.light_map import LightMap
from vc_gym.errors import MapFileError, NotLearnedError
from vc_gym.exposure import (
    GAIN_STEP_STOPS,
    column_levels,
    gain_table,
    mean_linear_level,
    quantized_stops,
    rounded_gain,
)
from vc_gym.images import check_image
from vc_gym.persistence import json_array, load_npz_checked, read_json_array, save_npz_atomic
from vc_gym.validation import positive_float

__all__ = ["VisualCompass", "CompassEstimate"]

MAP_SCHEMA = "vc_gym.VisualCompass"
#: Exposure modes that keep the colour-fitting images' mean light as a reference level.
REFERENCE_EXPOSURES = ("mean", "session")
MAP_SCHEMA_VERSION = 1
#: Pseudo-count per bin of the heading-independent (pooled) histogram.
_POOL_PSEUDOCOUNT = 0.5
_CACHE_SIZE = 16
#: Most distinct frame sizes a map file may list: a map learns from one camera or a
#: few; each listed size becomes a Python object when loaded (about 150 bytes), and an
#: entry of 64 MiB could otherwise list 4 million of them.
MAX_LEARNED_SIZES = 4096
# Table rows gathered at once when scoring a frame against several maps: a few hundred
# kilobytes stay in the cache; one gather of every row (16 MB for 24 maps) made the
# scoring memory-bound and 1.6 times slower (measured, see _group_sums).
_GATHER_BYTES = 1 << 19


@dataclass(frozen=True)
class CompassEstimate:
    """What the compass says about one image.

    Attributes
    ----------
    heading_deg : float
        Most likely heading in ``[0, 360)`` (arg-max of the log-likelihood, refined
        between grid points by a parabola through the peak and its neighbours).
    spread_deg : float
        Circular standard deviation (eq. 27) of the posterior ``∝ exp(log-likelihood)``
        under a uniform prior. Small when one heading clearly wins, large (up to
        infinity) when the image is ambiguous.
    score : float
        Goodness of fit: the mean log-probability per term (sector × class pair) of
        the image's features under the map at the best heading, ``<= 0``. It is
        comparable between maps with the same config, so it serves as the per-spot
        goodness ``L`` of eq. 28 (``exp(score)`` is the geometric-mean likelihood
        per term).
    n_sectors : int
        Number of sectors the image contributed (about ``hfov / sector_deg``).
    log_likelihood : numpy.ndarray
        The full log-likelihood over :attr:`VisualCompass.headings_deg`.
    """

    heading_deg: float
    spread_deg: float
    score: float
    n_sectors: int
    log_likelihood: np.ndarray


@dataclass(frozen=True)
class _Geometry:
    """Everything about an image size + camera that does not depend on pixel values."""

    grid: ScanGrid
    row_slice: slice
    col_slice: slice
    # (P*K,) each: the scanned columns ``first[r] <= u < stop[r]`` fall into relative
    # sector k at phase p, r = p*K + k (columns look at monotonically falling directions)
    first_col: np.ndarray
    stop_col: np.ndarray
    kmin: int
    n_rel: int  # K
    heading_phase: np.ndarray  # (n_headings,) phase index of each heading
    heading_sector: np.ndarray  # (n_headings,) sector of each heading's optical axis
    roll_index: np.ndarray  # (K, S): sector (s0 + k + kmin) mod S


class VisualCompass:
    """Appearance-based visual compass: learn a map at a spot, then tell headings.

    Parameters
    ----------
    config : CompassConfig, optional
        Parameters; the paper's values by default.
    colors : ColorClasses, optional
        Colour classes learned beforehand; otherwise call :meth:`fit_colors`.

    Notes
    -----
    The map holds counts ``m[sector, i, j, bin]`` (paper eq. 1, 6) and the number of
    frames that saw each sector. The likelihood of an image at heading ``φ`` is the
    product over the sectors in view and over all class pairs (eq. 5, 16) of the
    smoothed histogram probability of the bin its relative frequency falls in.

    The features of an image depend on the candidate heading (columns are grouped
    into sectors differently for headings that are not a multiple of the sector
    width). :meth:`log_likelihood` therefore returns the log of the likelihood
    *ratio* against the map's heading-independent model (the same histograms pooled
    over all sectors). It differs from ``log p(image | φ)`` by a term that does not
    depend on the heading; sectors the map has never seen contribute exactly zero.

    Examples
    --------
    >>> vc = VisualCompass(CompassConfig(n_colors=10))          # doctest: +SKIP
    >>> vc.fit_colors(images)                                   # doctest: +SKIP
    >>> for img, yaw in training: vc.learn(img, Camera(yaw_deg=yaw))  # doctest: +SKIP
    >>> vc.estimate(new_image, Camera()).heading_deg            # doctest: +SKIP
    """

    def __init__(self, config: CompassConfig | None = None, colors: ColorClasses | None = None):
        self.config = config if config is not None else CompassConfig()
        if not isinstance(self.config, CompassConfig):
            raise ValueError(f"config must be a CompassConfig, got {type(self.config).__name__}")
        self._colors: ColorClasses | None = None
        self._exposure_ref = 0.0  # mean linear level of the colour-fitting images
        if colors is not None:
            self._set_colors(colors)
        cfg = self.config
        c2 = cfg.n_colors**2
        self._counts = np.zeros((cfg.n_sectors, c2, cfg.n_bins), dtype=np.float64)
        self._n_obs = np.zeros(cfg.n_sectors, dtype=np.float64)
        self._light = LightMap(cfg.n_sectors)  # learned only with exposure="map"
        self._frames = 0
        self._sizes: set[tuple[int, int]] = set()  # (H, W) of the learned frames
        self._tables: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._geom_cache: OrderedDict[tuple, _Geometry] = OrderedDict()
        h = np.arange(cfg.n_headings, dtype=np.float64) * cfg.heading_step_deg
        h.setflags(write=False)
        self._headings = h

    # ------------------------------------------------------------------ properties
    @property
    def headings_deg(self) -> np.ndarray:
        """Candidate headings (read-only), ``0, step, ..., 360 - step`` degrees."""
        return self._headings

    @property
    def colors(self) -> ColorClasses | None:
        """The colour classes, or ``None`` before :meth:`fit_colors`."""
        return self._colors

    @property
    def frames_learned(self) -> int:
        """Number of frames added to the map by :meth:`learn`."""
        return self._frames

    @property
    def sector_observations(self) -> np.ndarray:
        """How many learned frames saw each sector (copy), shape ``(n_sectors,)``."""
        return self._n_obs.astype(np.int64)

    @property
    def learned_fraction(self) -> float:
        """Fraction of the full circle covered by at least one learned frame."""
        return float(np.mean(self._n_obs > 0))

    @property
    def is_learned(self) -> bool:
        """True once colour classes exist and at least one frame was learned."""
        return self._colors is not None and self._frames > 0

    # ------------------------------------------------------------------ colours
    def _set_colors(self, colors: ColorClasses) -> None:
        if not isinstance(colors, ColorClasses):
            raise ValueError(f"colors must be a ColorClasses, got {type(colors).__name__}")
        if colors.n_colors != self.config.n_colors:
            raise ValueError(
                f"colors has {colors.n_colors} classes but config.n_colors is "
                f"{self.config.n_colors}"
            )
        self._colors = colors
        if colors.exposure_reference > 0:  # fitted with exposure normalisation
            self._exposure_ref = colors.exposure_reference

    def fit_colors(
        self,
        images: Sequence[np.ndarray],
        rng: np.random.Generator | None = None,
        *,
        reset_map: bool = False,
        max_samples: int = 20000,
    ) -> VisualCompass:
        """Learn the colour classes from sample images (paper 3.4, eq. 7-8).

        Parameters
        ----------
        images : sequence of numpy.ndarray
            ``(H, W, 3)`` uint8 RGB images of the environment.
        rng : numpy.random.Generator, optional
            Source of the pixel subsample and k-means++ seeds (default: seed 0).
        reset_map : bool
            A learned map is only valid for the classes it was learned with, so
            refitting the classes of a compass that has learned frames is an error
            unless ``reset_map=True``, which also clears the map.
        max_samples : int
            Pixels used for EM.

        Returns
        -------
        VisualCompass
            ``self``, for chaining.
        """
        if self._frames > 0 and not reset_map:
            raise ValueError(
                "this compass has already learned a map with its colour classes; "
                "pass reset_map=True to refit the classes and clear the map"
            )
        if isinstance(images, np.ndarray) and images.ndim == 3:
            images = [images]
        images = [check_image(im, f"images[{i}]") for i, im in enumerate(images)]
        if not images:
            raise ValueError("fit_colors needs at least one image")
        ref = 0.0
        if self.config.exposure in REFERENCE_EXPOSURES:
            # reference level from the upper halves (what the compass scans at pitch 0)
            levels = [mean_linear_level(im[: max(im.shape[0] // 2, 1)]) for im in images]
            ref = float(np.mean(levels))
            if ref <= 0:
                raise ValueError(
                    f"exposure={self.config.exposure!r} needs colour-fitting images that are "
                    "not black"
                )
        if self.config.exposure == "mean":
            images = [
                self._apply_gain(im[: max(im.shape[0] // 2, 1)], lvl, ref)
                for im, lvl in zip(images, levels, strict=True)
            ]
        colors = ColorClasses.fit(
            images,
            n_colors=self.config.n_colors,
            rng=rng,
            bits=self.config.lut_bits,
            max_samples=max_samples,
        )
        colors.exposure_reference = ref
        self._exposure_ref = ref
        self._set_colors(colors)
        if reset_map:
            self.reset_map()
        return self

    def reset_map(self) -> None:
        """Forget every learned frame (keeps the colour classes)."""
        self._counts[:] = 0
        self._n_obs[:] = 0
        self._light.clear()
        self._frames = 0
        self._sizes.clear()
        self._tables = None

    # ------------------------------------------------------------------ features
    def _geometry(self, camera: Camera, width: int, height: int) -> _Geometry:
        key = (width, height, camera.hfov_deg, camera.pitch_deg, camera.principal_point)
        geom = self._geom_cache.get(key)
        if geom is not None:
            self._geom_cache.move_to_end(key)
            return geom
        cfg = self.config
        row_step, col_step = cfg.grid_steps
        grid = scan_grid(camera, width, height, row_step, col_step)
        if grid.rows.size:
            row_slice = slice(int(grid.rows[0]), int(grid.rows[-1]) + 1, row_step)
        else:
            row_slice = slice(0, 0)
        col_slice = slice(int(grid.cols[0]), width, col_step)
        delta = cfg.sector_deg
        s_total = cfg.n_sectors
        # heading = s0 * delta + phase, 0 <= phase < delta; a column at offset r then
        # falls into sector s0 + floor((phase + r) / delta)
        hs = self._headings
        s0 = np.floor(hs / delta + 1e-9).astype(np.int64)
        phase = np.round(hs - s0 * delta, 9)
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
        geom = _Geometry(
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
        self._geom_cache[key] = geom
        if len(self._geom_cache) > _CACHE_SIZE:
            self._geom_cache.popitem(last=False)
        return geom

    @staticmethod
    def _apply_gain(pixels: np.ndarray, level: float, ref: float) -> np.ndarray:
        """Scale linear light so that a frame at ``level`` comes out at ``ref``."""
        if level <= 0:
            return pixels
        return np.take(gain_table(ref / level), pixels)

    def _scanned_classes(self, pixels: np.ndarray, gain: float = 1.0) -> np.ndarray:
        """``(R, U)`` class ids of the scanned ``pixels`` after the exposure correction:
        ``exposure="mean"`` scales the frame to the reference level, otherwise the
        linear light is multiplied by ``gain``."""
        assert self._colors is not None
        if self.config.exposure == "mean":
            pixels = self._apply_gain(pixels, mean_linear_level(pixels), self._exposure_ref)
        elif gain != 1.0:
            pixels = np.take(gain_table(gain), pixels)
        return self._colors.classify_pixels(pixels)

    def _column_counts(self, classes: np.ndarray) -> np.ndarray:
        return column_transition_counts(classes, self.config.n_colors, self.config.count_same_class)

    def _checked(self, image: np.ndarray, camera: Camera, need_map: bool) -> None:
        check_image(image)
        if not isinstance(camera, Camera):
            raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
        if self._colors is None:
            raise NotLearnedError("no colour classes yet: call fit_colors(images) first")
        if need_map and self._frames == 0:
            raise NotLearnedError("the map is empty: learn(image, camera) at least one frame")
        size = image.shape[:2]
        if need_map and size not in self._sizes and size[::-1] in self._sizes:
            raise ValueError(
                f"image of shape {image.shape} looks transposed: the map was learned from "
                f"{size[1]}x{size[0]} (HxW) frames; pass (H, W, 3) arrays"
            )

    # ------------------------------------------------------------------ learning
    def learn(self, image: np.ndarray, camera: Camera) -> int:
        """Add one frame seen at the known ``camera.yaw_deg`` to the map (eq. 6).

        Only the sectors in the camera's view are updated: each gets one count in
        the bin its relative frequency (eq. 11) falls in, for every class pair.

        Returns
        -------
        int
            Number of sectors updated (0 if nothing above the horizon is visible).

        Raises
        ------
        ValueError
            On an invalid image or camera, or a frame of a new size when the map has
            learned :data:`MAX_LEARNED_SIZES` sizes (its file could not be loaded).
        """
        self._checked(image, camera, need_map=False)
        h, w = image.shape[:2]
        _check_sizes(self._sizes | {(h, w)})
        geom = self._geometry(camera, w, h)
        pixels = image[geom.row_slice, geom.col_slice]
        colcounts = self._column_counts(self._scanned_classes(pixels))
        cfg = self.config
        sector = (
            np.floor((camera.yaw_deg + geom.grid.offsets_deg) / cfg.sector_deg + 1e-9).astype(
                np.int64
            )
            % cfg.n_sectors
        )
        c2 = colcounts.shape[1]
        flat = (sector[:, None] * c2 + np.arange(c2)[None, :]).ravel()
        counts = np.bincount(flat, weights=colcounts.ravel(), minlength=cfg.n_sectors * c2).reshape(
            cfg.n_sectors, c2
        )
        total = counts.sum(axis=1)
        seen = np.flatnonzero(total > 0)
        if seen.size == 0:
            return 0
        z = counts[seen] / total[seen, None]
        bins = log2_bin(z, cfg.n_bins)
        self._counts[seen[:, None], np.arange(c2)[None, :], bins] += 1.0
        self._n_obs[seen] += 1.0
        if cfg.exposure == "map":
            self._light.add(sector, column_levels(pixels))
        self._frames += 1
        self._sizes.add((h, w))
        self._tables = None
        return int(seen.size)

    def merge(self, other: VisualCompass) -> VisualCompass:
        """Add the map of ``other`` to this one (in place; returns ``self``).

        A map is counts (eq. 6), so the map learned from two sets of frames is the sum of
        their maps: merging the turns learned at several places near a spot gives the map
        of all their frames. Both compasses must share the config and the colour classes
        (learn the second with the first's :attr:`colors`).

        Raises
        ------
        ValueError
            If the configs or colour classes differ, ``other`` is not a compass, or
            together they learned frames of more than :data:`MAX_LEARNED_SIZES` sizes.
        """
        if not isinstance(other, VisualCompass):
            raise ValueError(f"can only merge a VisualCompass, got {type(other).__name__}")
        if other.config != self.config:
            raise ValueError("cannot merge maps learned with different CompassConfigs")
        if not self.shares_colors(other):
            raise ValueError("cannot merge maps learned with different colour classes")
        _check_sizes(self._sizes | other._sizes)
        self._counts += other._counts
        self._n_obs += other._n_obs
        self._light.merge(other._light)
        self._frames += other._frames
        self._sizes |= other._sizes
        self._tables = None
        return self

    def shares_colors(self, other: VisualCompass) -> bool:
        """True if both compasses classify pixels with the same colour classes (then
        their maps count the same transitions and may be added or compared)."""
        return (
            self._colors is not None
            and other._colors is not None
            and _same_colors(self._colors, other._colors)
        )

    @property
    def map_counts(self) -> np.ndarray:
        """The map ``m[sector, i·c + j, bin]`` (eq. 6) as a read-only view.

        Shape ``(n_sectors, n_colors², n_bins)``; ``float64`` counts of learned frames.
        """
        view = self._counts.view()
        view.setflags(write=False)
        return view

    def sector_log_probabilities(self) -> np.ndarray:
        """Smoothed ``log p(bin | sector, i→j)`` of the map (the terms of eq. 5, 16).

        Returns
        -------
        numpy.ndarray
            ``(n_sectors, n_colors², n_bins)`` copy; every row sums to 1 in
            probability. A sector never seen gives the pooled histograms of all sectors.
        """
        return self._log_tables()[2].copy()

    def resampled(self, source: np.ndarray) -> VisualCompass:
        """A new compass whose sector ``s`` holds a copy of the map of sector
        ``source[s]`` (the inverse direction of :meth:`regrouped`: every sector gets
        exactly one source, so none is left unseen).

        :mod:`vc_gym.compass.parallax` uses it to re-draw a map learned elsewhere for
        the spot (each spot sector takes the sector in which the other place saw the
        same wall point). Colours, exposure reference and frame count are kept.

        Raises
        ------
        ValueError
            If ``source`` is not ``(n_sectors,)`` integers in ``[0, n_sectors)``.
        """
        source = self._checked_sectors("source", source)
        out = self._like()
        out._counts = self._counts[source]
        out._n_obs = self._n_obs[source]
        out._light.level_sum = self._light.level_sum[source]
        out._light.columns = self._light.columns[source]
        return out

    def _checked_sectors(self, name: str, sectors: np.ndarray, rows: bool = False) -> np.ndarray:
        """``sectors`` as an integer array of map sectors: ``(n_sectors,)``, or
        ``(N, n_sectors)`` with ``rows``; a clear ``ValueError`` otherwise."""
        n = self.config.n_sectors
        sectors = np.asarray(sectors)
        shape = f"(N, {n})" if rows else f"({n},)"
        if (
            sectors.ndim != (2 if rows else 1)
            or sectors.shape[-1] != n
            or not np.issubdtype(sectors.dtype, np.integer)
        ):
            raise ValueError(
                f"{name} must be an integer array of shape {shape}, got "
                f"{sectors.dtype} {sectors.shape}"
            )
        if sectors.size and (sectors.min() < 0 or sectors.max() >= n):
            raise ValueError(
                f"{name} sectors must lie in [0, {n}), got {sectors.min()}..{sectors.max()}"
            )
        return sectors

    def _like(self) -> VisualCompass:
        """An empty map with this one's config, colours, exposure, frames and sizes."""
        out = VisualCompass(self.config, self._colors)
        out._exposure_ref = self._exposure_ref
        out._frames = self._frames
        out._sizes = set(self._sizes)
        return out

    def regrouped(self, target: np.ndarray) -> VisualCompass:
        """A new compass whose sector ``t`` holds the map of every sector ``s`` with
        ``target[s] == t`` (counts added; eq. 6 is a sum, so this is the map the same
        frames would have given had each sector looked in direction ``t``).

        This is how a map learned at one place is re-drawn for another
        (:mod:`vc_gym.compass.parallax`): each sector moves to the direction its wall
        point has from the new place. Sectors no source lands on stay unseen. Colours,
        exposure reference, light map and frame count are kept.

        Parameters
        ----------
        target : numpy.ndarray
            ``(n_sectors,)`` integers in ``[0, n_sectors)``.

        Raises
        ------
        ValueError
            If ``target`` has another shape, is not integer or is out of range.
        """
        n = self.config.n_sectors
        target = self._checked_sectors("target", target)
        out = self._like()
        np.add.at(out._counts, target, self._counts)
        out._n_obs = np.bincount(target, weights=self._n_obs, minlength=n).astype(np.float64)
        out._light.level_sum = np.bincount(target, weights=self._light.level_sum, minlength=n)
        out._light.columns = np.bincount(target, weights=self._light.columns, minlength=n)
        return out

    # ------------------------------------------------------------------ likelihood
    def _log_tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(delta_t, base, log_abs)`` for the current map (cached until it changes).

        ``log_abs[s, ij, b]`` is the smoothed log-probability of bin ``b``;
        ``ratio = log_abs - log_pool``; ``base[s]`` sums the ratio of the empty bin
        over all pairs and ``delta_t[ij * n + b, s]`` is the ratio minus that of the
        empty bin, so that only non-zero frequencies need a table read.
        """
        if self._tables is not None:
            return self._tables
        cfg = self.config
        n = cfg.n_bins
        counts = self._counts
        pooled = counts.sum(axis=0) + _POOL_PSEUDOCOUNT  # (c2, n)
        p_pool = pooled / pooled.sum(axis=1, keepdims=True)
        kappa = cfg.smoothing
        # in place where the result replaces its input: a map-sized array costs
        # 8 bytes per count, and at most two live beside the counts and delta_t
        # (CompassConfig.memory_bytes)
        log_abs = counts + kappa * p_pool[None]
        log_abs /= self._n_obs[:, None, None] + kappa
        np.log(log_abs, out=log_abs)
        delta = log_abs - np.log(p_pool)[None]  # the log-ratio against the pooled model
        last = delta[:, :, n - 1 : n].copy()
        base = last[:, :, 0].sum(axis=1)  # (S,)
        delta -= last  # (S, c2, n)
        delta_t = np.ascontiguousarray(delta.reshape(delta.shape[0], -1).T)  # (c2*n, S)
        del delta
        self._tables = (delta_t, base, log_abs)
        return self._tables

    def _sector_features(
        self, image: np.ndarray, camera: Camera, gain: float = 1.0
    ) -> tuple[_Geometry, np.ndarray, np.ndarray]:
        """Counts per (phase, relative sector, pair) and which of them saw anything.

        A frame without a single change of colour class above the horizon (a black,
        covered or overexposed frame, a blank wall) says nothing about the heading: it
        gives no counts at all, so it is treated like a frame that sees nothing above
        the horizon (a flat log-likelihood), not as a confident match of the maps'
        "no change" statistics. So does a frame of noise, whose classes change between
        neighbours as often as those of independent pixels
        (:data:`~vc_gym.compass.features.NOISE_CHANGE_RATIO`): its transitions are
        chance, and matched against the maps they would still pick some heading
        confidently.
        """
        h, w = image.shape[:2]
        geom = self._geometry(camera, w, h)
        return (geom, *self._features_of(image[geom.row_slice, geom.col_slice], geom, gain))

    def _features_of(
        self, pixels: np.ndarray, geom: _Geometry, gain: float = 1.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(counts, total)`` of :meth:`_sector_features` from the scanned pixels."""
        classes = self._scanned_classes(pixels, gain)
        colcounts = self._column_counts(classes)
        ratio = change_ratio(classes, self.config.n_colors)
        if ratio == 0.0 or ratio >= NOISE_CHANGE_RATIO:  # no class change at all, or noise
            colcounts = np.zeros_like(colcounts)
        # integer counts in float32: the cumulative sums and their differences are exact
        cum = np.zeros((colcounts.shape[0] + 1, colcounts.shape[1]), dtype=colcounts.dtype)
        np.cumsum(colcounts, axis=0, out=cum[1:])
        counts = cum[geom.stop_col] - cum[geom.first_col]  # (P*K, c2)
        total = counts.sum(axis=1)
        return counts, total

    def _light_profile(
        self, image: np.ndarray, camera: Camera
    ) -> tuple[np.ndarray, tuple[_Geometry, np.ndarray, np.ndarray], int]:
        """``exposure="map"``: log-likelihood over headings, each heading's features
        classified with the gain that brings the frame to the light the map learned in
        the directions that heading puts in view (see :mod:`vc_gym.compass.light_map`).

        Returns the log-likelihoods, and the sector features and the gain (in steps of
        :data:`~vc_gym.compass.light_map.GAIN_STEP_STOPS`) of the best heading.
        """
        h, w = image.shape[:2]
        geom = self._geometry(camera, w, h)
        pixels = image[geom.row_slice, geom.col_slice]
        gains = self._light.heading_gains(
            column_levels(pixels),
            geom.first_col,
            geom.stop_col,
            geom.n_rel,
            geom.heading_phase,
            geom.roll_index[:, geom.heading_sector],
        )
        steps = quantized_stops(gains)
        ll = np.empty(steps.size)
        # only the features of the best heading so far are kept (a frame has 5-15
        # gains, each a (phases x sectors in view x pairs) array); the best is the
        # first heading of the largest log-likelihood, as numpy.argmax finds it
        best, best_at, best_features = 0, steps.size, None
        for k in np.unique(steps).tolist():
            features = self._features_of(pixels, geom, 2.0 ** (k * GAIN_STEP_STOPS))
            at = np.flatnonzero(steps == k)
            ll[at] = self._log_likelihood_of(geom, *features)[at]
            first = int(at[np.argmax(ll[at])])
            if best_features is None or (ll[first], -first) > (ll[best_at], -best_at):
                best, best_at, best_features = k, first, features
        assert best_features is not None
        return ll, (geom, *best_features), best

    def log_likelihood(
        self, image: np.ndarray, camera: Camera, gain: float | None = None
    ) -> np.ndarray:
        """Log-likelihood of every candidate heading for one image (eq. 5, 15-16).

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W, 3)`` uint8 RGB camera image.
        camera : Camera
            Intrinsics and pitch of the camera; its ``yaw_deg`` is ignored.
        gain : float, optional
            Multiply the image's linear light by this before classifying it (a light
            level known for the whole session: a
            :class:`~vc_gym.exposure.SessionLight` of :meth:`frame_gain` with
            ``exposure="session"``, the median of :meth:`light_gain` with ``"map"``).
            Not with ``exposure="mean"``, which sets its own gain. The default is 1,
            except with ``"map"`` (a gain per candidate heading) and with
            ``"session"`` (the frame's own :meth:`frame_gain`, rounded to a third of a
            stop: a session of one frame).

        Returns
        -------
        numpy.ndarray
            ``float64`` array over :attr:`headings_deg`: ``log p(image | φ, m)`` up to
            a constant that does not depend on ``φ`` (see class notes), divided by
            ``config.temperature``. All zeros if nothing above the horizon is visible.
        """
        self._checked(image, camera, need_map=True)
        gain = self._checked_gain(gain)
        if gain is None and self.config.exposure == "map":
            return self._light_profile(image, camera)[0]
        return self._log_likelihood_of(
            *self._sector_features(image, camera, self._gain_for(image, camera, gain))
        )

    def _log_likelihood_of(
        self, geom: _Geometry, counts: np.ndarray, total: np.ndarray
    ) -> np.ndarray:
        """Log-likelihood over headings from sector features (see log_likelihood)."""
        delta_t, base, _ = self._log_tables()
        return _log_likelihoods_of(
            self.config, geom, counts, total, delta_t[:, None, :], base[None]
        )[0]

    def log_likelihood_remapped(
        self,
        image: np.ndarray,
        camera: Camera,
        sector_maps: np.ndarray,
        gain: float | None = None,
    ) -> np.ndarray:
        """Log-likelihood over headings for each of several re-indexings of the map.

        Row ``n`` of ``sector_maps`` says, for every direction sector ``s`` the camera
        may look into, which sector of the map describes what it sees there; the
        identity gives :meth:`log_likelihood` bit for bit. A map learned at one place
        scores a camera at another this way, with each row the parallax of one
        candidate position (:meth:`vc_gym.compass.parallax.ParallaxMap.pose_log_likelihood`).
        The frame's features are extracted once; every further row costs one gather.

        Parameters
        ----------
        image, camera, gain
            As for :meth:`log_likelihood`; not with ``exposure="map"``, whose gain per
            heading belongs to the map's own sectors.
        sector_maps : numpy.ndarray
            ``(N, n_sectors)`` integers in ``[0, n_sectors)``.

        Returns
        -------
        numpy.ndarray
            ``(N, n_headings)`` float64: row ``n`` is eq. 5, 16 with sector ``s`` of the
            view scored against map sector ``sector_maps[n, s]``.
        """
        self._checked(image, camera, need_map=True)
        if self.config.exposure == "map":
            raise ValueError('log_likelihood_remapped does not support exposure="map"')
        remap = self._checked_sectors("sector_maps", sector_maps, rows=True)
        gain = self._checked_gain(gain)
        geom, counts, total = self._sector_features(
            image, camera, self._gain_for(image, camera, gain)
        )
        delta_t, base, _ = self._log_tables()
        per_group = _group_scores(self.config, geom, counts, total, delta_t[:, None, :], base[None])
        if per_group is None:
            return np.zeros((remap.shape[0], geom.heading_phase.size))
        idx = remap[:, geom.roll_index]  # (N, K, S): map sector of relative k at start s0
        k = np.arange(geom.n_rel)[None, :, None]
        by_start = per_group[:, k, 0, idx].sum(axis=2)  # (P, N, S)
        return _by_heading(self.config, geom, by_start.transpose(2, 0, 1))

    def estimate(
        self, image: np.ndarray, camera: Camera, gain: float | None = None
    ) -> CompassEstimate:
        """Best heading, its spread and the goodness of fit for one image.

        See :class:`CompassEstimate` for the meaning of each number (eq. 25-28) and
        :meth:`log_likelihood` for ``gain``.
        """
        self._checked(image, camera, need_map=True)
        gain = self._checked_gain(gain)
        if gain is None and self.config.exposure == "map":
            ll, features, _ = self._light_profile(image, camera)
            return _estimates_of([self], *features, ll[None])[0]
        return self._estimate_of(
            *self._sector_features(image, camera, self._gain_for(image, camera, gain))
        )

    def frame_gain(self, image: np.ndarray, camera: Camera) -> float:
        """The gain ``exposure="mean"`` applies to this frame (beyond the paper).

        The reference level (the colour-fitting images') divided by the mean linear
        level of the pixels the compass scans; ``inf`` for a black frame. One frame's
        gain reads what it shows as much as the light; a
        :class:`~vc_gym.exposure.SessionLight` over a session's frames reads the light.
        Needs ``exposure="mean"`` or ``"session"``.
        """
        if self.config.exposure not in REFERENCE_EXPOSURES:
            raise ValueError(
                f"frame_gain needs exposure='mean' or 'session', not {self.config.exposure!r}"
            )
        self._checked(image, camera, need_map=False)
        if self._colors is None:
            raise NotLearnedError("call fit_colors() before frame_gain()")
        h, w = image.shape[:2]
        geom = self._geometry(camera, w, h)
        level = mean_linear_level(image[geom.row_slice, geom.col_slice])
        return self._exposure_ref / level if level > 0 else math.inf

    def _gain_for(self, image: np.ndarray, camera: Camera, gain: float | None) -> float:
        """The gain a checked ``gain`` argument means: itself, or without one 1, except
        with ``exposure="session"``, where a frame without a session is its own: its
        :meth:`frame_gain` rounded to :data:`~vc_gym.exposure.GAIN_STEP_STOPS`."""
        if gain is not None:
            return gain
        if self.config.exposure == "session":
            return rounded_gain(self.frame_gain(image, camera))
        return 1.0

    def light_gain(self, image: np.ndarray, camera: Camera) -> float:
        """``exposure="map"``: the gain that brings this frame to the learned light.

        It is the gain of the heading that fits best when every heading is scored with
        its own gain (see :meth:`log_likelihood`), in steps of a third of a stop. One
        frame's answer is wrong when its best heading is; the median over the frames
        of a session is a robust estimate of the session's light (pass it as ``gain``).
        """
        if self.config.exposure != "map":
            raise ValueError(f"light_gain needs exposure='map', not {self.config.exposure!r}")
        self._checked(image, camera, need_map=True)
        return float(2.0 ** (self._light_profile(image, camera)[2] * GAIN_STEP_STOPS))

    def _checked_gain(self, gain: float | None) -> float | None:
        if gain is None:
            return None
        if self.config.exposure == "mean":
            raise ValueError("exposure='mean' sets its own gain per frame: pass gain=None")
        return positive_float("gain", gain)

    def _estimate_of(
        self, geom: _Geometry, counts: np.ndarray, total: np.ndarray
    ) -> CompassEstimate:
        """:meth:`estimate` from sector features."""
        ll = self._log_likelihood_of(geom, counts, total)
        return _estimates_of([self], geom, counts, total, ll[None])[0]

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | os.PathLike) -> Path:
        """Save config, colour classes and map to an ``.npz`` file, atomically.

        Returns the path written (``.npz`` appended if missing).
        """
        return save_npz_atomic(path, MAP_SCHEMA, MAP_SCHEMA_VERSION, self.to_arrays())

    def to_arrays(self, with_colors: bool = True) -> dict[str, np.ndarray]:
        """Config, map and (unless ``with_colors=False``) colour classes as plain arrays.

        What :meth:`save` writes and :meth:`from_arrays` reads; a
        :class:`~vc_gym.compass.CompassAtlas` stores shared colour classes once.
        """
        if self._colors is None:
            raise NotLearnedError("nothing to save: the compass has no colour classes yet")
        arrays = {
            "config": json_array(self.config.to_dict()),
            "counts": self._counts.astype(np.uint32),
            "sector_observations": self._n_obs.astype(np.uint32),
            "frames_learned": np.array(self._frames, dtype=np.int64),
            "exposure_reference": np.array(self._exposure_ref, dtype=np.float64),
            "learned_sizes": np.array(sorted(self._sizes), dtype=np.int64).reshape(-1, 2),
        }
        if self.config.exposure == "map":
            arrays["light_sum"] = self._light.level_sum.copy()
            arrays["light_columns"] = self._light.columns.copy()
        if with_colors:
            arrays.update(self._colors.to_arrays())
        return arrays

    @classmethod
    def load(cls, path: str | os.PathLike, config: CompassConfig | None = None) -> VisualCompass:
        """Load a compass saved by :meth:`save`.

        Parameters
        ----------
        path : path-like
            The ``.npz`` file.
        config : CompassConfig, optional
            If given, the file's config must equal it (guards against mixing maps
            learned with other parameters).

        Raises
        ------
        MapFileError
            Missing, empty, truncated or corrupt file, another schema or version,
            or arrays whose shapes do not match the stored config.
        """
        arrays = load_npz_checked(path, MAP_SCHEMA, MAP_SCHEMA_VERSION)
        return cls.from_arrays(arrays, path, config)

    @classmethod
    def from_arrays(
        cls,
        arrays: Mapping[str, np.ndarray],
        source: str | os.PathLike,
        config: CompassConfig | None = None,
        colors: ColorClasses | None = None,
    ) -> VisualCompass:
        """Rebuild a compass from :meth:`to_arrays` output, checking every entry.

        Parameters
        ----------
        arrays : mapping
            The arrays (e.g. read from an ``.npz`` file).
        source : path-like
            Named in error messages (the file the arrays came from).
        config : CompassConfig, optional
            If given, the stored config must equal it.
        colors : ColorClasses, optional
            Colour classes to use instead of reading them from ``arrays``.

        Raises
        ------
        MapFileError
            Naming ``source`` and the entry at fault.
        """
        path = source
        raw = read_json_array(arrays, "config", path)
        try:
            stored = CompassConfig.from_dict(raw)  # type: ignore[arg-type]
        except (TypeError, ValueError) as e:
            raise MapFileError(f"{path}: invalid config ({e})") from None
        if config is not None and stored != config:
            raise MapFileError(f"{path}: was learned with {stored}, expected {config}")
        if colors is None:
            try:
                colors = ColorClasses.from_arrays(arrays)
            except ValueError as e:
                raise MapFileError(f"{path}: invalid colour classes ({e})") from None
        vc = cls(stored, colors)
        expect = {
            "counts": vc._counts.shape,
            "sector_observations": vc._n_obs.shape,
            "frames_learned": (),
        }
        for key, shape in expect.items():
            if key not in arrays:
                raise MapFileError(f"{path}: missing entry {key!r}")
            a = arrays[key]
            if a.shape != shape or a.dtype.kind not in "iu":
                raise MapFileError(
                    f"{path}: entry {key!r} has shape {a.shape} and dtype {a.dtype}, "
                    f"expected integer counts of shape {shape} for {stored}"
                )
        # checked as stored and copied straight into the compass' float64 map: a
        # float64 copy of its own would add 8 bytes per count to the peak of loading
        counts = arrays["counts"]
        n_obs = arrays["sector_observations"].astype(np.float64)
        if np.any(counts < 0) or np.any(n_obs < 0):
            raise MapFileError(f"{path}: negative counts")
        # every class pair of a sector gets exactly one count per frame that saw it
        per_pair = counts.sum(axis=2, dtype=np.float64)
        if not np.array_equal(per_pair, np.broadcast_to(n_obs[:, None], per_pair.shape)):
            raise MapFileError(f"{path}: counts do not add up to the sector observations")
        frames = int(arrays["frames_learned"])
        if frames < 0 or (frames == 0) != (n_obs.sum() == 0):
            raise MapFileError(f"{path}: frames_learned={frames} contradicts the counts")
        ref = arrays.get("exposure_reference")
        if (
            ref is None
            or ref.shape != ()
            or ref.dtype.kind not in "iuf"
            or not np.isfinite(ref)
            or not 0 <= ref <= MAX_LIGHT_LEVEL
        ):
            # a mean linear light level: 0 (not fitted with exposure) to 1 (white)
            raise MapFileError(
                f"{path}: entry 'exposure_reference' missing or not a light level in [0, 1]"
            )
        if stored.exposure in REFERENCE_EXPOSURES and ref <= 0:
            raise MapFileError(
                f"{path}: exposure={stored.exposure!r} but no reference level stored"
            )
        vc._exposure_ref = float(ref)
        sizes = arrays.get("learned_sizes")
        if (
            sizes is None
            or sizes.ndim != 2
            or sizes.shape[1] != 2
            or sizes.dtype.kind not in "iu"
            or np.any(sizes < 1)
        ):
            raise MapFileError(f"{path}: entry 'learned_sizes' missing or not an (N, 2) int array")
        if sizes.shape[0] > MAX_LEARNED_SIZES:
            raise MapFileError(
                f"{path}: entry 'learned_sizes' lists {sizes.shape[0]} frame sizes, more than "
                f"{MAX_LEARNED_SIZES}"
            )
        if stored.exposure == "map":
            _read_light(vc._light, arrays, path)
        vc._counts[:] = counts
        vc._n_obs[:] = n_obs
        vc._frames = frames
        vc._sizes = {(int(a), int(b)) for a, b in sizes}
        return vc

    def __repr__(self) -> str:
        return (
            f"VisualCompass(frames_learned={self._frames}, "
            f"learned={self.learned_fraction:.0%} of 360°, config={self.config})"
        )


def _log_likelihoods_of(
    config: CompassConfig,
    geom: _Geometry,
    counts: np.ndarray,
    total: np.ndarray,
    delta_t: np.ndarray,
    base: np.ndarray,
    maps: np.ndarray | None = None,
) -> np.ndarray:
    """Log-likelihood over headings (eq. 5, 15-16) of one frame under several maps.

    The maps share ``config`` and colour classes, so the frame's sector features
    (``geom``, ``counts``, ``total``) and which table rows they read are computed once;
    ``delta_t`` ``(c²·n, M, S)`` and ``base`` ``(M, S)`` are the maps' stacked log
    tables (:meth:`VisualCompass._log_tables`; rows first, so that one read brings a
    row of every map). Sums run in the same order for any ``M``, so each map's row
    equals its own :meth:`VisualCompass.log_likelihood` bit for bit. ``maps`` (indices
    into ``M``) scores only those maps, reading only their tables. Returns
    ``(M, n_headings)`` (``(len(maps), n_headings)``); all zeros where nothing was seen.
    """
    m = base.shape[0] if maps is None else len(maps)
    per_group = _group_scores(config, geom, counts, total, delta_t, base, maps)
    if per_group is None:
        return np.zeros((m, geom.heading_phase.size))
    # score[p, m, s0] = sum_k per_group[p, k, m, s0 + k + kmin]; the advanced indices
    # come first: (K, S, P, M), summed over K
    by_start = per_group[:, np.arange(geom.n_rel)[:, None], :, geom.roll_index].sum(axis=0)
    return _by_heading(config, geom, by_start)


def _by_heading(config: CompassConfig, geom: _Geometry, by_start: np.ndarray) -> np.ndarray:
    """``(X, n_headings)`` log-likelihoods from the scores ``by_start[s0, p, x]`` of
    every starting sector and phase (``X`` maps, or re-indexings of one map)."""
    ll = by_start[geom.heading_sector, geom.heading_phase].T
    if config.temperature != 1.0:
        ll = ll / config.temperature
    return np.ascontiguousarray(ll)


def _group_scores(
    config: CompassConfig,
    geom: _Geometry,
    counts: np.ndarray,
    total: np.ndarray,
    delta_t: np.ndarray,
    base: np.ndarray,
    maps: np.ndarray | None = None,
) -> np.ndarray | None:
    """``(P, K, M, S)``: the log-ratio of the frame's columns of phase ``p`` and relative
    sector ``k`` under sector ``s`` of map ``m`` (see :func:`_log_likelihoods_of`);
    ``None`` if the frame saw nothing."""
    if maps is not None:
        base = base[maps]
    m = base.shape[0]
    n = config.n_bins
    seen = total > 0
    if not seen.any():
        return None
    nz_group, nz_code = np.nonzero(counts)
    z = counts[nz_group, nz_code] / total[nz_group]
    rows = nz_code * n + log2_bin(z, n)
    per_group = _group_sums(delta_t, rows, nz_group, counts.shape[0], maps)
    per_group[seen] += base[None, :, :]
    return per_group.reshape(-1, geom.n_rel, m, config.n_sectors)


def _group_sums(
    delta_t: np.ndarray,
    rows: np.ndarray,
    groups: np.ndarray,
    n_groups: int,
    maps: np.ndarray | None,
) -> np.ndarray:
    """``out[g, m, s] = Σ delta_t[rows[e], maps[m], s]`` over the entries ``e`` of group
    ``g`` (``groups`` sorted, as :func:`numpy.nonzero` gives them); ``(n_groups, M, S)``.

    The rows are gathered a few whole groups at a time (:data:`_GATHER_BYTES`), so the
    gathered block stays in the cache. Each group is still one ``reduceat`` segment
    summed in order, so the sums are bit for bit those of a single gather, for any
    number of maps.
    """
    m = delta_t.shape[1] if maps is None else maps.size
    out = np.zeros((n_groups, m, delta_t.shape[2]))
    if rows.size == 0:
        return out
    starts = np.flatnonzero(np.r_[True, groups[1:] != groups[:-1]])
    bounds = np.r_[starts, rows.size]
    per_chunk = max(1, _GATHER_BYTES // (m * delta_t.shape[2] * delta_t.itemsize))
    i = 0
    while i < starts.size:
        # the groups that fit in per_chunk rows, at least one
        j = int(np.searchsorted(bounds, bounds[i] + per_chunk, side="right")) - 1
        j = min(max(j, i + 1), starts.size)
        a, b = bounds[i], bounds[j]
        if maps is None:
            gathered = np.take(delta_t, rows[a:b], axis=0)  # (E, M, S)
        else:
            gathered = delta_t[rows[a:b, None], maps[None, :]]
        out[groups[starts[i:j]]] = np.add.reduceat(gathered, starts[i:j] - a, axis=0)
        i = j
    return out


def _estimates_of(
    compasses: Sequence[VisualCompass],
    geom: _Geometry,
    counts: np.ndarray,
    total: np.ndarray,
    lls: np.ndarray,
) -> list[CompassEstimate]:
    """:class:`CompassEstimate` of one frame under each map, from its log-likelihoods.

    ``lls`` is ``(M, n_headings)`` (:func:`_log_likelihoods_of`). The best heading is
    refined by a parabola through the peak and its neighbours, the spread is the
    circular standard deviation of the posterior (eq. 27) and the score the mean
    per-term log-probability at the best heading (eq. 28), all computed for the ``M``
    maps at once.
    """
    first = compasses[0]
    headings = first._headings
    m = lls.shape[0]
    heading, best = peak_headings(lls, first.config.heading_step_deg)
    spread = circular_std_rows(headings, np.exp(lls - lls[np.arange(m), best][:, None]))
    scores, n_sectors = _scores_at(compasses, geom, counts, total, best)
    return [
        CompassEstimate(float(heading[k]), float(spread[k]), scores[k], n_sectors[k], lls[k])
        for k in range(m)
    ]


def _scores_at(
    compasses: Sequence[VisualCompass],
    geom: _Geometry,
    counts: np.ndarray,
    total: np.ndarray,
    best: np.ndarray,
) -> tuple[list[float], list[int]]:
    """Each map's goodness at its own best heading: the mean per-term log-probability
    of the frame's features (eq. 28) and the number of sectors used; the frame's bins
    are read once per heading phase."""
    cfg = compasses[0].config
    k_rel = geom.n_rel
    scores, used = [0.0] * len(compasses), [0] * len(compasses)
    phases = geom.heading_phase[best]
    for p in np.unique(phases):
        t = total[p * k_rel : (p + 1) * k_rel]
        seen = np.flatnonzero(t > 0)
        if seen.size == 0:
            continue
        c = counts[p * k_rel : (p + 1) * k_rel]
        bins = log2_bin(c[seen] / t[seen, None], cfg.n_bins)  # (seen, c2)
        pairs = np.arange(c.shape[1])[None, :]
        for k in np.flatnonzero(phases == p):
            log_abs = compasses[k]._log_tables()[2]
            sectors = (geom.heading_sector[best[k]] + seen + geom.kmin) % cfg.n_sectors
            scores[k] = float(log_abs[sectors[:, None], pairs, bins].mean())
            used[k] = int(seen.size)
    return scores, used


def _read_light(light: LightMap, arrays: Mapping[str, np.ndarray], path: object) -> None:
    """Fill ``light`` from a map file's ``light_sum`` and ``light_columns``, checked."""
    shape = light.level_sum.shape
    read = []
    for key in ("light_sum", "light_columns"):
        a = arrays.get(key)
        if a is None or a.shape != shape or a.dtype.kind not in "iuf":
            raise MapFileError(
                f"{path}: exposure='map' needs entry {key!r}: a number per sector, shape {shape}"
            )
        a = a.astype(np.float64)
        if not np.all(np.isfinite(a)) or np.any(a < 0):
            raise MapFileError(f"{path}: entry {key!r} must be finite and >= 0")
        read.append(a)
    level_sum, columns = read
    # every column's mean level is at most 1 (linear light)
    if np.any(level_sum > columns * (1 + 1e-9)):
        raise MapFileError(f"{path}: light_sum exceeds light_columns (levels above 1)")
    light.level_sum[:] = level_sum
    light.columns[:] = columns


def _check_sizes(sizes: set[tuple[int, int]]) -> None:
    """A ``ValueError`` if a map would remember more than :data:`MAX_LEARNED_SIZES`
    frame sizes (the loader refuses such a file)."""
    if len(sizes) > MAX_LEARNED_SIZES:
        raise ValueError(
            f"a map learns frames of at most {MAX_LEARNED_SIZES} different sizes; this one "
            f"would have {len(sizes)}"
        )


def _same_colors(a: ColorClasses, b: ColorClasses) -> bool:
    if a is b:
        return True
    x, y = a.to_arrays(), b.to_arrays()
    return x.keys() == y.keys() and all(np.array_equal(x[k], y[k]) for k in x)
