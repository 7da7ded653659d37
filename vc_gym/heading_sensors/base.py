"""The surface every image baseline shares with the visual compass.

:class:`BaselineCompass` holds what is the same for every image-based baseline: the
circular grid of candidate headings, the checks of images and cameras, the best
heading with its spread (the visual compass' eq. 25-27 over the baseline's own
likelihood), the sensor protocol of the filters and checked, atomic ``.npz`` files.
A subclass says how it learns a frame, how it scores a frame at every heading and
which arrays make up its map.
"""

from __future__ import annotations

import os
from abc import ABC, abstractmethod
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from vc_gym.angles import (
    MIN_HEADING_STEP_DEG,
    circular_std_rows,
    interp_circular,
    peak_headings,
    steps_in_circle,
)
from vc_gym.compass import Camera, CompassEstimate
from vc_gym.errors import MapFileError, NotLearnedError
from vc_gym.filters.sensor_protocol import check_log_likelihood
from vc_gym.images import check_image
from vc_gym.persistence import json_array, load_npz_checked, read_json_array, save_npz_atomic
from vc_gym.validation import positive_float

__all__ = ["BaselineCompass", "FrameScore", "check_camera", "estimate_of", "heading_grid"]


def check_camera(camera: object) -> Camera:
    """Return ``camera`` if it is a :class:`~vc_gym.compass.Camera`, else a clear error."""
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be a vc_gym.compass.Camera, got {type(camera).__name__}")
    return camera


def heading_grid(step_deg: float) -> np.ndarray:
    """The read-only heading grid ``0, step, ..., 360 - step`` (``step`` must divide 360
    and lie in ``[MIN_HEADING_STEP_DEG, 90]``)."""
    step = positive_float("heading_step_deg", step_deg)
    if step < MIN_HEADING_STEP_DEG:
        raise ValueError(f"heading_step_deg must be >= {MIN_HEADING_STEP_DEG}, got {step}")
    n = steps_in_circle(step)
    if step > 90.0 or n is None:
        raise ValueError(f"heading_step_deg must divide 360 (and be <= 90), got {step}")
    h = np.arange(n, dtype=np.float64) * step
    h.setflags(write=False)
    return h


def estimate_of(
    log_likelihood: np.ndarray, headings_deg: np.ndarray, goodness: float, n_terms: int
) -> CompassEstimate:
    """A :class:`~vc_gym.compass.CompassEstimate` from a log-likelihood on the grid
    ``headings_deg``: the parabola-refined arg-max and the circular spread of the
    posterior ``∝ exp(log-likelihood)`` (eq. 25-27)."""
    ll = np.asarray(log_likelihood, dtype=np.float64)[None]
    heading, best = peak_headings(ll, 360.0 / headings_deg.size)
    spread = circular_std_rows(headings_deg, np.exp(ll - ll[0, best[0]]))
    return CompassEstimate(float(heading[0]), float(spread[0]), goodness, n_terms, ll[0])


class FrameScore:
    """What a baseline computes for one frame: log-likelihood over the heading grid,
    goodness of fit at the best heading (higher is better) and the number of terms
    (sectors, columns, matches) the frame contributed."""

    __slots__ = ("log_likelihood", "goodness", "n_terms")

    def __init__(self, log_likelihood: np.ndarray, goodness: float, n_terms: int):
        self.log_likelihood = log_likelihood
        self.goodness = float(goodness)
        self.n_terms = int(n_terms)


