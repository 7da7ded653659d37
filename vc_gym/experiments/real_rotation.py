"""The compass on real photos of a camera turning in place.

For each rotation set (18 photos over a full turn, yaw ground truth from the
stitching of the photos): fit colour classes on and learn from 9 alternate photos,
then estimate the yaw of crops of the other 9 photos. A crop keeps the photo's focal
length and optical axis (its principal point moves), so its true yaw is the photo's.
With ``light`` below 1 the crops are darkened in linear light (the paper's
illumination test, section 5.3, on real photos); the training photos never are.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.compass import Camera, CompassConfig, ImageCompass, VisualCompass
from vc_gym.experiments.real_data import (
    ROTATION_SETS,
    RotationPhoto,
    default_real_data_dir,
    load_rotation_set,
)
from vc_gym.experiments.studies.common import ExperimentOptions
from vc_gym.exposure import SessionLight, gain_table
from vc_gym.jobs.output import write_json
from vc_gym.validation import positive_float

__all__ = [
    "crop_columns",
    "evaluate_rotation_set",
    "evaluate_rotation_sets",
    "rotation_set_errors",
    "run_real_rotation",
    "summary_lines",
]

#: Exposure modes whose crops are also estimated at the light of the whole set.
SESSION_EXPOSURES = ("map", "session")


def crop_columns(photo: RotationPhoto, left: int, width: int) -> tuple[np.ndarray, Camera]:
    """A full-height crop of ``width`` columns from ``left``, and the camera that took it."""
    h, w = photo.image.shape[:2]
    if left < 0 or width < 2 or left + width > w:
        raise ValueError(f"crop [{left}, {left + width}) is outside the {w}-pixel-wide photo")
    crop = np.ascontiguousarray(photo.image[:, left : left + width])
    cam = Camera.from_focal(
        photo.focal_px,
        width,
        yaw_deg=photo.yaw_deg,
        principal_point=((w - 1) / 2.0 - left, (h - 1) / 2.0),
    )
    return crop, cam


def _learn_all(sensor: ImageCompass, frames: list[tuple[np.ndarray, Camera]]) -> None:
    for image, camera in frames:
        sensor.learn(image, camera)


def rotation_set_errors(
    photos: list[RotationPhoto],
    sensor: ImageCompass,
    prepare: Callable[[ImageCompass, list[tuple[np.ndarray, Camera]]], None] | None = None,
    crop_width_frac: float = 0.5,
    crops_per_photo: int = 3,
    setup: Callable[[ImageCompass, list[tuple[np.ndarray, Camera]]], None] | None = None,
    light: float = 1.0,
    session_gain: bool = False,
) -> dict[str, Any]:
    """Teach ``sensor`` the even photos, then estimate the yaw of crops of the odd ones.

    Parameters
    ----------
    photos : list of RotationPhoto
        One rotation set (at least 4 photos).
    sensor : ImageCompass
        A fresh sensor (the visual compass or a baseline).
    prepare : callable, optional
        ``prepare(sensor, [(image, camera), ...])`` teaches it the training photos
        (default: ``sensor.learn`` on each; a visual compass also needs its colours).
    crop_width_frac : float
        Width of a crop as a fraction of the photo's.
    crops_per_photo : int
        Crops per test photo, spread from the left to the right edge.
    setup : callable, optional
        ``setup(sensor, frames)`` before ``prepare``, not timed (e.g. fitting colour
        classes: once per place, not a cost per frame).
    light : float
        Linear light of the test crops relative to the photos (1: as taken).
    session_gain : bool
        Estimate the light of the whole session first, as the
        :class:`~vc_gym.exposure.SessionLight` (median, in thirds of a stop) of the
        sensor's per-crop :meth:`~vc_gym.compass.VisualCompass.light_gain`
        (``exposure="map"``) or :meth:`~vc_gym.compass.VisualCompass.frame_gain`
        (``exposure="session"``), then estimate every crop with that gain.

    Returns
    -------
    dict
        ``errors_deg`` and ``crops`` per crop, ``n_train``, the milliseconds per
        frame to learn (``learn_ms``) and to estimate (``localise_ms``, median), and
        with ``session_gain`` the ``gain`` used.
    """
    if len(photos) < 4:
        raise ValueError(f"need at least 4 photos, got {len(photos)}")
    light = positive_float("light", light)
    if session_gain and not (
        isinstance(sensor, VisualCompass) and sensor.config.exposure in SESSION_EXPOSURES
    ):
        raise ValueError(f"session_gain needs a VisualCompass with exposure in {SESSION_EXPOSURES}")
    train, test = photos[0::2], photos[1::2]
    frames = [
        (p.image, Camera.from_focal(p.focal_px, p.image.shape[1], yaw_deg=p.yaw_deg)) for p in train
    ]
    if setup is not None:
        setup(sensor, frames)
    t0 = time.perf_counter()
    (prepare or _learn_all)(sensor, frames)
    learn_ms = 1e3 * (time.perf_counter() - t0) / len(frames)
    tests = []
    for p in test:
        w = p.image.shape[1]
        cw = max(2, int(round(w * crop_width_frac)))
        for left in np.linspace(0, w - cw, crops_per_photo).round().astype(int):
            crop, cam = crop_columns(p, int(left), cw)
            if light != 1.0:
                crop = np.take(gain_table(light), crop)
            tests.append((p, int(left), cw, crop, cam))
    extra: dict[str, Any] = {}
    estimate = sensor.estimate
    if session_gain:
        assert isinstance(sensor, VisualCompass)
        read = sensor.light_gain if sensor.config.exposure == "map" else sensor.frame_gain
        gain = SessionLight.of(read(crop, cam) for *_, crop, cam in tests)
        extra["gain"] = gain

        def estimate(image: np.ndarray, camera: Camera) -> Any:
            return sensor.estimate(image, camera, gain=gain)

    errors, crops, cost = [], [], []
    for p, left, cw, crop, cam in tests:
        t0 = time.perf_counter()
        est = estimate(crop, cam)
        cost.append(1e3 * (time.perf_counter() - t0))
        errors.append(abs(float(wrap180(est.heading_deg - p.yaw_deg))))
        crops.append(
            {
                "photo": p.name,
                "left": left,
                "width": cw,
                "true_yaw_deg": p.yaw_deg,
                "estimate_deg": est.heading_deg,
                # a crop without evidence has an infinite spread: JSON has no infinity
                "spread_deg": est.spread_deg if math.isfinite(est.spread_deg) else None,
            }
        )
    return {
        "errors_deg": errors,
        "crops": crops,
        "n_train": len(train),
        "learn_ms": learn_ms,
        "localise_ms": float(np.median(cost)),
        **extra,
    }


def evaluate_rotation_set(
    photos: list[RotationPhoto],
    config: CompassConfig,
    crop_width_frac: float = 0.5,
    crops_per_photo: int = 3,
    light: float = 1.0,
) -> dict[str, object]:
    """Learn from the even photos, estimate the yaw of crops of the odd ones.

    With ``config.exposure`` ``"map"`` or ``"session"`` the crops are estimated twice:
    each on its own (``per_frame_*`` figures: with ``"map"`` a gain per candidate
    heading, with ``"session"`` the crop's own gain), and all with the session's gain
    (the main figures and ``session_gain``; see :func:`rotation_set_errors`).

    Returns
    -------
    dict
        ``median_error_deg``, ``mean_error_deg``, ``within_5deg``, ``within_10deg``,
        ``learned_fraction`` (of the circle covered by training photos), ``errors_deg``
        per crop and the crop details.
    """

    def fit_colors(sensor: VisualCompass, frames: list[tuple[np.ndarray, Camera]]) -> None:
        sensor.fit_colors([image for image, _ in frames])

    def errors(session_gain: bool) -> tuple[VisualCompass, dict[str, Any]]:
        vc = VisualCompass(config)
        r = rotation_set_errors(
            photos,
            vc,
            crop_width_frac=crop_width_frac,
            crops_per_photo=crops_per_photo,
            setup=fit_colors,
            light=light,
            session_gain=session_gain,
        )
        return vc, r

    with_session = config.exposure in SESSION_EXPOSURES
    vc, r = errors(session_gain=with_session)
    e = np.array(r["errors_deg"])
    out: dict[str, object] = {
        "median_error_deg": float(np.median(e)),
        "mean_error_deg": float(np.mean(e)),
        "within_5deg": float(np.mean(e < 5.0)),
        "within_10deg": float(np.mean(e < 10.0)),
        "learned_fraction": vc.learned_fraction,
        "n_train": r["n_train"],
        "n_crops": len(e),
        "errors_deg": [round(float(x), 3) for x in e],
        "crops": r["crops"],
    }
    if with_session:
        out["session_gain"] = r["gain"]
        per_frame = np.array(errors(session_gain=False)[1]["errors_deg"])
        out["per_frame_median_error_deg"] = float(np.median(per_frame))
        out["per_frame_within_5deg"] = float(np.mean(per_frame < 5.0))
    return out


def evaluate_rotation_sets(
    data_dir: str | os.PathLike,
    n_colors: tuple[int, ...] = (10, 3),
    exposures: tuple[str, ...] = ("none", "mean", "map", "session"),
    lights: tuple[float, ...] = (1.0, 0.5),
    progress: bool = False,
) -> dict[str, object]:
    """Run :func:`evaluate_rotation_set` on every rotation set for several configs
    and lights of the test crops."""
    data_dir = Path(data_dir)
    lights = tuple(positive_float("lights", v) for v in lights)
    jobs = [
        (s, c, e, li) for s in ROTATION_SETS for li in lights for c in n_colors for e in exposures
    ]
    iterator = jobs
    if progress:
        from tqdm import tqdm

        iterator = tqdm(jobs, desc="real rotation", unit="run")
    loaded: dict[str, list[RotationPhoto]] = {}
    results = []
    for set_name, c, exposure, light in iterator:
        if set_name not in loaded:
            loaded[set_name] = load_rotation_set(data_dir / set_name)
        cfg = CompassConfig(n_colors=c, exposure=exposure)
        r = evaluate_rotation_set(loaded[set_name], cfg, light=light)
        results.append({"set": set_name, "n_colors": c, "exposure": exposure, "light": light, **r})
    return {"experiment": "real_rotation", "results": results}


def run_real_rotation(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    data_dir: str | os.PathLike | None = None,
) -> dict[str, object]:
    """The ``real-rotation`` experiment: :func:`evaluate_rotation_sets` on the photos in
    ``data_dir``, written to ``out_dir/results.json``.

    Parameters
    ----------
    out_dir : path-like
        Output folder.
    opts : ExperimentOptions, optional
        Only ``progress`` is used (the experiment draws nothing at random).
    data_dir : path-like, optional
        The folder holding ``rotation_grail/`` and ``rotation_parrington/``; default
        :func:`~vc_gym.experiments.real_data.default_real_data_dir`.

    Raises
    ------
    FileNotFoundError
        If there is no such folder.
    """
    opts = opts or ExperimentOptions()
    data = Path(data_dir) if data_dir is not None else default_real_data_dir()
    if data is None or not data.is_dir():
        raise FileNotFoundError(
            "real photos not found: pass --data DIR (the folder holding rotation_grail/ "
            "and rotation_parrington/) or set VC_GYM_REAL_DATA"
        )
    result = evaluate_rotation_sets(data, progress=opts.progress)
    write_json(Path(out_dir) / "results.json", result)
    return result


def summary_lines(results: dict) -> list[str]:
    """A table: set, light, colour classes, exposure, median error, share within 5°."""
    head = f"{'set':22s} {'light':>5s} {'classes':>7s} {'exposure':>8s} {'median':>8s} {'<5°':>5s}"
    lines = [head]
    for r in results["results"]:
        line = (
            f"{r['set']:22s} {r['light']:5.2f} {r['n_colors']:7d} {r['exposure']:>8s} "
            f"{r['median_error_deg']:7.2f}° {r['within_5deg']:5.0%}"
        )
        if "session_gain" in r:
            line += (
                f"  (session gain {r['session_gain']:.2f}; per frame "
                f"{r['per_frame_median_error_deg']:.2f}°, {r['per_frame_within_5deg']:.0%})"
            )
        lines.append(line)
    return lines
