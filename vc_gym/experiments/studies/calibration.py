"""Is the compass' heading spread calibrated? Coverage of ±1σ and ±2σ, before and after.

A calibrated sensor's true heading lies within one reported spread of its estimate for
about 68 % of frames and within two for about 95 %. The paper's spread (eq. 27 of the
posterior of eq. 16) is far too small; :meth:`VisualCompass.calibrate
<vc_gym.compass.VisualCompass.calibrate>` fits a temperature of the log-likelihood
(:mod:`vc_gym.compass.calibration`). This experiment measures both spreads:

- **simulator**: in every scene and for every learning seed the compass learns a
  learning turn at the orientation experiment's training spot (8 directions × a head
  scan, true yaws; colour classes fitted with the learning seed), is calibrated on the
  learning frames themselves, each left out of the map in turn (map time, no other
  data), and then estimates single views at 0, 1 and 2 m from the spot, in random
  directions with random headings;
- **real photos**: each rotation set with the protocol of ``vc-gym experiment
  real-rotation`` (learn 9 alternate photos, estimate crops of the other 9). Its
  learning photos do not overlap (34° views 40° apart), so leave-one-out has nothing to
  go on; the crops are calibrated by 2-fold cross-fitting instead: the temperature
  fitted to the crops of every other test photo is scored on the crops of the rest, and
  the other way round.

``results.json`` holds, per condition, the share of errors within 1σ and 2σ, the median
|error| and the median spread, uncalibrated and calibrated, the fitted temperatures and
the coverage curve (share within ``kσ`` against ``k``); ``calibration.png`` draws the
coverage per condition and the curves beside a Gaussian's.
"""

from __future__ import annotations

import math
import os
import zlib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.compass import Camera, CompassConfig, VisualCompass
from vc_gym.compass.calibration import (
    FLOOR_STEPS,
    UNCALIBRATED,
    fit_temperature,
    heading_errors,
    tempered_spreads,
)
from vc_gym.experiments.real_data import ROTATION_SETS, default_real_data_dir, load_rotation_set
from vc_gym.experiments.real_rotation import crop_columns
from vc_gym.experiments.spot_sensors import room
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    check_scenes,
    open_run,
    pick_size,
    scene_field_bounds,
)
from vc_gym.experiments.studies.orientation_grid import rear_half_centre
from vc_gym.experiments.views import frames_at_pose, learning_turn
from vc_gym.jobs.job import Job
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.sim.scenes import scene_names

__all__ = [
    "DISTANCES_M",
    "GAUSSIAN_COVERAGE",
    "SIGMAS",
    "calibration_real_job",
    "calibration_scene_job",
    "coverage_figures",
    "run_calibration",
    "summary_lines",
]

#: How far from the learning spot the simulated views are taken (metres).
DISTANCES_M = (0.0, 1.0, 2.0)
#: Keep views this far inside the field's bounds (metres).
VIEW_MARGIN_M = 0.3
#: Multiples of the spread at which the coverage curve is read.
SIGMAS = tuple(round(0.25 * k, 2) for k in range(17))
#: Share of a Gaussian within ±1σ and ±2σ: what a calibrated spread gives.
GAUSSIAN_COVERAGE = {"1": math.erf(1 / math.sqrt(2)), "2": math.erf(2 / math.sqrt(2))}
#: The two spreads every condition reports.
SPREADS = ("uncalibrated", "calibrated")
SIZES = {
    "quick": {
        "scenes": ["robolab"],
        "seeds": 1,
        "learn_frames": 3,
        "views": 4,
        "real_n_colors": [10],
    },
    "paper": {"scenes": None, "seeds": 2, "learn_frames": 8, "views": 10, "real_n_colors": [10, 3]},
    "full": {"scenes": None, "seeds": 3, "learn_frames": 8, "views": 24, "real_n_colors": [10, 3]},
}