class BaselineCompass(ABC):
    """Base of the image baselines: learn frames with a known yaw, tell headings.

    Parameters
    ----------
    heading_step_deg : float
        Step of the candidate heading grid; must divide 360.

    Notes
    -----
    Subclasses implement :meth:`_learn`, :meth:`_score`, :meth:`_config` and
    :meth:`_map_arrays` / :meth:`_from_map_arrays`, and name their file :attr:`schema`.
    Every public method checks its inputs here, so a subclass sees only
    ``(H, W, 3)`` ``uint8`` RGB images and :class:`~vc_gym.compass.Camera` objects.
    """

    #: File schema name (``.npz`` entry ``schema``); one per class.
    schema: ClassVar[str] = ""
    #: Other schema names :meth:`load` accepts as this class' files (another spelling
    #: of :attr:`schema`).
    legacy_schemas: ClassVar[tuple[str, ...]] = ()
    #: Version of the class' file layout.
    schema_version: ClassVar[int] = 1
    #: Short name of the sensor (as in :data:`vc_gym.heading_sensors.SENSORS`).
    name: ClassVar[str] = ""

    def __init__(self, heading_step_deg: float = 1.0):
        self._headings = heading_grid(heading_step_deg)
        self.heading_step_deg = float(heading_step_deg)
        self._frames = 0

    # ------------------------------------------------------------------ properties
    @property
    def headings_deg(self) -> np.ndarray:
        """Candidate headings ``0, step, ..., 360 - step`` (read-only)."""
        return self._headings

    @property
    def frames_learned(self) -> int:
        """Number of frames learned so far."""
        return self._frames

    @property
    def is_learned(self) -> bool:
        """Whether the map holds anything to compare a frame with."""
        return self._frames > 0

    # ------------------------------------------------------------------ to implement
    @abstractmethod
    def _learn(self, image: np.ndarray, camera: Camera) -> None:
        """Add one checked frame taken with ``camera`` (its yaw is the truth)."""

    @abstractmethod
    def _score(self, image: np.ndarray, camera: Camera) -> FrameScore:
        """Log-likelihood of one checked frame at every grid heading, and its goodness."""

    @abstractmethod
    def _config(self) -> dict[str, Any]:
        """The constructor's keyword arguments (JSON-able), saved with the map."""

    @abstractmethod
    def _map_arrays(self) -> dict[str, np.ndarray]:
        """The learned map as plain numeric arrays."""

    @abstractmethod
    def _from_map_arrays(self, arrays: Mapping[str, np.ndarray]) -> None:
        """Restore the map from :meth:`_map_arrays`' output; raise ``ValueError`` (with
        the entry's name) on anything inconsistent with the config."""

    # ------------------------------------------------------------------ public surface
    def learn(self, image: np.ndarray, camera: Camera) -> None:
        """Learn one frame whose camera yaw (``camera.yaw_deg``) is the true heading."""
        check_image(image)
        self._learn(image, check_camera(camera))
        self._frames += 1

    def _checked_score(self, image: np.ndarray, camera: Camera) -> FrameScore:
        check_image(image)
        check_camera(camera)
        if not self.is_learned:
            raise NotLearnedError(f"{type(self).__name__} has learned no frame yet")
        score = self._score(image, camera)
        score.log_likelihood = check_log_likelihood(
            score.log_likelihood, self._headings.size, type(self).__name__
        )
        return score

    def log_likelihood(self, image: np.ndarray, camera: Camera) -> np.ndarray:
        """``log p(image | heading)`` up to a constant, for every :attr:`headings_deg`.

        ``camera`` gives the intrinsics and pitch; its yaw is ignored (every heading is
        tried).
        """
        return self._checked_score(image, camera).log_likelihood

    def estimate(self, image: np.ndarray, camera: Camera) -> CompassEstimate:
        """Best heading (parabola-refined arg-max), its spread (circular std of the
        posterior ``∝ exp(log-likelihood)``, as eq. 27) and the goodness of fit.

        ``score`` is the baseline's own goodness (higher fits better; see the class);
        ``n_sectors`` the number of terms the frame contributed.
        """
        s = self._checked_score(image, camera)
        return estimate_of(s.log_likelihood, self._headings, s.goodness, s.n_terms)

    def heading_log_likelihood(
        self,
        observation: tuple[np.ndarray, Camera],
        headings_deg: np.ndarray,
    ) -> np.ndarray:
        """The filters' sensor protocol: ``observation`` is ``(image, camera)``.

        Headings between grid points are interpolated (wrapping around 360°).
        """
        try:
            image, camera = observation
        except (TypeError, ValueError):
            raise ValueError(
                f"{type(self).__name__} observes (image, camera) pairs, got {type(observation)}"
            ) from None
        ll = self.log_likelihood(image, camera)
        return interp_circular(ll, self.heading_step_deg, np.asarray(headings_deg, float))

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | os.PathLike) -> Path:
        """Save config and map to an ``.npz`` file, atomically; returns the path."""
        if not self.is_learned:
            raise NotLearnedError(f"nothing to save: {type(self).__name__} has learned no frame")
        arrays = {
            "config": json_array(self._config()),
            "frames_learned": np.array(self._frames, dtype=np.int64),
            **self._map_arrays(),
        }
        return save_npz_atomic(path, self.schema, self.schema_version, arrays)

    @classmethod
    def load(cls, path: str | os.PathLike) -> BaselineCompass:
        """Load a map saved by :meth:`save` (never unpickles; sizes checked first).

        Raises
        ------
        MapFileError
            Naming the file: missing, corrupt, another schema or version, a bad config
            (one the constructor refuses, or whose map cannot be allocated) or arrays
            that do not fit it.
        """
        arrays = load_npz_checked(
            path, cls.schema, cls.schema_version, legacy_schemas=cls.legacy_schemas
        )
        config = read_json_array(arrays, "config", path) if "config" in arrays else None
        if not isinstance(config, dict):
            raise MapFileError(f"{path}: no config object")
        try:
            # the constructor validates the saved config as it would a typed one
            obj = cls(**config)
        except (TypeError, ValueError) as e:
            raise MapFileError(f"{path}: bad config ({e})") from None
        except MemoryError:
            # a config whose arrays cannot even be allocated is the file's fault
            raise MapFileError(f"{path}: bad config (its map does not fit in memory)") from None
        frames = arrays.get("frames_learned")
        if frames is None or frames.ndim != 0 or frames.dtype.kind not in "iu" or int(frames) < 1:
            raise MapFileError(f"{path}: frames_learned must be an integer >= 1")
        try:
            obj._from_map_arrays(arrays)
        except (KeyError, ValueError, TypeError) as e:
            raise MapFileError(f"{path}: {e}") from None
        obj._frames = int(frames)
        return obj

    def __repr__(self) -> str:
        cfg = ", ".join(f"{k}={v!r}" for k, v in self._config().items())
        return f"{type(self).__name__}({cfg}; {self._frames} frames learned)"
