"""Configuration of the visual compass, with the paper's values as defaults."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

from vc_gym.angles import MIN_HEADING_STEP_DEG, steps_in_circle

__all__ = ["CompassConfig", "EXPOSURE_MODES", "MAX_MAP_ENTRIES", "MIN_COVERAGE"]

#: Accepted values of :attr:`CompassConfig.exposure`.
EXPOSURE_MODES = ("none", "mean", "map", "session")
#: Smallest scanning coverage (0.1 %); the paper reports that < 1 % still works.
MIN_COVERAGE = 0.001
#: Most counts a map may hold (``n_sectors · n_colors² · n_bins``; 128 MB as float64).
#: The paper's map holds 64,000; 1° sectors with 32 classes and 32 bins 11.8 million.
MAX_MAP_ENTRIES = 2**24


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
        size = self.n_sectors * self.n_colors**2 * self.n_bins
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
        if self.smoothing <= 0:
            raise ValueError(f"smoothing must be > 0, got {self.smoothing}")
        if not 3 <= self.lut_bits <= 7:
            raise ValueError(f"lut_bits must be in 3..7, got {self.lut_bits}")
        if self.temperature <= 0:
            raise ValueError(f"temperature must be > 0, got {self.temperature}")
        if self.exposure not in EXPOSURE_MODES:
            raise ValueError(f"exposure must be one of {EXPOSURE_MODES}, got {self.exposure!r}")

    @property
    def n_sectors(self) -> int:
        """Number of sectors around the full circle, ``360 / sector_deg``."""
        return int(round(360.0 / self.sector_deg))

    @property
    def n_headings(self) -> int:
        """Number of candidate headings, ``360 / heading_step_deg``."""
        return int(round(360.0 / self.heading_step_deg))

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