def _view_poses(
    spot: Sequence[float],
    bounds: Sequence[float],
    distance_m: float,
    n: int,
    rng: np.random.Generator,
) -> list[list[float]]:
    """``n`` poses ``distance_m`` from ``spot`` in random directions inside the field
    (``VIEW_MARGIN_M`` from its edges), each with a random heading; fewer where the
    field has no room at that distance."""
    x0, x1, y0, y1 = (float(v) for v in bounds)
    m = VIEW_MARGIN_M
    poses: list[list[float]] = []
    for _ in range(200 * max(n, 1)):
        if len(poses) == n:
            break
        a = rng.uniform(0.0, 2.0 * math.pi)
        x, y = spot[0] + distance_m * math.cos(a), spot[1] + distance_m * math.sin(a)
        if x0 + m <= x <= x1 - m and y0 + m <= y <= y1 - m:
            poses.append([round(x, 4), round(y, 4), round(float(rng.uniform(0.0, 360.0)), 3)])
    return poses


def _spreads(vc: VisualCompass, lls: np.ndarray) -> dict[str, np.ndarray]:
    """Both spreads of each row of ``lls`` under ``vc``'s map."""
    h = vc.headings_deg
    return {
        "uncalibrated": tempered_spreads(lls, h, *UNCALIBRATED),
        "calibrated": tempered_spreads(lls, h, vc.spread_temperature, vc.spread_floor_deg),
    }


def _records(errors: np.ndarray, spreads: Mapping[str, np.ndarray]) -> list[dict[str, float]]:
    """One plain record per frame: its |error| and both spreads (rounded; a flat
    posterior's infinite spread as 1e9)."""
    return [
        {
            "error_deg": round(float(e), 4),
            **{k: round(min(float(spreads[k][i]), 1e9), 4) for k in SPREADS},
        }
        for i, e in enumerate(errors)
    ]


