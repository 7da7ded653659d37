"""The compass on your own footage: its camera, learning a map from a full turn at known
yaws (paper 4.3, eq. 6) and tracking other footage frame by frame (eq. 5, 16, 27, 28).
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.compass.calibration import SpreadCalibration
from vc_gym.compass.camera import MAX_HFOV_DEG, MIN_HFOV_DEG, Camera, check_hfov
from vc_gym.compass.config import CompassConfig
from vc_gym.compass.footage.frames import Footage
from vc_gym.compass.visual_compass import CompassEstimate, VisualCompass
from vc_gym.persistence import write_atomic
from vc_gym.validation import finite_real

__all__ = [
    "CALIBRATION_FRAMES",
    "CALIBRATION_MAX_BYTES",
    "calibrate_footage",
    "COLOR_FIT_FRAMES",
    "FootageTrack",
    "Progress",
    "footage_camera",
    "learn_footage",
    "track_footage",
    "write_track_csv",
]

T = TypeVar("T")
#: ``progress(iterable, total)``: wraps a loop, e.g. in a progress bar (``tqdm``).
Progress = Callable[[Iterable[Any], int], Iterable[Any]]

#: Frames the colour classes are fitted on (spread evenly over the learning frames);
#: each is subsampled to at most :data:`_COLOR_FIT_PIXELS` pixels first.
COLOR_FIT_FRAMES = 16
_COLOR_FIT_PIXELS = 2**20


def footage_camera(
    footage: Footage,
    hfov_deg: float | None = None,
    focal_px: float | None = None,
    pitch_deg: float = 0.0,
    *,
    names: Mapping[str, str] | None = None,
) -> Camera:
    """The camera that filmed ``footage``: from its horizontal field of view, or from
    its focal length in pixels of the frames as stored (``hfov = 2 atan(W / 2f)``).

    Exactly one of ``hfov_deg`` and ``focal_px`` must be given; either way the field of
    view must lie in ``[MIN_HFOV_DEG, MAX_HFOV_DEG]``. Scaling the frames
    (``Footage(width=...)``) keeps the field of view, so the camera is the same.
    ``names`` gives the names used in error messages, by argument (a command's flags,
    e.g. ``{"focal_px": "--focal"}``).
    """
    label = dict(names or {})

    def name(arg: str) -> str:
        return label.get(arg, arg)

    if (hfov_deg is None) == (focal_px is None):
        raise ValueError(
            f"give the camera's field of view ({name('hfov_deg')}) or its focal length "
            f"({name('focal_px')})"
        )
    pitch = finite_real(name("pitch_deg"), pitch_deg)
    if hfov_deg is not None:
        return Camera(hfov_deg=check_hfov(name("hfov_deg"), hfov_deg), pitch_deg=pitch)
    f = finite_real(name("focal_px"), focal_px)
    width = footage.first_size()[1]
    if f <= 0:
        raise ValueError(f"{name('focal_px')} must be > 0 pixels, got {focal_px!r}")
    hfov = Camera.hfov_of_focal(f, width)
    if not MIN_HFOV_DEG <= hfov <= MAX_HFOV_DEG:
        lo = Camera(hfov_deg=MAX_HFOV_DEG).focal_px(width)
        hi = Camera(hfov_deg=MIN_HFOV_DEG).focal_px(width)
        raise ValueError(
            f"{name('focal_px')} {focal_px:g}: frames {width} pixels wide would see "
            f"{hfov:.4g} degrees; the field of view must lie in [{MIN_HFOV_DEG:g}, "
            f"{MAX_HFOV_DEG:g}] degrees, a focal length in [{lo:.3g}, {hi:.4g}] pixels"
        )
    return Camera.from_focal(f, width, pitch_deg=pitch)


# ----------------------------------------------------------------------------- learning
def _wrapped(progress: Progress | None, items: Iterable[T], total: int) -> Iterable[T]:
    return items if progress is None else progress(items, total)


def _color_sample(frame: np.ndarray) -> np.ndarray:
    """``frame`` subsampled to at most :data:`_COLOR_FIT_PIXELS` pixels."""
    s = max(1, math.ceil(math.sqrt(frame.shape[0] * frame.shape[1] / _COLOR_FIT_PIXELS)))
    return np.ascontiguousarray(frame[::s, ::s]) if s > 1 else frame


def learn_footage(
    footage: Footage,
    camera: Camera,
    yaws_deg: np.ndarray,
    config: CompassConfig | None = None,
    *,
    rng: np.random.Generator | None = None,
    progress: Progress | None = None,
) -> VisualCompass:
    """Learn a compass map from the frames of ``footage`` at known yaws.

    The colour classes are fitted (paper 3.4, eq. 7-8) on up to
    :data:`COLOR_FIT_FRAMES` frames spread evenly over the footage, then every frame
    is added to the map at its yaw (eq. 6).

    Parameters
    ----------
    footage : Footage
        The learning frames: the camera turning in place.
    camera : Camera
        Its intrinsics and pitch (:func:`footage_camera`); the yaw is each frame's.
    yaws_deg : numpy.ndarray
        One yaw per frame of :attr:`Footage.indices` (:func:`footage_yaws`).
    config : CompassConfig, optional
        The compass' parameters (the paper's by default).
    rng : numpy.random.Generator, optional
        Seeds the colour fitting (default: seed 0).
    progress : callable, optional
        ``progress(iterable, total)`` wrapping the learning loop (e.g. ``tqdm``).

    Returns
    -------
    VisualCompass
        The learned compass; :meth:`~VisualCompass.save` writes its map.
    """
    idx = footage.indices
    yaws = np.asarray(yaws_deg, dtype=np.float64)
    if yaws.shape != idx.shape or not np.all(np.isfinite(yaws)):
        raise ValueError(f"yaws_deg must be {idx.size} finite numbers, got shape {yaws.shape}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
    picks = np.unique(np.linspace(0, idx.size - 1, min(COLOR_FIT_FRAMES, idx.size)).round())
    samples = [_color_sample(frame) for _, frame in footage.frames(idx[picks.astype(int)])]
    vc = VisualCompass(config)
    vc.fit_colors(samples, rng=rng if rng is not None else np.random.default_rng(0))
    del samples
    yaw_of = dict(zip(idx.tolist(), yaws.tolist(), strict=True))
    for index, frame in _wrapped(progress, footage.frames(), idx.size):
        vc.learn(frame, camera.replace(yaw_deg=yaw_of[index]))
    return vc


#: Most learning frames the spread is calibrated on (spread evenly over the footage).
CALIBRATION_FRAMES = 72
#: Most bytes of frames the calibration holds at once: the frames are estimated
#: together, so large frames mean fewer of them (13 at :data:`MAX_FRAME_PIXELS`).
CALIBRATION_MAX_BYTES = 2 * 2**30


def calibrate_footage(
    vc: VisualCompass, footage: Footage, camera: Camera, yaws_deg: np.ndarray
) -> SpreadCalibration | None:
    """Calibrate the spread of a map learned from ``footage`` on its own learning frames.

    Up to :data:`CALIBRATION_FRAMES` of the frames :func:`learn_footage` learned (spread
    evenly; fewer where they would take more than :data:`CALIBRATION_MAX_BYTES` at the
    size the compass sees, :attr:`Footage.frame_size`) are each estimated against the
    map without themselves (:meth:`VisualCompass.calibrate` with ``leave_one_out``),
    which fits the temperature of the spread (eq. 27) so that the truth lies within two
    spreads about 95 % of the time near the spot.

    Returns
    -------
    SpreadCalibration or None
        The fit, or ``None`` when too few learning frames overlap their neighbours to
        calibrate on (photos far apart): the map then keeps the paper's spread.
    """
    idx = footage.indices
    height, width = footage.frame_size
    fits = max(1, CALIBRATION_MAX_BYTES // (3 * height * width))
    spaced = np.linspace(0, idx.size - 1, min(CALIBRATION_FRAMES, fits, idx.size)).round()
    picks = idx[np.unique(spaced.astype(int))]
    yaws = np.asarray(yaws_deg, dtype=np.float64).tolist()
    yaw_of = dict(zip(idx.tolist(), yaws, strict=True))
    frames = list(footage.frames(picks))  # bad frames left out with skip_bad_frames
    images = [frame for _, frame in frames]
    cameras = [camera.replace(yaw_deg=yaw_of[index]) for index, _ in frames]
    try:
        return vc.calibrate(images, cameras, leave_one_out=True)
    except ValueError:
        return None


# ----------------------------------------------------------------------------- tracking
@dataclass(frozen=True)
class FootageTrack:
    """The compass' estimate for every tracked frame (:func:`track_footage`).

    Attributes
    ----------
    indices : numpy.ndarray
        Input index of each frame.
    heading_deg, spread_deg, score : numpy.ndarray
        :class:`~vc_gym.compass.CompassEstimate`'s best heading in ``[0, 360)``, its
        spread (circular standard deviation, eq. 27) and the goodness of fit (mean
        log-probability per term, eq. 28).
    has_evidence : numpy.ndarray
        Whether the frame showed any colour change (bool); without it the heading is a
        placeholder and the frame is left out of the figures.
    true_deg : numpy.ndarray or None
        The known yaw of each frame, if given.
    skipped : int
        Frames of the selection left out because they could not be read
        (``Footage(skip_bad_frames=True)``); they have no row here.
    """

    indices: np.ndarray
    heading_deg: np.ndarray
    spread_deg: np.ndarray
    score: np.ndarray
    has_evidence: np.ndarray
    true_deg: np.ndarray | None = None
    skipped: int = 0

    @property
    def error_deg(self) -> np.ndarray | None:
        """Signed error ``wrap180(heading - true)`` of each frame, or ``None``."""
        if self.true_deg is None:
            return None
        return np.asarray(wrap180(self.heading_deg - self.true_deg), dtype=np.float64).reshape(-1)

    def summary(self) -> dict[str, Any]:
        """The figures of the track, as plain numbers (JSON-ready).

        ``frames`` (tracked), ``skipped_frames`` (unreadable, left out),
        ``frames_with_evidence``, ``median_spread_deg``; with the true yaws
        also ``median_abs_error_deg``, ``mean_abs_error_deg``, ``max_abs_error_deg``,
        ``within_5deg`` and ``within_10deg`` (shares) and ``within_2sigma``: the share
        of frames whose true yaw lies within twice the reported spread of the estimate.
        A calibrated sensor has about 0.95 there. Every figure is over the frames with
        evidence (``None`` when there are none).
        """
        ev = self.has_evidence
        out: dict[str, Any] = {
            "frames": int(self.indices.size),
            "skipped_frames": int(self.skipped),
            "frames_with_evidence": int(ev.sum()),
            "median_spread_deg": _median(self.spread_deg[ev]),
        }
        err = self.error_deg
        if err is not None:
            e = np.abs(err[ev])
            some = e.size > 0
            out.update(
                median_abs_error_deg=_median(e),
                mean_abs_error_deg=float(np.mean(e)) if some else None,
                max_abs_error_deg=float(np.max(e)) if some else None,
                within_5deg=float(np.mean(e <= 5.0)) if some else None,
                within_10deg=float(np.mean(e <= 10.0)) if some else None,
                within_2sigma=float(np.mean(e <= 2.0 * self.spread_deg[ev])) if some else None,
            )
        return out


def _median(values: np.ndarray) -> float | None:
    return float(np.median(values)) if values.size else None


def track_footage(
    compass: VisualCompass,
    footage: Footage,
    camera: Camera,
    true_deg: np.ndarray | None = None,
    *,
    progress: Progress | None = None,
    on_frame: Callable[[int, np.ndarray, CompassEstimate], None] | None = None,
) -> FootageTrack:
    """Estimate the heading of every frame of ``footage`` on its own (eq. 5, 16, 25-28).

    Parameters
    ----------
    compass : VisualCompass
        A learned compass (e.g. :meth:`VisualCompass.load` of a map).
    footage : Footage
        The frames to track.
    camera : Camera
        Their camera (its yaw is ignored).
    true_deg : numpy.ndarray, optional
        The known yaw of each frame of :attr:`Footage.indices`, to measure errors.
    progress : callable, optional
        ``progress(iterable, total)`` wrapping the loop (e.g. ``tqdm``).
    on_frame : callable, optional
        ``on_frame(index, frame, estimate)`` after each frame (e.g. to draw it).

    Returns
    -------
    FootageTrack
        One row per frame read; frames skipped as unreadable
        (``Footage(skip_bad_frames=True)``) have none and are counted in ``skipped``.
    """
    idx = footage.indices
    truth = None
    if true_deg is not None:
        truth = np.asarray(true_deg, dtype=np.float64)
        if truth.shape != idx.shape or not np.all(np.isfinite(truth)):
            raise ValueError(f"true_deg must be {idx.size} finite numbers, got shape {truth.shape}")
    n = idx.size
    heading, spread, score = np.zeros(n), np.zeros(n), np.zeros(n)
    evidence, read = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    position = {index: k for k, index in enumerate(idx.tolist())}
    for index, frame in _wrapped(progress, footage.frames(), n):
        est = compass.estimate(frame, camera)
        k = position[index]
        heading[k], spread[k], score[k] = est.heading_deg, est.spread_deg, est.score
        evidence[k], read[k] = est.has_evidence, True
        if on_frame is not None:
            on_frame(index, frame, est)
    return FootageTrack(
        idx[read],
        heading[read],
        spread[read],
        score[read],
        evidence[read],
        None if truth is None else truth[read],
        skipped=int(n - read.sum()),
    )


def write_track_csv(path: str | os.PathLike, track: FootageTrack) -> Path:
    """Write ``track`` as CSV, atomically: columns ``frame, heading_deg, spread_deg,
    score, has_evidence`` and, with true yaws, ``true_deg, error_deg`` (``error_deg`` =
    ``wrap180(heading - true)``; ``has_evidence`` is 1 or 0)."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    head = ["frame", "heading_deg", "spread_deg", "score", "has_evidence"]
    err = track.error_deg
    if err is not None:
        head += ["true_deg", "error_deg"]
    w.writerow(head)
    for k in range(track.indices.size):
        row = [
            int(track.indices[k]),
            f"{track.heading_deg[k]:.3f}",
            f"{track.spread_deg[k] + 0.0:.4g}",  # + 0.0: no "-0"
            f"{track.score[k]:.6g}",
            int(track.has_evidence[k]),
        ]
        if err is not None:
            assert track.true_deg is not None
            row += [f"{track.true_deg[k]:.3f}", f"{err[k]:.3f}"]
        w.writerow(row)
    data = out.getvalue().encode("utf-8")

    def write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())

    return write_atomic(path, write)
