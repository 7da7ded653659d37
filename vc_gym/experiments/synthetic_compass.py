"""The compass on synthetic panoramas at normal and half illumination.

Learns a room panorama the way the paper's robot does (8 body directions of 45°, each
with head scanning, paper 4.3), then estimates the heading of random test frames at
normal and at half illumination (paper 5.3), and writes ``results.json``
and ``synthetic_compass.png``. Four exposure modes: none (the paper), ``mean`` (every
frame scaled to the learned mean light), ``map`` (every candidate heading scored with
the gain that brings the frame to the light the map learned in that direction, per frame)
and ``session`` (the test frames of one light are one session, all scored at its
:class:`~vc_gym.exposure.SessionLight`).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from tqdm import tqdm

from vc_gym.angles import wrap180
from vc_gym.compass import AIBO_RESOLUTION, Camera, CompassConfig, VisualCompass
from vc_gym.experiments.studies.common import ExperimentOptions
from vc_gym.exposure import SessionLight
from vc_gym.jobs.output import new_figure, save_figure, write_json
from vc_gym.worlds.panorama import Panorama, render_view
from vc_gym.worlds.panorama_painters import make_panorama

__all__ = ["run_synthetic_compass", "summary_lines"]

HEAD_PANS_DEG = (-22.5, 0.0, 22.5)
BODY_YAWS_DEG = tuple(range(0, 360, 45))
EXPOSURES = ("none", "mean", "map", "session")


def _learn(vc: VisualCompass, pano: Panorama, label: str) -> None:
    w, h = AIBO_RESOLUTION
    views = [(b + p) for b in BODY_YAWS_DEG for p in HEAD_PANS_DEG]
    for yaw in tqdm(views, desc=f"learn {label}", unit="frame", leave=False):
        vc.learn(render_view(pano, Camera(yaw_deg=yaw), w, h), Camera(yaw_deg=yaw))


def _evaluate(
    vc: VisualCompass, pano: Panorama, yaws: np.ndarray, illumination: float, label: str
) -> tuple[np.ndarray, float | None]:
    """Signed heading errors of test frames at ``yaws``, and the session gain they were
    scored at (``exposure="session"``; ``None`` otherwise)."""
    w, h = AIBO_RESOLUTION
    images = [
        render_view(pano, Camera(yaw_deg=float(yaw)), w, h, illumination=illumination)
        for yaw in yaws
    ]
    gain = None
    if vc.config.exposure == "session":
        gain = SessionLight.of(vc.frame_gain(img, Camera()) for img in images)
    errs = []
    for yaw, img in tqdm(
        list(zip(yaws, images, strict=True)), desc=f"localise {label}", unit="frame", leave=False
    ):
        errs.append(float(wrap180(vc.estimate(img, Camera(), gain=gain).heading_deg - yaw)))
    return np.array(errs), gain


def run_synthetic_compass(
    out_dir: str | os.PathLike = "vc_gym_synthetic",
    opts: ExperimentOptions | None = None,
    n_test: int = 120,
) -> dict:
    """Run the experiment; write ``results.json`` and ``synthetic_compass.png`` to
    ``out_dir``.

    Parameters
    ----------
    out_dir : path-like
        Output folder.
    opts : ExperimentOptions, optional
        Only ``seed`` is used (the panoramas and the test yaws derive from it).
    n_test : int
        Test frames per panorama, exposure and light.

    Returns
    -------
    dict
        What ``results.json`` holds (figures only).
    """
    seed = (opts or ExperimentOptions()).seed
    if n_test < 1:
        raise ValueError(f"n_test must be >= 1, got {n_test}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    w, h = AIBO_RESOLUTION
    results: dict[str, dict] = {}
    curves = {}
    panos = {}
    for kind in ("room", "outdoor"):
        pano = make_panorama(rng, kind=kind)
        panos[kind] = pano
        yaws = rng.uniform(0.0, 360.0, n_test)
        for exposure in EXPOSURES:
            label = f"{kind}/exposure={exposure}"
            vc = VisualCompass(CompassConfig(exposure=exposure))
            vc.fit_colors([render_view(pano, Camera(yaw_deg=a), w, h) for a in BODY_YAWS_DEG])
            _learn(vc, pano, label)
            entry = {}
            for illum in (1.0, 0.5):
                errs, gain = _evaluate(vc, pano, yaws, illum, f"{label} light={illum}")
                a = np.abs(errs)
                entry[f"illumination_{illum}"] = {
                    "median_error_deg": float(np.median(a)),
                    "within_5deg": float(np.mean(a < 5.0)),
                    "max_error_deg": float(a.max()),
                    **({} if gain is None else {"session_gain": gain}),
                }
                curves[(kind, exposure, illum)] = (yaws, errs)
            results[label] = entry
            if kind == "room" and exposure == "none":
                test_yaw = float(yaws[0])
                img = render_view(pano, Camera(yaw_deg=test_yaw), w, h)
                example = (img, test_yaw, vc.estimate(img, Camera()), vc.headings_deg.copy())
    summary = {
        "experiment": "visual compass on synthetic panoramas (learn 8 x 45 deg with head pans)",
        "seed": seed,
        "frames_per_test": n_test,
        "frame": f"{w}x{h}",
        "results": results,
    }
    _plot(out / "synthetic_compass.png", panos, curves, example)
    write_json(out / "results.json", summary)
    return summary


def _plot(path: Path, panos: dict, curves: dict, example: tuple) -> None:
    img, test_yaw, est, headings = example
    fig = new_figure(figsize=(13, 9), layout="constrained")
    grid = fig.add_gridspec(3, 3)
    ax = fig.add_subplot(grid[0, :])
    pano = panos["room"]
    ax.imshow(pano.image, extent=(360, 0, pano.elev_bottom_deg, pano.elev_top_deg), aspect="auto")
    for b in BODY_YAWS_DEG:
        ax.axvline(b, color="yellow", lw=1, ls="--")
    ax.axvline(test_yaw, color="red", lw=2, label=f"test frame, true yaw {test_yaw:.1f}°")
    ax.set_xlabel("azimuth (deg, CCW)")
    ax.set_ylabel("elevation (deg)")
    ax.set_title(
        "Synthetic room panorama; yellow: the 8 learning directions (each ±22.5° head pan)"
    )
    ax.legend(loc="upper right")

    ax = fig.add_subplot(grid[1, 0])
    ax.imshow(img)
    ax.set_title(f"test frame 208×160, estimate {est.heading_deg:.1f}°")
    ax.axis("off")
    ax = fig.add_subplot(grid[1, 1:])
    ax.plot(headings, est.log_likelihood, lw=1)
    ax.axvline(test_yaw, color="red", lw=1, label="true yaw")
    ax.set_xlabel("candidate heading (deg)")
    ax.set_ylabel("log-likelihood ratio")
    ax.set_title("compass output for the test frame (eq. 16)")
    ax.legend()

    for i, kind in enumerate(("room", "outdoor")):
        ax = fig.add_subplot(grid[2, i])
        for (k, exposure, illum), (yaws, errs) in curves.items():
            if k != kind:
                continue
            marker = "o" if illum == 1.0 else "x"
            ax.scatter(yaws, errs, s=10, marker=marker, label=f"exposure={exposure}, light×{illum}")
        ax.set_ylim(-180, 180)
        ax.set_xlabel("true heading (deg)")
        ax.set_ylabel("error (deg)")
        ax.set_title(f"{kind}: heading error per test frame")
        ax.legend(fontsize=7)
    ax = fig.add_subplot(grid[2, 2])
    labels, medians = [], []
    for (k, exposure, illum), (_, errs) in curves.items():
        labels.append(f"{k}\n{exposure}\n×{illum}")
        medians.append(float(np.median(np.abs(errs))))
    ax.bar(range(len(medians)), medians)
    ax.set_xticks(range(len(medians)), labels, fontsize=6)
    ax.set_yscale("log")
    ax.set_ylabel("median |error| (deg)")
    ax.set_title("median error")
    save_figure(fig, path, dpi=100)


def summary_lines(results: dict) -> list[str]:
    """One line per panorama and exposure: median error and share within 5° per light."""
    lines = []
    for label, entry in results["results"].items():
        parts = [
            f"light×{k.split('_')[1]}: median {v['median_error_deg']:.2f}°, "
            f"{v['within_5deg']:.0%} within 5°"
            + (f" (session gain {v['session_gain']:.2f})" if "session_gain" in v else "")
            for k, v in entry.items()
        ]
        lines.append(f"{label:28s} " + " | ".join(parts))
    return lines
