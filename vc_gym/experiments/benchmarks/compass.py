"""Speed of the compass per 208×160 frame, against the floor of copying its pixels.

Every figure is measured in one run, side by side: for each test frame the floor
(copying the scanned pixels once), learning and localisation are timed in turn, so
machine noise hits all of them alike. Medians are reported.
"""

from __future__ import annotations

import platform
import time
from collections.abc import Callable

import numpy as np

from vc_gym.compass import AIBO_RESOLUTION, Camera, CompassConfig, VisualCompass
from vc_gym.validation import check_seed, int_in_range
from vc_gym.worlds.panorama import render_view
from vc_gym.worlds.panorama_painters import make_panorama

__all__ = ["MAX_FRAMES", "MAX_INNER", "MAX_REPEATS", "bench_compass"]

#: Most distinct test frames (each is rendered and kept in memory, ~100 KB).
MAX_FRAMES = 1_000
#: Most timed rounds.
MAX_REPEATS = 1_000
#: Most calls per timing sample.
MAX_INNER = 10_000

#: Figures the paper reports for the Sony Aibo (section 5.3), milliseconds per frame.
PAPER_LEARN_MS = 4.0
PAPER_LOCALIZE_MS = 13.0


def _time_us(fn: Callable[[], object], inner: int) -> float:
    t0 = time.perf_counter()
    for _ in range(inner):
        fn()
    return (time.perf_counter() - t0) / inner * 1e6


def bench_compass(
    frames: int = 40,
    repeats: int = 15,
    inner: int = 20,
    config: CompassConfig | None = None,
    seed: int = 0,
    progress: bool = False,
) -> dict[str, object]:
    """Measure learning and localisation time per frame at the paper's defaults.

    Parameters
    ----------
    frames : int
        Distinct test frames (random yaws in a synthetic room), 1 to
        :data:`MAX_FRAMES`.
    repeats : int
        Timed rounds; each round times every frame once per quantity (1 to
        :data:`MAX_REPEATS`).
    inner : int
        Calls per timing sample (divides timer overhead away; 1 to
        :data:`MAX_INNER`).
    config : CompassConfig, optional
        Compass parameters (default: the paper's).
    seed : int
        Seed of the synthetic room and the yaws.
    progress : bool
        Show a progress bar.

    Returns
    -------
    dict
        ``learn_ms``, ``localize_ms``, ``estimate_ms``, ``floor_ms`` (copying the
        scanned pixels once), ``pixels_per_s`` (scanned pixels localised per second),
        the ratios to the floor, the paper's Aibo figures and run details.
    """
    int_in_range("frames", frames, 1, MAX_FRAMES)
    int_in_range("repeats", repeats, 1, MAX_REPEATS)
    int_in_range("inner", inner, 1, MAX_INNER)
    check_seed("seed", seed)
    rng = np.random.default_rng(seed)
    cfg = config if config is not None else CompassConfig()
    width, height = AIBO_RESOLUTION
    pano = make_panorama(rng, kind="room")
    cam = Camera()
    vc = VisualCompass(cfg)
    vc.fit_colors([render_view(pano, Camera(yaw_deg=a), width, height) for a in range(0, 360, 45)])
    for yaw in np.arange(0.0, 360.0, 15.0):
        vc.learn(render_view(pano, Camera(yaw_deg=yaw), width, height), Camera(yaw_deg=yaw))
    yaws = rng.uniform(0.0, 360.0, frames)
    images = [render_view(pano, Camera(yaw_deg=y), width, height) for y in yaws]
    # a separate compass to learn into, so the benchmarked map stays the same
    learner = VisualCompass(cfg, vc.colors)
    geom = vc._geometry(cam, width, height)
    scanned = int(geom.grid.rows.size * geom.grid.cols.size)
    vc.log_likelihood(images[0], cam)  # build the cached tables outside the timing

    samples: dict[str, list[float]] = {"floor": [], "learn": [], "localize": [], "estimate": []}
    iterator = range(repeats)
    if progress:
        from tqdm import tqdm

        iterator = tqdm(iterator, desc="bench compass", unit="round")
    for _ in iterator:
        for img, yaw in zip(images, yaws, strict=True):
            learn_cam = Camera(yaw_deg=float(yaw))
            samples["floor"].append(
                _time_us(lambda img=img: img[geom.row_slice, geom.col_slice].copy(), inner)
            )
            samples["learn"].append(
                _time_us(lambda img=img, c=learn_cam: learner.learn(img, c), inner)
            )
            samples["localize"].append(_time_us(lambda img=img: vc.log_likelihood(img, cam), inner))
            samples["estimate"].append(_time_us(lambda img=img: vc.estimate(img, cam), inner))

    med = {k: float(np.median(v)) / 1000.0 for k, v in samples.items()}
    errors = [
        abs((vc.estimate(img, cam).heading_deg - y + 180.0) % 360.0 - 180.0)
        for img, y in zip(images, yaws, strict=True)
    ]
    return {
        "benchmark": "compass",
        "frame": f"{width}x{height}",
        "config": cfg.to_dict(),
        "scanned_pixels": scanned,
        "learn_ms": med["learn"],
        "localize_ms": med["localize"],
        "estimate_ms": med["estimate"],
        "floor_ms": med["floor"],
        "pixels_per_s": scanned / (med["localize"] / 1000.0),
        "localize_over_floor": med["localize"] / med["floor"],
        "learn_over_floor": med["learn"] / med["floor"],
        "paper_aibo_learn_ms": PAPER_LEARN_MS,
        "paper_aibo_localize_ms": PAPER_LOCALIZE_MS,
        "median_heading_error_deg": float(np.median(errors)),
        "frames": frames,
        "repeats": repeats,
        "inner": inner,
        "numpy": np.__version__,
        "python": platform.python_version(),
        "machine": platform.machine(),
    }
