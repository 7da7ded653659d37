"""Cost and accuracy of every filter, measured side by side in one run.

1. Cost: median time of one motion + sensor update of each filter on a simple heading
   sensor (so that the filter, not the sensor, is timed): the grid filter at 1° (both
   rules), the particle filter with 1,000 and 10,000 particles, the Kalman filter and
   the translational filter.
2. Accuracy: one seeded tracking run in a synthetic room — a robot turning with noisy,
   biased odometry, a 208×160 camera frame per step and the real ``VisualCompass`` as
   the sensor of every filter — with each filter's mean heading error, next to raw
   compass readings and odometry alone.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.compass import (
    AIBO_RESOLUTION,
    Camera,
    CompassConfig,
    VisualCompass,
)
from vc_gym.filters.heading_grid import HeadingGridFilter
from vc_gym.filters.heading_kalman import KalmanHeadingFilter
from vc_gym.filters.particle_filter import ParticleFilter
from vc_gym.filters.synthetic_sensors import VonMisesHeadingSensor
from vc_gym.filters.translational import TranslationalFilter
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.localization import CompassHeadingSensor
from vc_gym.validation import check_seed, int_in_range
from vc_gym.worlds.room import make_room, render_room_view

__all__ = ["bench_filters", "tracking_run"]

DT_S = 1.0 / 30.0
#: Most timed rounds of the cost benchmark.
MAX_REPEATS = 1_000
#: Fewest and most steps of the tracking run.
MIN_STEPS, MAX_STEPS = 8, 100_000
FIELD = (-3.0, 3.0, -2.0, 2.0)


def _median_ms(fn: Callable[[], object], repeats: int, inner: int) -> float:
    fn()
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(inner):
            fn()
        samples.append((time.perf_counter() - t0) / inner)
    return float(np.median(samples) * 1e3)


def _cost(repeats: int, seed: int) -> dict[str, float]:
    rng = np.random.default_rng(seed)
    sensor = VonMisesHeadingSensor(noise_deg=10.0)
    reading = 42.0
    grid_mix = HeadingGridFilter(rule="mixing", dt_s=DT_S)
    grid_bayes = HeadingGridFilter(rule="bayes", dt_s=DT_S)
    pf1k = ParticleFilter(1000, bounds=FIELD, rng=np.random.default_rng(seed))
    pf10k = ParticleFilter(10000, bounds=FIELD, rng=np.random.default_rng(seed))
    kf = KalmanHeadingFilter(0.0, 180.0)
    goodness = rng.uniform(0.5, 1.5, 4)
    tf = TranslationalFilter(np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]]))

    def grid_step(f: HeadingGridFilter) -> None:
        f.predict(1.5, 1.0)
        f.update(sensor, reading)

    def pf_step(f: ParticleFilter) -> None:
        f.predict((0.01, 0.0, 1.5), (0.005, 0.005, 1.0))
        f.update(sensor, reading)

    def kf_step() -> None:
        kf.predict(1.5, 1.0)
        kf.update(reading, 10.0)

    def tf_step() -> None:
        tf.predict(0.01, 0.0)
        tf.update(goodness)

    jobs = {
        "grid_1deg_mixing": lambda: grid_step(grid_mix),
        "grid_1deg_bayes": lambda: grid_step(grid_bayes),
        "particle_1000": lambda: pf_step(pf1k),
        "particle_10000": lambda: pf_step(pf10k),
        "kalman_ukf": kf_step,
        "translational": tf_step,
    }
    samples: dict[str, list[float]] = {k: [] for k in jobs}
    # interleave the filters so machine noise hits all of them alike
    for _ in range(repeats):
        for name, fn in jobs.items():
            inner = 3 if name == "particle_10000" else 20
            samples[name].append(_median_ms(fn, 1, inner))
    return {f"{k}_update_ms": float(np.median(v)) for k, v in samples.items()}


def _occlude(img: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Cover 30-60 % of the frame's width with a person-sized block of random colour."""
    h, w = img.shape[:2]
    bw = int(rng.uniform(0.3, 0.6) * w)
    x0 = int(rng.integers(0, w - bw + 1))
    out = img.copy()
    out[:, x0 : x0 + bw] = rng.integers(0, 256, 3, dtype=np.uint8)
    return out


