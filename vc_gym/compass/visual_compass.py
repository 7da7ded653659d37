"""The visual compass sensor model of Sturm & Visser (paper sections 3.1-3.4).

A :class:`VisualCompass` learns, at one spot, how often each colour-class transition
appears in each direction (a histogram map, eq. 1-2 and 6) and answers, for a new
camera image, a log-likelihood for every candidate heading (eq. 5, 15-16).

The class holds the map and checks its inputs; the work is done by one module per
concept: :mod:`~vc_gym.compass.scan_geometry` (which columns fall into which
sector), :mod:`~vc_gym.compass.sector_map` (how frames add to the map),
:mod:`~vc_gym.compass.likelihood` (features, log tables, log-likelihoods,
estimates), :mod:`~vc_gym.compass.calibration` (the temperature that calibrates the
heading spread), :mod:`~vc_gym.compass.light_gain` (the exposure correction) and
:mod:`~vc_gym.compass.map_files` (arrays and ``.npz`` files).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vc_gym.compass.calibration import (
    FLOOR_STEPS,
    MIN_CALIBRATION_FRAMES,
    MIN_COVERED_FRACTION,
    UNCALIBRATED,
    SpreadCalibration,
    calibration_report,
    check_spread_calibration,
    fit_temperature,
    heading_errors,
)
from vc_gym.compass.camera import Camera
from vc_gym.compass.colors import ColorClasses
from vc_gym.compass.config import CompassConfig
from vc_gym.compass.features import column_transition_counts
from vc_gym.compass.light_gain import (
    REFERENCE_EXPOSURES,
    color_fitting_levels,
    exposure_corrected,
    frame_gain_of,
    heading_gain_steps,
    profile_log_likelihood,
    scaled_to_reference,
    step_gain,
    upper_half,
)
from vc_gym.compass.light_map import LightMap
from vc_gym.compass.likelihood import (
    heading_estimates,
    log_likelihoods,
    log_tables,
    remapped_log_likelihoods,
    sector_features,
)

# the map file's constants, re-exported: importable from the compass' module too
from vc_gym.compass.map_files import MAP_SCHEMA as MAP_SCHEMA
from vc_gym.compass.map_files import MAP_SCHEMA_VERSION as MAP_SCHEMA_VERSION
from vc_gym.compass.map_files import MAX_LEARNED_SIZES as MAX_LEARNED_SIZES
from vc_gym.compass.map_files import (
    MapContents,
    check_learned_sizes,
    map_arrays,
    read_config_and_colors,
    read_map_contents,
    read_map_file,
    write_map_file,
)
from vc_gym.compass.scan_geometry import ScanGeometry, ScanGeometryCache, column_sectors
from vc_gym.compass.sector_map import add_frame, checked_sectors, regrouped_counts
from vc_gym.errors import NotLearnedError
from vc_gym.exposure import column_levels, rounded_gain
from vc_gym.images import check_image
from vc_gym.validation import positive_float

__all__ = ["VisualCompass", "CompassEstimate"]


@dataclass(frozen=True)
class CompassEstimate:
    """What the compass says about one image.

    Attributes
    ----------
    heading_deg : float
        Most likely heading in ``[0, 360)`` (arg-max of the log-likelihood, refined
        between grid points by a parabola through the peak and its neighbours).
    spread_deg : float
        Circular standard deviation ``sqrt(-2 ln R)`` (eq. 27) of the posterior
        ``∝ exp(log-likelihood / T)`` under a uniform prior, at least a floor, with the
        temperature ``T`` and the floor of the map's spread calibration
        (:attr:`VisualCompass.spread_temperature`, :meth:`VisualCompass.calibrate`;
        :mod:`~vc_gym.compass.calibration`). Calibrated, the true heading lies within
        ``±2 spread_deg`` of ``heading_deg`` for about 95 % of frames taken at the
        learning spot; uncalibrated (``T = 1``, no floor: the paper's eq. 16 as a
        product of independent terms) it is far too small. Small when one heading
        clearly wins, large when the image is ambiguous (a nearly flat posterior gives
        hundreds of degrees). ``inf`` exactly when :attr:`has_evidence` is false: the
        posterior is then uniform, its resultant length ``R`` is 0 and
        ``sqrt(-2 ln 0)`` infinite (a Kalman filter given it does not update).
    score : float
        Goodness of fit: the mean log-probability per term (sector × class pair) of
        the image's features under the map at the best heading, ``<= 0``. It is
        comparable between maps with the same config, so it serves as the per-spot
        goodness ``L`` of eq. 28 (``exp(score)`` is the geometric-mean likelihood
        per term).
    n_sectors : int
        Number of sectors the image contributed (about ``hfov / sector_deg``); ``0``
        when it shows no usable colour change, and then :attr:`has_evidence` is false,
        ``heading_deg`` is ``0.0``, ``spread_deg`` is ``inf`` and the log-likelihood is
        flat (all zeros).
    log_likelihood : numpy.ndarray
        The full log-likelihood over :attr:`VisualCompass.headings_deg`.
    """

    heading_deg: float
    spread_deg: float
    score: float
    n_sectors: int
    log_likelihood: np.ndarray = field(repr=False)

    @property
    def has_evidence(self) -> bool:
        """Whether the image said anything about the heading (``n_sectors > 0``); without
        evidence the estimate is a placeholder a filter should not update on."""
        return self.n_sectors > 0

    def __repr__(self) -> str:
        # the log-likelihood is one number per heading: its length says enough
        return (
            f"CompassEstimate(heading_deg={self.heading_deg:.2f}, "
            f"spread_deg={self.spread_deg:.2f}, score={self.score:.4f}, "
            f"n_sectors={self.n_sectors}, log_likelihood=<{len(self.log_likelihood)} headings>)"
        )


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
    >>> vc.calibrate(images, cameras, leave_one_out=True)       # doctest: +SKIP
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
        self._spread = UNCALIBRATED  # (temperature, floor_deg) of the heading spread
        h = np.arange(cfg.n_headings, dtype=np.float64) * cfg.heading_step_deg
        h.setflags(write=False)
        self._headings = h
        self._geometries = ScanGeometryCache(cfg, h)

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

    @property
    def spread_temperature(self) -> float:
        """Temperature ``T`` of the heading spread: :attr:`CompassEstimate.spread_deg` is
        the eq. 27 spread of ``exp(log-likelihood / T)``, floored at
        :attr:`spread_floor_deg` (:mod:`~vc_gym.compass.calibration`). 1 until
        :meth:`calibrate` or :meth:`set_spread_temperature`. It changes the spread only:
        :meth:`log_likelihood` and the heading are the same for every ``T``."""
        return self._spread[0]

    @property
    def spread_floor_deg(self) -> float:
        """Smallest :attr:`CompassEstimate.spread_deg` of a frame with evidence (degrees;
        0 until calibrated, half a heading step once calibrated)."""
        return self._spread[1]

    @property
    def is_spread_calibrated(self) -> bool:
        """Whether the spread has a calibration (fitted or set by hand)."""
        return self._spread != UNCALIBRATED

    def set_spread_temperature(self, temperature: float, floor_deg: float | None = None) -> None:
        """Set the spread's temperature by hand (and its floor: by default half a
        heading step, :data:`~vc_gym.compass.calibration.FLOOR_STEPS`).

        ``set_spread_temperature(1.0, 0.0)`` restores the uncalibrated (paper's) spread.

        Raises
        ------
        ValueError
            A temperature outside ``[0.01, 1000]`` or a floor outside ``[0, 90]`` degrees.
        """
        if floor_deg is None:
            floor_deg = FLOOR_STEPS * self.config.heading_step_deg
        self._spread = check_spread_calibration(temperature, floor_deg)

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
            levels = color_fitting_levels(images)
            ref = float(np.mean(levels))
            if ref <= 0:
                raise ValueError(
                    f"exposure={self.config.exposure!r} needs colour-fitting images that are "
                    "not black"
                )
        if self.config.exposure == "mean":
            images = [
                scaled_to_reference(upper_half(im), lvl, ref)
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
        """Forget every learned frame and the spread calibration (keeps the colour
        classes)."""
        self._spread = UNCALIBRATED
        self._counts[:] = 0
        self._n_obs[:] = 0
        self._light.clear()
        self._frames = 0
        self._sizes.clear()
        self._tables = None

    # ------------------------------------------------------------------ features
    def _geometry(self, camera: Camera, width: int, height: int) -> ScanGeometry:
        """The (cached) scan geometry of ``width`` x ``height`` frames of ``camera``."""
        return self._geometries.get(camera, width, height)

    def _scanned_classes(self, pixels: np.ndarray, gain: float = 1.0) -> np.ndarray:
        """``(R, U)`` class ids of the scanned ``pixels`` after the exposure correction:
        ``exposure="mean"`` scales the frame to the reference level, otherwise the
        linear light is multiplied by ``gain``."""
        assert self._colors is not None
        pixels = exposure_corrected(pixels, self.config.exposure, self._exposure_ref, gain)
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
        the bin its relative frequency (eq. 11) falls in, for every class pair. The spread
        calibration is left as it is: once the turn is learned,
        ``calibrate(images, cameras, leave_one_out=True)`` fits it to the learning frames.

        Returns
        -------
        int
            Number of sectors updated (0 if nothing above the horizon is visible).

        Raises
        ------
        ValueError
            On an invalid image or camera, or a frame of a new size when the map has
            learned :data:`~vc_gym.compass.map_files.MAX_LEARNED_SIZES` sizes (its
            file could not be loaded).
        """
        self._checked(image, camera, need_map=False)
        h, w = image.shape[:2]
        check_learned_sizes(self._sizes | {(h, w)})
        pixels, colcounts, sector = self._frame_columns(image, camera)
        seen = add_frame(self._counts, self._n_obs, colcounts, sector)
        if seen.size == 0:
            return 0
        if self.config.exposure == "map":
            self._light.add(sector, column_levels(pixels))
        self._frames += 1
        self._sizes.add((h, w))
        self._tables = None
        return int(seen.size)

    def _frame_columns(
        self, image: np.ndarray, camera: Camera
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What :meth:`learn` adds of a frame: its scanned pixels, the transition counts
        of each scanned column and the map sector each column looks into."""
        h, w = image.shape[:2]
        geom = self._geometry(camera, w, h)
        pixels = image[geom.row_slice, geom.col_slice]
        colcounts = self._column_counts(self._scanned_classes(pixels))
        cfg = self.config
        sector = column_sectors(
            camera.yaw_deg, geom.grid.offsets_deg, cfg.sector_deg, cfg.n_sectors
        )
        return pixels, colcounts, sector

    def _without_frame(self, image: np.ndarray, camera: Camera) -> VisualCompass | None:
        """A copy of this compass whose map lacks one learned frame (eq. 6 is a sum, so
        its counts are subtracted), or ``None`` if the frame adds nothing or the rest of
        the map saw fewer than :data:`~vc_gym.compass.calibration.MIN_COVERED_FRACTION`
        of its sectors.

        Raises
        ------
        ValueError
            If the map does not hold the frame (removing it leaves negative counts).
        """
        pixels, colcounts, sector = self._frame_columns(image, camera)
        counts = np.zeros_like(self._counts)
        n_obs = np.zeros_like(self._n_obs)
        seen = add_frame(counts, n_obs, colcounts, sector)
        if seen.size == 0:
            return None
        counts = self._counts - counts
        n_obs = self._n_obs - n_obs
        if np.any(counts < 0) or np.any(n_obs < 0):
            raise ValueError(
                f"the map does not hold the frame at yaw {camera.yaw_deg:g}°: leave_one_out "
                "needs frames this compass learned, with the cameras they were learned with"
            )
        if np.mean(n_obs[seen] > 0) < MIN_COVERED_FRACTION:
            return None
        out = self._empty_copy()
        out._counts, out._n_obs = counts, n_obs
        out._frames = self._frames - 1
        if self.config.exposure == "map":
            out._light.merge(self._light)
            mine = LightMap(self.config.n_sectors)
            mine.add(sector, column_levels(pixels))
            out._light.level_sum = np.maximum(out._light.level_sum - mine.level_sum, 0.0)
            out._light.columns = np.maximum(out._light.columns - mine.columns, 0.0)
        return out

    def calibrate(
        self,
        images: Sequence[np.ndarray],
        cameras: Sequence[Camera],
        *,
        leave_one_out: bool = False,
        floor_deg: float | None = None,
        gain: float | None = None,
    ) -> SpreadCalibration:
        """Fit the temperature of the heading spread to frames whose heading is known.

        Each frame is estimated (its camera's ``yaw_deg`` is the truth), and the
        temperature ``T`` is the one whose spreads best describe the errors (the
        Gaussian score of :func:`~vc_gym.compass.calibration.fit_temperature`), so that
        about 68 % and 95 % of true headings lie within one and two
        :attr:`CompassEstimate.spread_deg` of the estimate. ``T`` and the floor are
        kept (:attr:`spread_temperature`, saved with the map); the heading and the
        log-likelihood do not change.

        Parameters
        ----------
        images : sequence of numpy.ndarray
            ``(H, W, 3)`` uint8 RGB frames.
        cameras : sequence of Camera
            One per image, its ``yaw_deg`` the frame's true heading.
        leave_one_out : bool
            The frames are ones this map learned (a learning turn, with the cameras
            :meth:`learn` was given): each is estimated against the map without itself,
            a new view from the learning spot. Frames whose sectors the rest of the map
            mostly did not see (learning frames that do not overlap) are skipped. Without
            it the frames must be new to the map (learned frames would be estimated
            against themselves: far too small errors).
        floor_deg : float, optional
            Floor of the spread; default half a heading step
            (:data:`~vc_gym.compass.calibration.FLOOR_STEPS`).
        gain : float, optional
            As for :meth:`log_likelihood` (the session's light).

        Returns
        -------
        SpreadCalibration
            The temperature, the frames used and skipped, and the share of errors
            within one and two spreads on those frames.

        Raises
        ------
        ValueError
            Images and cameras of different lengths or invalid, a frame the map does
            not hold (``leave_one_out``), or fewer than
            :data:`~vc_gym.compass.calibration.MIN_CALIBRATION_FRAMES` frames usable.
        NotLearnedError
            If the map is empty.
        """
        if isinstance(images, np.ndarray) and images.ndim == 3:
            images = [images]
        if isinstance(cameras, Camera):
            cameras = [cameras]
        images, cameras = list(images), list(cameras)
        if len(images) != len(cameras):
            raise ValueError(f"got {len(images)} images but {len(cameras)} cameras")
        floor = FLOOR_STEPS * self.config.heading_step_deg if floor_deg is None else floor_deg
        _, floor = check_spread_calibration(1.0, floor)
        for image, camera in zip(images, cameras, strict=True):
            self._checked(image, camera, need_map=True)
        lls, truth, skipped = [], [], 0
        for image, camera in zip(images, cameras, strict=True):
            vc = self._without_frame(image, camera) if leave_one_out else self
            est = None if vc is None else vc.estimate(image, camera, gain=gain)
            if est is None or not est.has_evidence:
                skipped += 1
                continue
            lls.append(est.log_likelihood)
            truth.append(camera.yaw_deg)
        if len(lls) < MIN_CALIBRATION_FRAMES:
            why = (
                " (leave-one-out skips learning frames whose view no other learning frame "
                "saw: calibrate with held-out frames of known heading instead)"
                if leave_one_out
                else ""
            )
            raise ValueError(
                f"calibration needs at least {MIN_CALIBRATION_FRAMES} frames with evidence, "
                f"got {len(lls)} of {len(images)}{why}"
            )
        ll = np.array(lls)
        errors = heading_errors(ll, np.array(truth), self.config.heading_step_deg)
        temperature = fit_temperature(ll, errors, self._headings, floor)
        self._spread = (temperature, floor)
        return calibration_report(ll, errors, self._headings, temperature, floor, skipped)

    def merge(self, other: VisualCompass) -> VisualCompass:
        """Add the map of ``other`` to this one (in place; returns ``self``).

        A map is counts (eq. 6), so the map learned from two sets of frames is the sum of
        their maps: merging the turns learned at several places near a spot gives the map
        of all their frames. Both compasses must share the config and the colour classes
        (learn the second with the first's :attr:`colors`). This compass keeps its spread
        calibration, fitted to the map before the merge: :meth:`calibrate` again for the
        merged one.

        Raises
        ------
        ValueError
            If the configs or colour classes differ, ``other`` is not a compass, or
            together they learned frames of more than
            :data:`~vc_gym.compass.map_files.MAX_LEARNED_SIZES` sizes.
        """
        if not isinstance(other, VisualCompass):
            raise ValueError(f"can only merge a VisualCompass, got {type(other).__name__}")
        if other.config != self.config:
            raise ValueError("cannot merge maps learned with different CompassConfigs")
        if not self.shares_colors(other):
            raise ValueError("cannot merge maps learned with different colour classes")
        check_learned_sizes(self._sizes | other._sizes)
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
        source = checked_sectors("source", source, self.config.n_sectors)
        out = self._empty_copy()
        out._counts = self._counts[source]
        out._n_obs = self._n_obs[source]
        out._light = self._light.resampled(source)
        return out

    def _empty_copy(self) -> VisualCompass:
        """A compass with an empty map and this one's config, colours, exposure
        reference, spread calibration, frame count and frame sizes (the map is filled in
        by the caller)."""
        out = VisualCompass(self.config, self._colors)
        out._exposure_ref = self._exposure_ref
        out._spread = self._spread
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
        target = checked_sectors("target", target, self.config.n_sectors)
        out = self._empty_copy()
        out._counts, out._n_obs = regrouped_counts(self._counts, self._n_obs, target)
        out._light = self._light.regrouped(target)
        return out

    # ------------------------------------------------------------------ likelihood
    def _log_tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(delta_t, base, log_abs)`` of the current map
        (:func:`~vc_gym.compass.likelihood.log_tables`, cached until the map changes)."""
        if self._tables is None:
            self._tables = log_tables(self.config, self._counts, self._n_obs)
        return self._tables

    def _sector_features(
        self, image: np.ndarray, camera: Camera, gain: float = 1.0
    ) -> tuple[ScanGeometry, np.ndarray, np.ndarray]:
        """The frame's scan geometry and its counts per (phase, relative sector, pair)
        and their totals (:func:`~vc_gym.compass.likelihood.sector_features`)."""
        h, w = image.shape[:2]
        geom = self._geometry(camera, w, h)
        return (geom, *self._features_of(image[geom.row_slice, geom.col_slice], geom, gain))

    def _features_of(
        self, pixels: np.ndarray, geom: ScanGeometry, gain: float = 1.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(counts, total)`` of :meth:`_sector_features` from the scanned pixels."""
        return sector_features(self._scanned_classes(pixels, gain), geom, self.config)

    def _light_profile(
        self, image: np.ndarray, camera: Camera
    ) -> tuple[np.ndarray, tuple[ScanGeometry, np.ndarray, np.ndarray], int]:
        """``exposure="map"``: log-likelihood over headings, each heading's features
        classified with the gain that brings the frame to the light the map learned in
        the directions that heading puts in view (see :mod:`vc_gym.compass.light_gain`).

        Returns the log-likelihoods, and the sector features and the gain (in steps of
        :data:`~vc_gym.exposure.GAIN_STEP_STOPS`) of the best heading.
        """
        h, w = image.shape[:2]
        geom = self._geometry(camera, w, h)
        pixels = image[geom.row_slice, geom.col_slice]
        ll, best_features, best = profile_log_likelihood(
            heading_gain_steps(self._light, pixels, geom),
            lambda gain: self._features_of(pixels, geom, gain),
            lambda features: self._log_likelihood_of(geom, *features),
        )
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
        self, geom: ScanGeometry, counts: np.ndarray, total: np.ndarray
    ) -> np.ndarray:
        """Log-likelihood over headings from sector features (see log_likelihood)."""
        delta_t, base, _ = self._log_tables()
        lls = log_likelihoods(self.config, geom, counts, total, delta_t[:, None, :], base[None])
        return lls[0]

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
        remap = checked_sectors("sector_maps", sector_maps, self.config.n_sectors, rows=True)
        gain = self._checked_gain(gain)
        geom, counts, total = self._sector_features(
            image, camera, self._gain_for(image, camera, gain)
        )
        delta_t, base, _ = self._log_tables()
        return remapped_log_likelihoods(self.config, geom, counts, total, delta_t, base, remap)

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

    def _estimate_of(
        self, geom: ScanGeometry, counts: np.ndarray, total: np.ndarray
    ) -> CompassEstimate:
        """:meth:`estimate` from sector features."""
        ll = self._log_likelihood_of(geom, counts, total)
        return _estimates_of([self], geom, counts, total, ll[None])[0]

    # ------------------------------------------------------------------ light gain
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
        return frame_gain_of(image[geom.row_slice, geom.col_slice], self._exposure_ref)

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
        return step_gain(self._light_profile(image, camera)[2])

    def _checked_gain(self, gain: float | None) -> float | None:
        if gain is None:
            return None
        if self.config.exposure == "mean":
            raise ValueError("exposure='mean' sets its own gain per frame: pass gain=None")
        return positive_float("gain", gain)

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | os.PathLike) -> Path:
        """Save config, colour classes and map to an ``.npz`` file, atomically.

        Returns the path written (``.npz`` appended if missing).
        """
        return write_map_file(path, self.to_arrays())

    def to_arrays(self, with_colors: bool = True) -> dict[str, np.ndarray]:
        """Config, map and (unless ``with_colors=False``) colour classes as plain arrays.

        What :meth:`save` writes and :meth:`from_arrays` reads; a
        :class:`~vc_gym.compass.CompassAtlas` stores shared colour classes once.
        """
        if self._colors is None:
            raise NotLearnedError("nothing to save: the compass has no colour classes yet")
        contents = MapContents(
            counts=self._counts,
            sector_observations=self._n_obs,
            frames_learned=self._frames,
            exposure_reference=self._exposure_ref,
            learned_sizes=self._sizes,
            light=self._light,
            spread_calibration=self._spread,
        )
        return map_arrays(self.config, contents, self._colors if with_colors else None)

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
        return cls.from_arrays(read_map_file(path), path, config)

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
        stored, colors = read_config_and_colors(arrays, source, config, colors)
        vc = cls(stored, colors)
        contents = read_map_contents(arrays, source, stored)
        vc._exposure_ref = contents.exposure_reference
        if contents.light is not None:
            vc._light = contents.light
        vc._counts[:] = contents.counts
        vc._n_obs[:] = contents.sector_observations
        vc._frames = contents.frames_learned
        vc._sizes = contents.learned_sizes
        vc._spread = contents.spread_calibration
        return vc

    def __repr__(self) -> str:
        return (
            f"VisualCompass(frames_learned={self._frames}, "
            f"learned={self.learned_fraction:.0%} of 360°, config={self.config})"
        )


def _estimates_of(
    compasses: Sequence[VisualCompass],
    geom: ScanGeometry,
    counts: np.ndarray,
    total: np.ndarray,
    lls: np.ndarray,
) -> list[CompassEstimate]:
    """:class:`CompassEstimate` of one frame under each map, from its log-likelihoods.

    ``lls`` is ``(M, n_headings)`` (:func:`~vc_gym.compass.likelihood.log_likelihoods`);
    the numbers are those of :func:`~vc_gym.compass.likelihood.heading_estimates`,
    computed for the ``M`` maps at once.
    """
    first = compasses[0]
    log_abs = [vc._log_tables()[2] for vc in compasses]
    heading, spread, scores, n_sectors = heading_estimates(
        first.config,
        first._headings,
        log_abs,
        geom,
        counts,
        total,
        lls,
        [vc._spread for vc in compasses],
    )
    return [
        CompassEstimate(float(heading[k]), float(spread[k]), scores[k], n_sectors[k], lls[k])
        for k in range(lls.shape[0])
    ]


def _same_colors(a: ColorClasses, b: ColorClasses) -> bool:
    if a is b:
        return True
    x, y = a.to_arrays(), b.to_arrays()
    return x.keys() == y.keys() and all(np.array_equal(x[k], y[k]) for k in x)
