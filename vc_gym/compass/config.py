"""Configuration of the visual compass, with the paper's values as defaults."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

import numpy as np

from vc_gym.angles import MIN_HEADING_STEP_DEG, steps_in_circle
from vc_gym.compass.camera import AIBO_RESOLUTION
from vc_gym.persistence import MAX_ARRAY_BYTES

__all__ = [
    "CompassConfig",
    "EXPOSURE_MODES",
    "MAX_MAP_BYTES",
    "MAX_MAP_ENTRIES",
    "MAX_SMOOTHING",
    "MAX_TEMPERATURE",
    "MIN_COVERAGE",
    "MIN_SMOOTHING",
    "MIN_TEMPERATURE",
]

#: Accepted values of :attr:`CompassConfig.exposure`.
EXPOSURE_MODES = ("none", "mean", "map", "session")
#: Smallest scanning coverage (0.1 %); the paper reports that < 1 % still works.
MIN_COVERAGE = 0.001
#: Bytes a map file stores per count (``uint32``).
COUNT_BYTES = 4
#: Most counts a map may hold (``n_sectors · n_colors² · n_bins``): as many as fit in
#: the largest entry a map file may have (:data:`vc_gym.persistence.MAX_ARRAY_BYTES`,
#: 64 MiB of ``uint32``), so every map the compass saves can be loaded.
#: The paper's map holds 64,000; 1° sectors with 32 classes and 32 bins 11.8 million.
MAX_MAP_ENTRIES = MAX_ARRAY_BYTES // COUNT_BYTES
#: Most memory loading a map and scoring one frame with it may take, as
#: :meth:`CompassConfig.memory_bytes` reckons it for the widest camera: 512 MiB. The
#: largest maps (about 32 bytes per count) and the per-frame tables of a fine heading
#: grid against narrow sectors (phases × sectors in view × sectors) both grow far
#: beyond a map file's size, so a small file must not claim gigabytes.
MAX_MAP_BYTES = 512 * 2**20
#: Smallest :attr:`CompassConfig.temperature`: a frame's log-likelihoods range over a
#: few hundred across headings at 1, so below 0.01 every frame's posterior is a single
#: grid point, and far below the sums overflow.
MIN_TEMPERATURE = 0.01
#: Largest :attr:`CompassConfig.temperature`: above 1000 those ranges shrink below one
#: unit, and every frame's log-likelihood is all but flat: the map says nothing.
MAX_TEMPERATURE = 1000.0
#: Smallest :attr:`CompassConfig.smoothing` (pseudo-observations): an unseen bin keeps
#: at least about a thousandth of a frame's weight; near zero it becomes impossible
#: and one unusual frame rules out the true heading.
MIN_SMOOTHING = 1e-3
#: Largest :attr:`CompassConfig.smoothing`: 10,000 pseudo-observations outweigh the
#: frames a spot learns (hundreds to a few thousand per sector), pulling every sector
#: to the pooled histograms and the likelihood to flat.
MAX_SMOOTHING = 1e4
#: Frame size (width, height) :meth:`CompassConfig.memory_bytes` reckons with by
#: default: the Aibo's camera image.
REFERENCE_FRAME = AIBO_RESOLUTION
#: Widest field of view a :class:`~vc_gym.compass.Camera` may have (degrees).
_WIDEST_VIEW_DEG = 180.0
# Bytes per element of the arrays that loading a map and scoring a frame allocate, by
# stage (CompassConfig.memory_bytes; checked against tracemalloc in
# tests/compass/test_map_limits.py):
# - per count of a map: as loaded, the uint32 counts of the file (4), the float64 map
#   (8) and a test of them (1); the float64 log tables while built (counts, log_abs,
#   delta, delta_t: 32) and kept (24); an atlas also stacks its maps' delta_t (8);
_FILE_PER_COUNT = 4
_MAP_PER_COUNT = 8
_TEST_PER_COUNT = 1
_BUILD_PER_COUNT = 32
_KEEP_PER_COUNT = 24
_STACK_PER_COUNT = 8
# - per frame count (phase x relative sector in view x colour pair, float32): while
#   cut (both cumulative gathers and their difference) and kept;
_CUT_PER_FEATURE = 12
_KEEP_PER_FEATURE = 4
# - per non-zero frame count: its indices, frequency, bin and table row (int64 and
#   float64 with their temporaries);
_PER_NONZERO = 64
# - per group score (phase x relative sector x map sector, float64, for every map
#   scored): the scores, then their re-indexed copy beside them;
_PER_GROUP_SCORE = 8
# - per phase and scanned column while the frame geometry is built (int64 indices);
_GEOMETRY_PER_COLUMN = 32
# - exposure="map": per candidate heading and relative sector, the (headings x sectors
#   in view) float64 arrays of the light gains;
_LIGHT_PER_HEADING_SECTOR = 48
# - the colour lookup table: one byte a cell kept; while built, the cell centres (six
#   float64 arrays) and a fixed working set (a chunk of cells under every class).
_LUT_BUILD_PER_CELL = 48
_LUT_CHUNK_BYTES = 11 * 2**19


@dataclass(frozen=True)
class CompassConfig:
    """Parameters of the visual compass (paper sections 3.1-3.4 and 4.1).

    Parameters
    ----------
    n_colors : int
        Number of colour classes ``c`` (paper: 10; 3 suffice). ``1 <= c <= 32``.
    sector_deg : float
        Sector width ``Δφ_sensor`` in degrees (paper: 4.5). Must divide 360.
    n_bins : int
        Number of log-scaled histogram bins ``n`` (eq. 2); bin ``k`` holds
        ``2^-(k+1) < z <= 2^-k``, the last bin also ``z <= 2^-(n-1)`` and zero.
    coverage : float
        Fraction of pixels on the scanning grid (paper: 0.25 = every 2nd row and
        column). ``0.001 <= coverage <= 1`` (0.1 %: every 32nd row and column).
    heading_step_deg : float
        Resolution of the heading grid on which likelihoods are returned (default 1°).
        Must divide 360.
    smoothing : float
        Strength (pseudo-observations) of the prior that pulls each sector's
        histogram towards the map's heading-independent histogram. An unseen bin
        gets a small but non-zero probability, and a sector never learned is
        exactly as likely at every heading. ``> 0``.
    count_same_class : bool
        Also count "transitions" ``i -> i`` (no change of class), i.e. the diagonal of
        the matrix ``Z`` of eq. 4. With it every sector that is seen has counts, even
        a plain wall.
    lut_bits : int
        Bits per channel of the colour lookup table (``2^(3 bits)`` entries).
    temperature : float
        Divides the returned log-likelihoods. 1 is the paper's product of
        independent terms (eq. 16); larger values temper that over-confident
        independence assumption for filters.
    exposure : str
        ``"none"`` (the paper) classifies pixels as they are. ``"mean"`` first scales
        each frame's scanned pixels in linear light so that their mean level equals
        that of the colour-fitting images, which undoes a change of illumination
        or camera exposure (beyond the paper; see the README for measurements), but
        also brightens a view of dark things and darkens one of the sky. ``"map"``
        also learns the mean light of every sector and scores each candidate heading
        with the gain that brings the frame to the light learned in the directions
        it would then see (:mod:`vc_gym.compass.light_map`); it costs one
        classification per distinct gain (about 5-15 per frame). ``"session"``
        applies one gain to every frame of a session: the median of the frames'
        ``"mean"`` gains, rounded to a third of a stop
        (:class:`~vc_gym.exposure.SessionLight`, which the trackers keep), so a
        session at the colour-fitting light is classified as the paper does and
        one at half the light is brightened twice; a frame scored on its own is its
        own session.
    """

    n_colors: int = 10
    sector_deg: float = 4.5
    n_bins: int = 8
    coverage: float = 0.25
    heading_step_deg: float = 1.0
    smoothing: float = 1.0
    count_same_class: bool = True
    lut_bits: int = 5
    temperature: float = 1.0
    exposure: str = "none"

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.type in ("int", int):
                if isinstance(v, bool) or not isinstance(v, int):
                    raise ValueError(f"{f.name} must be an int, got {v!r}")
            elif f.type in ("bool", bool):
                if not isinstance(v, bool):
                    raise ValueError(f"{f.name} must be a bool, got {v!r}")
            elif f.type in ("str", str):
                if not isinstance(v, str):
                    raise ValueError(f"{f.name} must be a str, got {v!r}")
            else:
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                    raise ValueError(f"{f.name} must be a finite number, got {v!r}")
        if not 1 <= self.n_colors <= 32:
            raise ValueError(f"n_colors must be in 1..32, got {self.n_colors}")
        if not 0 < self.sector_deg <= 90 or steps_in_circle(self.sector_deg) is None:
            raise ValueError(f"sector_deg must be in (0, 90] and divide 360, got {self.sector_deg}")
        if not 2 <= self.n_bins <= 32:
            raise ValueError(f"n_bins must be in 2..32, got {self.n_bins}")
        size = self.map_entries
        if size > MAX_MAP_ENTRIES:
            # a map file's config must not make the compass allocate gigabytes of counts
            # (sector_deg=0.001 with 32 classes and bins: 1.2e10 entries)
            raise ValueError(
                f"the map would hold {size} counts (sectors x n_colors² x n_bins), more than "
                f"{MAX_MAP_ENTRIES}: use wider sectors, fewer colour classes or bins"
            )
        if not MIN_COVERAGE <= self.coverage <= 1:
            # below it the grid's steps exceed a small image: it would learn nothing
            raise ValueError(f"coverage must be in [{MIN_COVERAGE}, 1], got {self.coverage}")
        step = self.heading_step_deg
        if not MIN_HEADING_STEP_DEG <= step <= 90 or steps_in_circle(step) is None:
            # a map file's config must not make the compass allocate 360 / 1e-9 headings
            raise ValueError(
                f"heading_step_deg must be in [{MIN_HEADING_STEP_DEG}, 90] and divide 360, "
                f"got {step}"
            )
        if not MIN_SMOOTHING <= self.smoothing <= MAX_SMOOTHING:
            raise ValueError(
                f"smoothing must be in [{MIN_SMOOTHING:g}, {MAX_SMOOTHING:g}], got {self.smoothing}"
            )
        if not 3 <= self.lut_bits <= 7:
            raise ValueError(f"lut_bits must be in 3..7, got {self.lut_bits}")
        if not MIN_TEMPERATURE <= self.temperature <= MAX_TEMPERATURE:
            raise ValueError(
                f"temperature must be in [{MIN_TEMPERATURE:g}, {MAX_TEMPERATURE:g}], "
                f"got {self.temperature}"
            )
        if self.exposure not in EXPOSURE_MODES:
            raise ValueError(f"exposure must be one of {EXPOSURE_MODES}, got {self.exposure!r}")
        need = self.memory_bytes()
        if need > MAX_MAP_BYTES:
            # a small map file must not make loading or scoring one frame take gigabytes
            raise ValueError(
                f"a map of this config would need about {need / 2**20:.0f} MiB to load and "
                f"score one frame (map of {size} counts, {self.n_phases} heading phases x "
                f"{self.n_sectors} sectors), more than MAX_MAP_BYTES = "
                f"{MAX_MAP_BYTES / 2**20:.0f} MiB: use wider sectors, fewer colour classes "
                "or bins, or a heading step that divides the sector width"
            )

    @property
    def n_sectors(self) -> int:
        """Number of sectors around the full circle, ``360 / sector_deg``."""
        return int(round(360.0 / self.sector_deg))

    @property
    def n_headings(self) -> int:
        """Number of candidate headings, ``360 / heading_step_deg``."""
        return int(round(360.0 / self.heading_step_deg))

    @property
    def map_entries(self) -> int:
        """Counts in the map, ``n_sectors · n_colors² · n_bins``."""
        return self.n_sectors * self.n_colors**2 * self.n_bins

    @property
    def n_phases(self) -> int:
        """Distinct offsets of the candidate headings within a sector.

        A frame's columns fall into sectors differently for each offset, so the compass
        cuts every frame once per phase: 9 for 1° headings in 4.5° sectors, up to
        :attr:`n_headings` when the heading step and the sector width have no common
        measure.
        """
        delta = self.sector_deg
        h = np.arange(self.n_headings, dtype=np.float64) * self.heading_step_deg
        # as VisualCompass._geometry groups them
        s0 = np.floor(h / delta + 1e-9)
        return int(np.unique(np.round(h - s0 * delta, 9)).size)

    def memory_bytes(
        self,
        hfov_deg: float = _WIDEST_VIEW_DEG,
        frame: tuple[int, int] = REFERENCE_FRAME,
        n_maps: int = 1,
    ) -> int:
        """Peak bytes of loading maps of this config and scoring one frame with them.

        The largest of the stages, each the arrays alive at its peak (bytes per
        element in the module's constants):

        * loading: the counts as stored, the float64 map and a test of them, beside the
          colour lookup table (one byte a cell; 48 bytes a cell and a working set of
          5.5 MiB while it is built);
        * cutting the frame: its float32 counts per (heading phase, relative sector in
          view, colour pair) while cut, beside the maps (and, with
          ``exposure="map"``, the light gains per heading and sector in view);
        * the log tables of the maps (32 bytes per count while one is built, 24 kept;
          an atlas stacks 8 more), beside the frame's counts;
        * scoring: the kept tables, the frame's counts, and either the arrays of its
          non-zero counts (at most one per transition the frame has per phase) with
          the group scores, or the group scores (phase x relative sector x sector, per
          map) with their re-indexed copy.

        Parameters
        ----------
        hfov_deg : float
            Field of view of the frame: it sets how many relative sectors are in view.
            The default, the widest a camera may have, gives the most.
        frame : tuple of int
            ``(width, height)`` of the frame (default: the Aibo's 208 x 160), level:
            the rows above the horizon, the upper half, are scanned. A larger frame, or
            one that looks up, adds up to 64 bytes per heading phase per scanned pixel.
        n_maps : int
            Maps scored together (>= 2: an atlas with one shared colour set).

        Returns
        -------
        int
            Bytes, besides the image and the interpreter: tracemalloc's peak to within
            a few percent where the map or the group scores dominate. The non-zero
            counts are reckoned at one per transition, an upper bound that a frame
            whose every colour change is a new pair in its sector comes close to.
        """
        m = int(n_maps)
        if m < 1:
            raise ValueError(f"n_maps must be >= 1, got {n_maps!r}")
        e = self.map_entries
        width, height = frame
        row_step, col_step = self.grid_steps
        columns = -(-int(width) // col_step)
        # every scanned pixel above the horizon but the top row's is one transition
        transitions = columns * max(-(-(int(height) // 2) // row_step) - 1, 0)
        phases = self.n_phases
        # relative sectors a view of hfov_deg spans at any phase
        in_view = 2 * math.ceil(hfov_deg / 2 / self.sector_deg) + 2
        groups = phases * in_view
        features = groups * self.n_colors**2
        scores = groups * self.n_sectors * m
        nonzero = min(features, phases * transitions)
        cells = 2 ** (3 * self.lut_bits)
        kept = m * e * (_KEEP_PER_COUNT + (_STACK_PER_COUNT if m > 1 else 0))
        light = 0
        if self.exposure == "map":
            light = _LIGHT_PER_HEADING_SECTOR * self.n_headings * in_view
        stages = (
            m * _FILE_PER_COUNT * e + _LUT_BUILD_PER_CELL * cells + _LUT_CHUNK_BYTES,
            m * (_FILE_PER_COUNT + _MAP_PER_COUNT) * e + _TEST_PER_COUNT * e,
            m * _MAP_PER_COUNT * e
            + _GEOMETRY_PER_COLUMN * phases * columns
            + max(_CUT_PER_FEATURE * features, light),
            max(kept, m * _BUILD_PER_COUNT * e) + _KEEP_PER_FEATURE * features,
            kept
            + _KEEP_PER_FEATURE * features
            + _PER_GROUP_SCORE * scores
            + max(_PER_NONZERO * nonzero, _PER_GROUP_SCORE * scores),
        )
        return int(max(stages)) + cells

    @property
    def grid_steps(self) -> tuple[int, int]:
        """``(row_step, column_step)`` of the scanning grid for :attr:`coverage`."""
        target = 1.0 / self.coverage
        col = max(1, int(round(math.sqrt(target))))
        row = max(1, int(round(target / col)))
        return row, col

    def to_dict(self) -> dict[str, object]:
        """Plain dict of the fields (JSON-serialisable)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, object]) -> CompassConfig:
        """Inverse of :meth:`to_dict`; unknown keys are an error."""
        names = {f.name for f in fields(cls)}
        unknown = set(d) - names
        if unknown:
            raise ValueError(f"unknown CompassConfig fields: {sorted(unknown)}")
        return cls(**d)  # type: ignore[arg-type]