def tracking_run(steps: int = 240, seed: int = 0, occlusion_prob: float = 0.15) -> dict:
    """One seeded heading-tracking run with the real compass; errors per filter.

    The compass learns at the centre of a synthetic 7×7 m room (8 × 45° with head
    pans), then the robot walks away from that spot (up to 1 m, so parallax makes the
    compass less certain, paper 5.1) while turning at up to 90°/s; its odometry
    overestimates turns by 10 % with noise, and ``occlusion_prob`` of the frames are
    half covered (a person walking by). Every filter uses the compass as its sensor.

    Returns a dict with ``truth_deg`` and, per method, ``estimates_deg`` and the mean,
    median and max absolute error.
    """
    rng = np.random.default_rng(seed)
    w, h = AIBO_RESOLUTION
    room = make_room(rng)
    vc = VisualCompass(CompassConfig())
    vc.fit_colors(
        [render_room_view(room, 0.0, 0.0, Camera(yaw_deg=a), w, h) for a in range(0, 360, 45)]
    )
    for yaw in [b + p for b in range(0, 360, 45) for p in (-22.5, 0.0, 22.5)]:
        vc.learn(render_room_view(room, 0.0, 0.0, Camera(yaw_deg=yaw), w, h), Camera(yaw_deg=yaw))
    sensor = CompassHeadingSensor(vc, Camera())

    rates = np.concatenate(
        [np.full(steps // 4, 90.0), np.zeros(steps // 4), np.full(steps // 4, -60.0)]
    )
    rates = np.concatenate([rates, np.full(steps - rates.size, 30.0)]) * DT_S
    truth = np.mod(rng.uniform(0, 360) + np.cumsum(rates + rng.normal(0, 0.2, steps)), 360.0)
    odometry = np.diff(np.r_[truth[0] - rates[0], truth])
    odometry = wrap180(odometry) * 1.1 + rng.normal(0, 0.5, steps)
    # position: spiralling out from the learning spot to 1 m
    radius = np.linspace(0.0, 1.0, steps)
    angle = np.linspace(0.0, 2.0 * np.pi, steps)
    xs, ys = radius * np.cos(angle), radius * np.sin(angle)

    grid_mix = HeadingGridFilter(rule="mixing", dt_s=DT_S)
    grid_bayes = HeadingGridFilter(rule="bayes", dt_s=DT_S)
    pf = ParticleFilter(1000, bounds=FIELD, rng=np.random.default_rng(seed + 1))
    kf = KalmanHeadingFilter(0.0, 180.0)
    names = ("compass_only", "odometry_only", "grid_mixing", "grid_bayes", "particle_1000")
    est: dict[str, list[float]] = {k: [] for k in (*names, "kalman_ukf")}
    dead_reckoning = float(truth[0])  # odometry alone, started at the true heading
    motion_noise = 1.0
    for t in range(steps):
        img = render_room_view(room, xs[t], ys[t], Camera(yaw_deg=float(truth[t])), w, h)
        if rng.random() < occlusion_prob:
            img = _occlude(img, rng)
        compass = vc.estimate(img, Camera())
        est["compass_only"].append(compass.heading_deg)
        dead_reckoning += odometry[t]
        est["odometry_only"].append(dead_reckoning)
        ll = sensor.heading_log_likelihood(img, grid_mix.headings_deg)
        for f, name in ((grid_mix, "grid_mixing"), (grid_bayes, "grid_bayes")):
            f.predict(odometry[t], motion_noise)
            f.update_log_likelihood(ll)
            est[name].append(f.estimate().heading_deg)
        pf.predict((0.0, 0.0, odometry[t]), (0.0, 0.0, motion_noise))
        pf.update(sensor, img)
        est["particle_1000"].append(pf.estimate().heading_deg)
        kf.predict(odometry[t], motion_noise)
        kf.update(compass.heading_deg, max(compass.spread_deg, 1.0))
        est["kalman_ukf"].append(kf.estimate().heading_deg)

    out: dict[str, object] = {"steps": steps, "dt_s": DT_S, "truth_deg": truth.tolist()}
    for name, values in est.items():
        err = np.abs(wrap180(np.array(values) - truth))
        out[name] = {
            "mean_error_deg": float(err.mean()),
            "median_error_deg": float(np.median(err)),
            "max_error_deg": float(err.max()),
            "estimates_deg": [round(float(v) % 360.0, 3) for v in values],
        }
    return out


def bench_filters(
    repeats: int = 30, steps: int = 240, seed: int = 0, plot: str | os.PathLike | None = None
) -> dict[str, object]:
    """Run the cost and the tracking benchmarks; optionally save a PNG of the run.

    ``repeats`` (1 to :data:`MAX_REPEATS`), ``steps`` (:data:`MIN_STEPS` to
    :data:`MAX_STEPS`), ``seed`` and ``plot`` (a writable file) are checked before any
    work.
    """
    int_in_range("repeats", repeats, 1, MAX_REPEATS)
    int_in_range("steps", steps, MIN_STEPS, MAX_STEPS)
    check_seed("seed", seed)
    if plot is not None:
        from vc_gym.jobs.output import check_out_file

        check_out_file(plot, "plot")
    cost = _cost(repeats, seed)
    track = tracking_run(steps, seed)
    summary = {
        name: {k: v for k, v in track[name].items() if k != "estimates_deg"}
        for name in track
        if isinstance(track[name], dict)
    }
    if plot is not None:
        _plot(Path(plot), track)
    return {"benchmark": "filters", **cost, "tracking": summary, "repeats": repeats}


def _plot(path: Path, track: dict) -> None:
    truth = np.array(track["truth_deg"])
    unwrapped = np.degrees(np.unwrap(np.radians(truth)))
    t = np.arange(truth.size) * track["dt_s"]
    fig = new_figure(figsize=(10, 6), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    axes[0].plot(t, unwrapped, "k", lw=2, label="true heading")
    for name, v in track.items():
        if not isinstance(v, dict):
            continue
        err = wrap180(np.array(v["estimates_deg"]) - truth)
        # drawn around the unwrapped truth so that crossing 0/360 draws no jumps
        axes[0].plot(t, unwrapped + err, lw=1, label=name)
        label = f"{name} (mean {v['mean_error_deg']:.2f}°)"
        axes[1].plot(t, np.abs(err), lw=1, label=label)
    axes[0].set_ylabel("heading, unwrapped (deg)")
    axes[0].legend(fontsize=7, ncol=4)
    axes[1].set_yscale("log")
    axes[1].set_ylabel("|error| (deg)")
    axes[1].set_xlabel("time (s)")
    axes[1].legend(fontsize=7, ncol=3)
    fig.suptitle(
        "Heading tracking with the visual compass: walking up to 1 m from the learning spot, "
        "15 % of frames occluded"
    )
    save_figure(fig, path, dpi=100)
