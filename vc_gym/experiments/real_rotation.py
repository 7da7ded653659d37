"""The compass on real photos of a camera turning in place.

For each rotation set (18 photos over a full turn, yaw ground truth from the
stitching of the photos): fit colour classes on and learn from 9 alternate photos,
then estimate the yaw of crops of the other 9 photos. A crop keeps the photo's focal
length and optical axis (its principal point moves), so its true yaw is the photo's.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.compass import Camera, CompassConfig, ImageCompass, VisualCompass
from vc_gym.experiments.real_data import ROTATION_SETS, RotationPhoto, load_rotation_set

__all__ = ["crop_columns", "evaluate_rotation_set", "rotation_set_errors", "run_real_rotation"]


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

    Returns
    -------
    dict
        ``errors_deg`` and ``crops`` per crop, ``n_train``, and the milliseconds per
        frame to learn (``learn_ms``) and to estimate (``localise_ms``, median).
    """
    if len(photos) < 4:
        raise ValueError(f"need at least 4 photos, got {len(photos)}")
    train, test = photos[0::2], photos[1::2]
    frames = [
        (p.image, Camera.from_focal(p.focal_px, p.image.shape[1], yaw_deg=p.yaw_deg)) for p in train
    ]
    if setup is not None:
        setup(sensor, frames)
    t0 = time.perf_counter()
    (prepare or _learn_all)(sensor, frames)
    learn_ms = 1e3 * (time.perf_counter() - t0) / len(frames)
    errors, crops, cost = [], [], []
    for p in test:
        w = p.image.shape[1]
        cw = max(2, int(round(w * crop_width_frac)))
        for left in np.linspace(0, w - cw, crops_per_photo).round().astype(int):
            crop, cam = crop_columns(p, int(left), cw)
            t0 = time.perf_counter()
            est = sensor.estimate(crop, cam)
            cost.append(1e3 * (time.perf_counter() - t0))
            errors.append(abs(float(wrap180(est.heading_deg - p.yaw_deg))))
            crops.append(
                {
                    "photo": p.name,
                    "left": int(left),
                    "width": cw,
                    "true_yaw_deg": p.yaw_deg,
                    "estimate_deg": est.heading_deg,
                    "spread_deg": est.spread_deg,
                }
            )
    return {
        "errors_deg": errors,
        "crops": crops,
        "n_train": len(train),
        "learn_ms": learn_ms,
        "localise_ms": float(np.median(cost)),
    }


def evaluate_rotation_set(
    photos: list[RotationPhoto],
    config: CompassConfig,
    crop_width_frac: float = 0.5,
    crops_per_photo: int = 3,
) -> dict[str, object]:
    """Learn from the even photos, estimate the yaw of crops of the odd ones.

    Returns
    -------
    dict
        ``median_error_deg``, ``mean_error_deg``, ``within_5deg``, ``within_10deg``,
        ``learned_fraction`` (of the circle covered by training photos), ``errors_deg``
        per crop and the crop details.
    """
    vc = VisualCompass(config)

    def fit_colours(sensor: VisualCompass, frames: list[tuple[np.ndarray, Camera]]) -> None:
        sensor.fit_colors([image for image, _ in frames])

    r = rotation_set_errors(
        photos,
        vc,
        crop_width_frac=crop_width_frac,
        crops_per_photo=crops_per_photo,
        setup=fit_colours,
    )
    e = np.array(r["errors_deg"])
    return {
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


def run_real_rotation(
    data_dir: str | os.PathLike,
    n_colors: tuple[int, ...] = (10, 3),
    exposures: tuple[str, ...] = ("none", "mean"),
    progress: bool = False,
) -> dict[str, object]:
    """Run :func:`evaluate_rotation_set` on every rotation set for several configs."""
    data_dir = Path(data_dir)
    jobs = [(s, c, e) for s in ROTATION_SETS for c in n_colors for e in exposures]
    iterator = jobs
    if progress:
        from tqdm import tqdm

        iterator = tqdm(jobs, desc="real rotation", unit="run")
    loaded: dict[str, list[RotationPhoto]] = {}
    results = []
    for set_name, c, exposure in iterator:
        if set_name not in loaded:
            loaded[set_name] = load_rotation_set(data_dir / set_name)
        cfg = CompassConfig(n_colors=c, exposure=exposure)
        r = evaluate_rotation_set(loaded[set_name], cfg)
        results.append({"set": set_name, "n_colors": c, "exposure": exposure, **r})
    return {"experiment": "real_rotation", "data_dir": str(data_dir), "results": results}
