"""A compass map as plain arrays and ``.npz`` files (design: Persistence).

A map file holds the config that produced it, the colour classes, the counts (eq. 6),
how many frames saw each sector, the exposure reference level, the frame sizes learned,
the calibration of the heading spread (:mod:`~vc_gym.compass.calibration`) and, with
``exposure="map"``, the light per sector. It is written atomically and read
with :func:`vc_gym.persistence.load_npz_checked` (never unpickled); every entry is
checked against the stored config, and a file that cannot be read gives a
:class:`~vc_gym.errors.MapFileError` naming the file and the entry at fault.
:class:`~vc_gym.compass.CompassAtlas` stores several maps in one file through the same
arrays (with shared colour classes written once).

Schema version 1. The spread calibration (entry ``spread_calibration``:
``[temperature, floor_deg]``) is optional within it, so the version stays: a file
without the entry loads as uncalibrated
(:data:`~vc_gym.compass.calibration.UNCALIBRATED`: the paper's spread), and a reader
that does not know the entry ignores it; an entry of another shape or with a value out
of range is refused. It is one entry, not two, so that an atlas of
:data:`~vc_gym.compass.atlas.MAX_SPOTS` spots with their own colour classes and light
maps stays within :data:`~vc_gym.persistence.MAX_MEMBERS` entries.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vc_gym.compass.calibration import UNCALIBRATED, check_spread_calibration
from vc_gym.compass.colors import MAX_LIGHT_LEVEL, ColorClasses
from vc_gym.compass.config import CompassConfig
from vc_gym.compass.light_gain import REFERENCE_EXPOSURES
from vc_gym.compass.light_map import LightMap
from vc_gym.errors import MapFileError
from vc_gym.persistence import json_array, load_npz_checked, read_json_array, save_npz_atomic

__all__ = [
    "MAP_SCHEMA",
    "MAP_SCHEMA_VERSION",
    "MAX_LEARNED_SIZES",
    "MapContents",
    "check_learned_sizes",
    "map_arrays",
    "read_config_and_colors",
    "read_light_map",
    "read_map_contents",
    "read_map_file",
    "read_spread_calibration",
    "write_map_file",
]

MAP_SCHEMA = "vc_gym.VisualCompass"
MAP_SCHEMA_VERSION = 1
#: Most distinct frame sizes a map file may list: a map learns from one camera or a
#: few; each listed size becomes a Python object when loaded (about 150 bytes), and an
#: entry of 64 MiB could otherwise list 4 million of them.
MAX_LEARNED_SIZES = 4096


@dataclass(frozen=True)
class MapContents:
    """What a map file holds besides its config and colour classes.

    Attributes
    ----------
    counts : numpy.ndarray
        ``(n_sectors, n_colors², n_bins)`` counts of learned frames (eq. 6); as
        stored (integers) when read, the compass' float64 map when written.
    sector_observations : numpy.ndarray
        ``(n_sectors,)`` frames that saw each sector.
    frames_learned : int
        Frames added to the map.
    exposure_reference : float
        Mean linear light level of the colour-fitting images (0 if not kept).
    learned_sizes : set of (int, int)
        ``(H, W)`` of the learned frames.
    light : LightMap or None
        The light per sector; written and read only with ``exposure="map"``
        (``None`` when read from a map of another mode).
    spread_calibration : tuple of float
        ``(temperature, floor_deg)`` of the heading spread
        (:mod:`~vc_gym.compass.calibration`); uncalibrated by default.
    """

    counts: np.ndarray
    sector_observations: np.ndarray
    frames_learned: int
    exposure_reference: float
    learned_sizes: set[tuple[int, int]]
    light: LightMap | None
    spread_calibration: tuple[float, float] = UNCALIBRATED


def check_learned_sizes(sizes: set[tuple[int, int]]) -> None:
    """A ``ValueError`` if a map would remember more than :data:`MAX_LEARNED_SIZES`
    frame sizes (the loader refuses such a file)."""
    if len(sizes) > MAX_LEARNED_SIZES:
        raise ValueError(
            f"a map learns frames of at most {MAX_LEARNED_SIZES} different sizes; this one "
            f"would have {len(sizes)}"
        )


def map_arrays(
    config: CompassConfig, contents: MapContents, colors: ColorClasses | None = None
) -> dict[str, np.ndarray]:
    """Config, map and (if given) colour classes as the plain arrays of a map file.

    The entries come in the order they are written (:func:`write_map_file`).
    """
    arrays = {
        "config": json_array(config.to_dict()),
        "counts": contents.counts.astype(np.uint32),
        "sector_observations": contents.sector_observations.astype(np.uint32),
        "frames_learned": np.array(contents.frames_learned, dtype=np.int64),
        "exposure_reference": np.array(contents.exposure_reference, dtype=np.float64),
        "learned_sizes": np.array(sorted(contents.learned_sizes), dtype=np.int64).reshape(-1, 2),
        "spread_calibration": np.array(contents.spread_calibration, dtype=np.float64),
    }
    if config.exposure == "map":
        assert contents.light is not None
        arrays["light_sum"] = contents.light.level_sum.copy()
        arrays["light_columns"] = contents.light.columns.copy()
    if colors is not None:
        arrays.update(colors.to_arrays())
    return arrays


def write_map_file(path: str | os.PathLike, arrays: Mapping[str, np.ndarray]) -> Path:
    """Write :func:`map_arrays` to an ``.npz`` file, atomically; returns the path written
    (``.npz`` appended if missing)."""
    return save_npz_atomic(path, MAP_SCHEMA, MAP_SCHEMA_VERSION, arrays)


def read_map_file(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """The arrays of a map file, read safely (schema and version checked).

    Raises
    ------
    MapFileError
        Missing, empty, truncated or corrupt file, another schema or version.
    """
    return load_npz_checked(path, MAP_SCHEMA, MAP_SCHEMA_VERSION)


def read_config_and_colors(
    arrays: Mapping[str, np.ndarray],
    source: str | os.PathLike,
    config: CompassConfig | None = None,
    colors: ColorClasses | None = None,
) -> tuple[CompassConfig, ColorClasses]:
    """The stored config (equal to ``config`` if given) and the colour classes
    (``colors`` if given, else read from ``arrays``).

    Raises
    ------
    MapFileError
        Naming ``source``: a missing or invalid config, another config than
        ``config``, invalid colour classes.
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
        if colors.n_colors != stored.n_colors:
            raise MapFileError(
                f"{path}: its config says {stored.n_colors} colour classes, but it holds "
                f"{colors.n_colors}"
            )
    return stored, colors