def calibration_scene_job(
    scene: str,
    spot: list[float],
    views: list[dict[str, Any]],
    learn_frames: int,
    seed: int,
) -> dict[str, Any]:
    """Job: learn and calibrate (leave-one-out) a compass at ``spot``, then read every view.

    Returns ``{"temperature", "loo": {"frames", "skipped", "within_1sigma",
    "within_2sigma"}, "views": [{"distance_m", "error_deg", "uncalibrated",
    "calibrated"}]}`` (a view without evidence is left out and counted in
    ``"no_evidence"``).
    """
    r = room(scene, 1.0)
    learning = learning_turn(r, spot, learn_frames, seed)
    vc = VisualCompass(CompassConfig())
    images = [image for image, _ in learning]
    vc.fit_colors(images[:: max(1, len(images) // 8)], rng=np.random.default_rng(seed))
    for image, camera in learning:
        vc.learn(image, camera)
    report = vc.calibrate(images, [c for _, c in learning], leave_one_out=True)
    camera = learning[0][1].replace(yaw_deg=0.0)
    lls, truth, distances, no_evidence = [], [], [], 0
    for i, view in enumerate(views):
        pose = view["pose"]
        (image, pan, _), *_ = frames_at_pose(r, tuple(pose), 1, seed=seed + 100 + i)
        est = vc.estimate(image, camera)
        if not est.has_evidence:
            no_evidence += 1
            continue
        lls.append(est.log_likelihood)
        truth.append(pose[2] + pan)
        distances.append(view["distance_m"])
    out: dict[str, Any] = {
        "temperature": round(vc.spread_temperature, 4),
        "loo": {
            "frames": report.frames,
            "skipped": report.skipped,
            "within_1sigma": round(report.within_1sigma, 4),
            "within_2sigma": round(report.within_2sigma, 4),
        },
        "no_evidence": no_evidence,
        "views": [],
    }
    if lls:
        ll = np.array(lls)
        errors = heading_errors(ll, np.array(truth), vc.config.heading_step_deg)
        for d, rec in zip(distances, _records(errors, _spreads(vc, ll)), strict=True):
            out["views"].append({"distance_m": d, **rec})
    return out


def calibration_real_job(folder: str, n_colors: int) -> dict[str, Any]:
    """Job: one rotation set, ``n_colors`` classes: learn the even photos (colour classes
    fitted on them), estimate 3 crops of each odd photo, and calibrate by 2-fold
    cross-fitting over the odd photos (alternate photos in each fold).

    Returns ``{"temperatures": [fold 0, fold 1], "crops": [{"error_deg",
    "uncalibrated", "calibrated"}], "loo_usable": the learning photos leave-one-out
    could calibrate on (0: fewer than a temperature needs), "n_train"}``.
    """
    photos = load_rotation_set(folder)
    train, test = photos[0::2], photos[1::2]
    frames = [
        (p.image, Camera.from_focal(p.focal_px, p.image.shape[1], yaw_deg=p.yaw_deg)) for p in train
    ]
    vc = VisualCompass(CompassConfig(n_colors=n_colors))
    vc.fit_colors([image for image, _ in frames])
    for image, camera in frames:
        vc.learn(image, camera)
    try:
        usable = vc.calibrate(*zip(*frames, strict=True), leave_one_out=True).frames
    except ValueError:  # fewer learning photos than a temperature needs
        usable = 0
    lls, truth, photo = [], [], []
    for k, p in enumerate(test):
        w = p.image.shape[1]
        cw = max(2, int(round(w * 0.5)))
        for left in np.linspace(0, w - cw, 3).round().astype(int):
            crop, cam = crop_columns(p, int(left), cw)
            est = vc.estimate(crop, cam)
            if est.has_evidence:
                lls.append(est.log_likelihood)
                truth.append(p.yaw_deg)
                photo.append(k)
    ll = np.array(lls)
    errors = heading_errors(ll, np.array(truth), vc.config.heading_step_deg)
    floor = FLOOR_STEPS * vc.config.heading_step_deg
    fold = np.array(photo) % 2
    calibrated = np.empty(len(errors))
    temperatures = []
    for f in (0, 1):
        fit, held = fold == f, fold != f
        t = fit_temperature(ll[fit], errors[fit], vc.headings_deg, floor)
        temperatures.append(round(t, 4))
        calibrated[held] = tempered_spreads(ll[held], vc.headings_deg, t, floor)
    spreads = {"uncalibrated": tempered_spreads(ll, vc.headings_deg, *UNCALIBRATED)}
    spreads["calibrated"] = calibrated
    return {
        "temperatures": temperatures,
        "loo_usable": int(usable),
        "n_train": len(train),
        "crops": _records(errors, spreads),
    }


def coverage_figures(records: Sequence[Mapping[str, float]]) -> dict[str, Any]:
    """Per spread: the share of errors within 1σ and 2σ, the median spread and the
    coverage curve over :data:`SIGMAS`; and the median |error| and the count."""
    e = np.array([r["error_deg"] for r in records], dtype=np.float64)
    out: dict[str, Any] = {
        "n": int(e.size),
        "median_abs_error_deg": round(float(np.median(e)), 3) if e.size else None,
    }
    for kind in SPREADS:
        s = np.array([r[kind] for r in records], dtype=np.float64)
        if not e.size:
            out[kind] = None
            continue
        out[kind] = {
            "within_1sigma": round(float(np.mean(e <= s)), 4),
            "within_2sigma": round(float(np.mean(e <= 2.0 * s)), 4),
            "median_spread_deg": round(float(np.median(s)), 3),
            "curve": [round(float(np.mean(e <= k * s)), 4) for k in SIGMAS],
        }
    return out


def run_calibration(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    scenes: Sequence[str] | None = None,
    seeds: Sequence[int] | None = None,
    data_dir: str | os.PathLike | None = None,
) -> dict[str, Any]:
    """Run the calibration experiment; write ``results.json``, ``run.json`` and
    ``calibration.png``.

    Parameters
    ----------
    out_dir : path-like
        The run folder (resumable).
    opts : ExperimentOptions
        Seed (learning seeds from it on, view poses) and size.
    scenes : sequence of str, optional
        Registered scenes (default: every registered scene; ``--quick``: robolab).
    seeds : sequence of int, optional
        Learning seeds (default by size, from ``opts.seed`` on): each seeds the colour
        fitting, the learning turn and the views.
    data_dir : path-like, optional
        Folder of the real rotation sets (default ``../shared/data/real`` when it
        exists; without it the real part is skipped and the results say so).

    Returns
    -------
    dict
        ``simulated``: per distance (all scenes) and per scene and distance, the
        :func:`coverage_figures`; the fitted temperatures per scene and seed and the
        leave-one-out figures. ``real``: per set and number of colour classes the same,
        with the cross-fitted temperatures.
    """
    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    default_scenes = size["scenes"] or list(scene_names())
    scenes = check_scenes(list(scenes) if scenes else default_scenes)
    seeds = list(seeds) if seeds else [opts.seed + k for k in range(size["seeds"])]
    real = Path(data_dir) if data_dir is not None else default_real_data_dir()
    if real is not None and not all((real / s).is_dir() for s in ROTATION_SETS):
        raise ValueError(f"--data {real}: expected the folders {sorted(ROTATION_SETS)}")
    settings = {
        "scenes": scenes,
        "seeds": seeds,
        "distances_m": list(DISTANCES_M),
        "learn_frames": size["learn_frames"],
        "views": size["views"],
        "real_n_colors": size["real_n_colors"],
        "floor_steps": FLOOR_STEPS,
    }
    run = open_run(out_dir, "calibration", opts, settings)
    jobs = []
    for scene in scenes:
        bounds = scene_field_bounds(scene)
        spot = rear_half_centre(bounds)
        for seed in seeds:
            rng = np.random.default_rng([seed, 83, zlib.crc32(scene.encode())])
            views = [
                {"distance_m": d, "pose": pose}
                for d in DISTANCES_M
                for pose in _view_poses(spot, bounds, d, size["views"], rng)
            ]
            kwargs = {
                "scene": scene,
                "spot": list(spot),
                "views": views,
                "learn_frames": size["learn_frames"],
                "seed": int(seed),
            }
            jobs.append(Job(f"{scene}-seed{seed}", f"{__name__}:calibration_scene_job", kwargs))
    outputs = run.run("views", jobs)
    results: dict[str, Any] = {
        "learning_seeds": seeds,
        "gaussian": {k: round(v, 4) for k, v in GAUSSIAN_COVERAGE.items()},
        "sigmas": list(SIGMAS),
        "simulated": _summarise_scenes(scenes, seeds, outputs),
    }
    if real is not None:
        keys = [(s, c) for s in ROTATION_SETS for c in size["real_n_colors"]]
        real_jobs = [
            Job(
                f"{s}-{c}colors",
                f"{__name__}:calibration_real_job",
                {"folder": str(real / s), "n_colors": c},
            )
            for s, c in keys
        ]
        real_out = run.run("real", real_jobs)
        results["real"] = {
            f"{s} {c} classes": {
                "temperatures": o["temperatures"],
                "loo_usable_photos": f"{o['loo_usable']} of {o['n_train']}",
                **coverage_figures(o["crops"]),
            }
            for (s, c), o in zip(keys, real_out, strict=True)
            if o is not None
        }
    else:
        results["real"] = None
        results["real_skipped"] = "no ../shared/data/real folder (give --data DIR)"
    _plot(run.out / "calibration.png", results)
    return run.finish(results)


def _summarise_scenes(
    scenes: Sequence[str], seeds: Sequence[int], outputs: Sequence[Mapping[str, Any] | None]
) -> dict[str, Any]:
    """Coverage per distance over all scenes and per scene; temperatures and the
    leave-one-out figures per scene and seed."""
    per_job = [
        (scene, seed, o)
        for (scene, seed), o in zip(
            [(sc, sd) for sc in scenes for sd in seeds], outputs, strict=True
        )
        if o is not None
    ]
    out: dict[str, Any] = {"all_scenes": {}, "scenes": {}, "temperatures": {}, "loo": {}}
    for d in DISTANCES_M:
        key = f"{d:g}m"
        views = [v for _, _, o in per_job for v in o["views"] if v["distance_m"] == d]
        out["all_scenes"][key] = coverage_figures(views)
        for scene in scenes:
            mine = [v for sc, _, o in per_job if sc == scene for v in o["views"]]
            mine = [v for v in mine if v["distance_m"] == d]
            out["scenes"].setdefault(scene, {})[key] = coverage_figures(mine)
    for scene, seed, o in per_job:
        out["temperatures"].setdefault(scene, {})[str(seed)] = o["temperature"]
        out["loo"].setdefault(scene, {})[str(seed)] = o["loo"]
    out["no_evidence_views"] = int(sum(o["no_evidence"] for _, _, o in per_job))
    return out


def _conditions(results: Mapping[str, Any]) -> list[tuple[str, Mapping[str, Any]]]:
    """``(label, coverage figures)`` of every condition the table and the plot show."""
    rows = [
        (f"sim {key} (all scenes)", fig)
        for key, fig in results["simulated"]["all_scenes"].items()
        if fig["n"]
    ]
    rows += [(f"real {name}", fig) for name, fig in (results.get("real") or {}).items()]
    return rows


def _plot(path: Path, results: Mapping[str, Any]) -> None:
    """Left: share within 1σ and 2σ per condition, uncalibrated (hollow) and calibrated
    (filled), against a Gaussian's; right: the calibrated coverage curves."""
    rows = _conditions(results)
    fig = new_figure(figsize=(12, 4.5), layout="constrained")
    ax, ax2 = fig.subplots(1, 2)
    x = np.arange(len(rows))
    for j, (sigma, marker) in enumerate((("1", "o"), ("2", "s"))):
        for kind, face in (("uncalibrated", "none"), ("calibrated", f"C{j}")):
            ys = [fig_[kind][f"within_{sigma}sigma"] for _, fig_ in rows]
            ax.scatter(
                x + (0.12 if kind == "calibrated" else -0.12),
                ys,
                marker=marker,
                s=40,
                facecolors=face,
                edgecolors=f"C{j}",
                label=f"±{sigma}σ {kind}",
                zorder=3,
            )
        ax.axhline(GAUSSIAN_COVERAGE[sigma], color=f"C{j}", ls=":", lw=1)
    ax.set_xticks(x, [label for label, _ in rows], rotation=25, ha="right", fontsize=8)
    ax.set_ylim(-0.02, 1.02)
    ax.set_ylabel("share of true headings within ±kσ")
    ax.set_title("coverage per condition (dotted: a Gaussian's 68 % and 95 %)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    k = np.array(results["sigmas"])
    ax2.plot(k, [math.erf(v / math.sqrt(2)) for v in k], "k--", lw=1, label="Gaussian")
    for i, (label, fig_) in enumerate(rows):
        ax2.plot(k, fig_["calibrated"]["curve"], "-", color=f"C{i % 10}", lw=1.2, label=label)
    ax2.set_xlabel("k (multiples of the calibrated spread)")
    ax2.set_ylabel("share of |error| <= k · spread")
    ax2.set_title("reliability of the calibrated spread", fontsize=10)
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=7)
    save_figure(fig, path)


def summary_lines(results: Mapping[str, Any]) -> list[str]:
    """A table: condition, frames, median |error|, then for the uncalibrated and the
    calibrated spread its median and the shares within 1σ and 2σ; the temperatures."""
    head = (
        f"{'condition':34s} {'n':>4s} {'med|err|':>8s}   "
        f"{'uncalibrated: spread  1σ   2σ':>30s}   {'calibrated: spread  1σ   2σ':>28s}"
    )
    lines = [head]
    for label, fig in _conditions(results):
        parts = []
        for kind in SPREADS:
            f = fig[kind]
            spread, one, two = f["median_spread_deg"], f["within_1sigma"], f["within_2sigma"]
            parts.append(f"{spread:10.2f}° {one:4.0%} {two:4.0%}")
        lines.append(
            f"{label:34s} {fig['n']:4d} {fig['median_abs_error_deg']:7.2f}°   "
            f"{'':>12s}{parts[0]}   {'':>10s}{parts[1]}"
        )
    sim = results["simulated"]
    temps = {sc: sorted(v.values()) for sc, v in sim["temperatures"].items()}
    lines.append(
        "leave-one-out temperatures per scene (over learning seeds): "
        + ", ".join(f"{sc} {', '.join(f'{t:g}' for t in ts)}" for sc, ts in temps.items())
    )
    for name, fig in (results.get("real") or {}).items():
        lines.append(
            f"real {name}: cross-fitted temperatures {fig['temperatures']}; leave-one-out "
            f"usable photos {fig['loo_usable_photos']}"
        )
    if results.get("real_skipped"):
        lines.append(f"real photos skipped: {results['real_skipped']}")
    for f in results.get("failed_jobs", []):
        lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
    return lines