def read_map_contents(
    arrays: Mapping[str, np.ndarray], source: str | os.PathLike, config: CompassConfig
) -> MapContents:
    """The map entries of ``arrays``, each checked against the stored ``config``.

    Raises
    ------
    MapFileError
        Naming ``source`` and the entry at fault: missing entries, shapes or dtypes
        that do not match ``config``, negative counts, counts that do not add up to
        the sector observations, an implausible frame count, exposure reference,
        list of frame sizes or light map.
    """
    path = source
    c2 = config.n_colors**2
    expect = {
        "counts": (config.n_sectors, c2, config.n_bins),
        "sector_observations": (config.n_sectors,),
        "frames_learned": (),
    }
    for key, shape in expect.items():
        if key not in arrays:
            raise MapFileError(f"{path}: missing entry {key!r}")
        a = arrays[key]
        if a.shape != shape or a.dtype.kind not in "iu":
            raise MapFileError(
                f"{path}: entry {key!r} has shape {a.shape} and dtype {a.dtype}, "
                f"expected integer counts of shape {shape} for {config}"
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
    if config.exposure in REFERENCE_EXPOSURES and ref <= 0:
        raise MapFileError(f"{path}: exposure={config.exposure!r} but no reference level stored")
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
    light = read_light_map(arrays, path, config.n_sectors) if config.exposure == "map" else None
    return MapContents(
        counts=counts,
        sector_observations=n_obs,
        frames_learned=frames,
        exposure_reference=float(ref),
        learned_sizes={(int(a), int(b)) for a, b in sizes},
        light=light,
        spread_calibration=read_spread_calibration(arrays, path),
    )


def read_spread_calibration(
    arrays: Mapping[str, np.ndarray], source: object
) -> tuple[float, float]:
    """``(temperature, floor_deg)`` of a map file's ``spread_calibration`` entry;
    :data:`~vc_gym.compass.calibration.UNCALIBRATED` when it is absent (a map never
    calibrated, or written by a vc_gym without calibration).

    Raises
    ------
    MapFileError
        Naming ``source``: an entry that is not two real numbers, or values
        :func:`~vc_gym.compass.calibration.check_spread_calibration` refuses.
    """
    a = arrays.get("spread_calibration")
    if a is None:
        return UNCALIBRATED
    if a.shape != (2,) or a.dtype.kind not in "iuf":
        raise MapFileError(
            f"{source}: entry 'spread_calibration' must be two real numbers "
            f"[temperature, floor_deg], got {a.dtype} of shape {a.shape}"
        )
    try:
        return check_spread_calibration(float(a[0]), float(a[1]))
    except ValueError as e:
        raise MapFileError(f"{source}: invalid spread calibration ({e})") from None


def read_light_map(arrays: Mapping[str, np.ndarray], source: object, n_sectors: int) -> LightMap:
    """The light map of a map file's ``light_sum`` and ``light_columns``, checked.

    Raises
    ------
    MapFileError
        Naming ``source``: an entry missing, of another shape than ``(n_sectors,)``,
        not finite and ``>= 0``, or a mean level above 1.
    """
    path = source
    light = LightMap(n_sectors)
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
    return light
