"""Full-field localisation from maps on a grid of spots (the paper's open problem, 5.2).

The paper's position estimate (eq. 30) can only answer points inside its spots' hull, and
its goodness says how well a frame fits a spot, not how far the spot is. Here the robot
learns a map at every spot of a coarse grid over the field (placed by hand at each spot
and turned through 8 × 45°, like the paper's orientation experiment), and is then put at
a finer grid of test poses. Two position estimates are compared on the same frames:

``paper``
    Eq. 30 over all spots: the goodness-weighted mean of the spot positions.
``calibrated``
    Each spot's goodness is calibrated against distance on held-out frames taken while
    learning at the spots and halfway between neighbouring spots (where a robot walking
    from spot to spot passes, knowing by odometry where it is): a saturating fall
    ``score_i ≈ a_i − b_i · (1 − exp(−d/λ))`` with residual spread ``σ_i``. A frame's
    scores then give a likelihood over the whole field,
    ``Π_i N(score_i; a_i − b_i·(1 − exp(−d_i(x)/λ)), σ_i)``, whose mean is the estimate
    and whose spread its uncertainty.

The same two, and a third, are also computed from a **full turn** on the spot: the robot
turns through ``turn_headings`` directions (the checking turn of the check-home homing
policy) and each spot's score is averaged over the turn. A single view's score depends
on where the camera looks as much as on where the robot stands; over a turn much of
that spread averages out, so the distance information carries. Calibration for the
turn methods uses turns at the calibration points, which here also include points on
the field's border beyond the outer spots (where a learning robot can walk too):

``turn_calibrated``
    The ``calibrated`` likelihood on turn-averaged scores and turn calibration.
``turn_nearest``
    Place recognition by the turn's score signature: the ``k`` calibration places whose
    turn-averaged scores are nearest (each spot's score divided by its residual spread),
    weighted by inverse signature distance; their weighted spread is the uncertainty.

The estimators are public in :mod:`vc_gym.localization`
(:func:`~vc_gym.localization.locate_by_goodness`,
:func:`~vc_gym.localization.locate_by_turn_signature`); this module takes the frames in
the simulator and compares them.

Results: mean, median and 90th-percentile position error over the field per method, the
share of true positions inside each uncertain method's 2σ, and a PNG of the error fields.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

import vc_gym.localization
from vc_gym.compass import Camera, CompassAtlas, CompassConfig, VisualCompass
from vc_gym.deprecation import moved_names
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    one_scene,
    open_run,
    pick_size,
    scene_field_bounds,
)
from vc_gym.experiments.views import field_grid, frames_at_pose, view_poses
from vc_gym.jobs.job import Job
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.jobs.workers import worker_cache
from vc_gym.localization import (
    calibrate_goodness,
    goodness_calibration,
    locate_by_goodness,
    locate_by_turn_signature,
    mean_spot_scores,
)
from vc_gym.localization.spot_scores import finite_array
from vc_gym.localization.turn_signature import NEAREST_K
from vc_gym.sim.aibo_room import AiboRoomEnv

__all__ = ["locate_eq30", "run_localization", "summary_lines"]

#: The estimators moved to :mod:`vc_gym.localization` (public API for trackers and
#: agents): their old names here still work for one release, with a DeprecationWarning.
__getattr__ = moved_names(
    __name__,
    {
        "calibrate": (vc_gym.localization, "calibrate_goodness"),
        "calibration_points": (vc_gym.localization, "calibration_points"),
        "locate_calibrated": (vc_gym.localization, "locate_by_goodness"),
        "locate_nearest": (vc_gym.localization, "locate_by_turn_signature"),
        "BORDER_MARGIN_M": (goodness_calibration, "BORDER_MARGIN_M"),
        "GRID_STEP_M": (goodness_calibration, "GRID_STEP_M"),
        "LENGTH_SCALES_M": (goodness_calibration, "LENGTH_SCALES_M"),
    },
)

SIZES = {
    "quick": {
        "spot_spacing_m": 3.0,
        "steps": 2,
        "test_spacing_m": 2.0,
        "headings": 1,
        "frames": 2,
        "calibration_headings": 2,
        "turn_headings": 4,
        "turn_frames": 1,
    },
    "paper": {
        "spot_spacing_m": 1.5,
        "steps": 8,
        "test_spacing_m": 0.5,
        "headings": 1,
        "frames": 4,
        "calibration_headings": 4,
        "turn_headings": 8,
        "turn_frames": 2,
    },
    "full": {
        "spot_spacing_m": 1.5,
        "steps": 16,
        "test_spacing_m": 0.33,
        "headings": 2,
        "frames": 6,
        "calibration_headings": 8,
        "turn_headings": 8,
        "turn_frames": 3,
    },
}
#: Margin of the spot grid inside the field (metres).
SPOT_MARGIN_M = 0.5


def _room(scene: str) -> AiboRoomEnv:
    return worker_cache(("room", scene, "{}"), lambda: AiboRoomEnv(scene=scene))


def learn_grid_job(
    scene: str,
    spots: list[list[float]],
    steps: int,
    calibration_headings: int,
    seed: int,
    path: str,
    turn_headings: int = 0,
    turn_frames: int = 1,
) -> dict[str, Any]:
    """Job: learn a map at every spot (8 × 45°, head scanning) and the calibration frames.

    Colour classes are fitted once, on the first frame of every direction at the spot
    nearest the field centre, and shared by every map (the goodness of different spots
    is then comparable). Calibration frames (random headings, not learned) are taken at
    every calibration point (:func:`~vc_gym.localization.calibration_points`, with the
    field's border); their raw scores under every map are saved with the atlas, and
    with ``turn_headings`` also the scores averaged over a turn at each point
    (:func:`turn_scores`).
    """
    room = _room(scene)
    room.reset(seed=seed)
    camera = Camera(hfov_deg=room.camera.hfov_deg)
    pts = np.asarray(spots, np.float64)
    x0, x1, y0, y1 = room.scene.field_bounds
    centre = int(np.argmin(np.hypot(pts[:, 0] - (x0 + x1) / 2, pts[:, 1] - (y0 + y1) / 2)))
    fit = [frames_at_pose(room, (*pts[centre], 45.0 * k), 1, seed=seed)[0][0] for k in range(8)]
    config = CompassConfig()
    colors = VisualCompass(config).fit_colors(fit).colors
    maps = {}
    for i, (x, y) in enumerate(pts):
        vc = VisualCompass(config, colors)
        for k in range(8):
            for image, pan, _ in frames_at_pose(
                room, (x, y, 45.0 * k), steps, seed=seed + 100 * i + k
            ):
                vc.learn(image, camera.replace(yaw_deg=45.0 * k + pan))
        maps[f"spot{i}"] = ((float(x), float(y)), vc)
    atlas = CompassAtlas(maps, home=f"spot{centre}")
    rng = np.random.default_rng([seed, 77])
    positions, scores, turns = [], [], []
    places = vc_gym.localization.calibration_points(pts, room.scene.field_bounds)
    for i, (x, y) in enumerate(places):
        for h in rng.uniform(0.0, 360.0, calibration_headings):
            for image, _, _ in frames_at_pose(room, (x, y, float(h)), 2, seed=seed + 50_000 + i):
                raw, _ = atlas.scores(image, camera)
                positions.append([float(x), float(y)])
                scores.append([round(float(v), 6) for v in raw])
        if turn_headings:
            start = float(rng.uniform(0.0, 360.0 / turn_headings))
            turn = turn_scores(
                room,
                atlas,
                camera,
                (x, y),
                start,
                turn_headings,
                turn_frames,
                seed=seed + 70_000 + 100 * i,
            )
            turns.append([round(float(v), 6) for v in turn])
    calibration: dict[str, Any] = {"calibration": {"positions": positions, "scores": scores}}
    if turn_headings:
        calibration["turn_calibration"] = {"positions": places.round(4).tolist(), "scores": turns}
    atlas.save(path, metadata=calibration)
    return {"spots": len(pts), "calibration_frames": len(scores), "turns": len(turns)}


def turn_scores(
    room: AiboRoomEnv,
    atlas: CompassAtlas,
    camera: Camera,
    position: Sequence[float],
    start_deg: float,
    headings: int,
    frames: int,
    seed: int,
) -> np.ndarray:
    """Every spot's raw score averaged over a turn on the spot.

    The robot is put at ``position`` facing ``start_deg + k·360/headings`` for
    ``k = 0 … headings−1`` and takes ``frames`` frames (head scanning) at each: the
    turn's signature (:func:`~vc_gym.localization.mean_spot_scores`).
    """
    images = [
        image
        for k in range(headings)
        for image, _, _ in frames_at_pose(
            room,
            (float(position[0]), float(position[1]), start_deg + k * 360.0 / headings),
            frames,
            seed=seed + k,
        )
    ]
    return mean_spot_scores(atlas, images, camera)


def locate_job(
    scene: str,
    atlas: str,
    poses: list[list[float]],
    frames: int,
    seed: int,
    turn_headings: int = 0,
    turn_frames: int = 1,
) -> dict[str, Any]:
    """Job: every spot's raw score (mean over the frames) at each pose of one position,
    and with ``turn_headings`` the scores averaged over a turn there (from each pose's
    heading)."""
    room = _room(scene)
    loaded = worker_cache(("atlas", atlas), lambda: CompassAtlas.load(atlas))
    camera = Camera(hfov_deg=room.camera.hfov_deg)
    out = []
    for k, pose in enumerate(poses):
        images = [image for image, _, _ in frames_at_pose(room, tuple(pose), frames, seed=seed + k)]
        view = {"pose": pose, "scores": mean_spot_scores(loaded, images, camera).round(6).tolist()}
        if turn_headings:
            turn = turn_scores(
                room,
                loaded,
                camera,
                pose[:2],
                float(pose[2]),
                turn_headings,
                turn_frames,
                seed=seed + 500 + 20 * k,
            )
            view["turn_scores"] = turn.round(6).tolist()
        out.append(view)
    return {"views": out}


def locate_eq30(scores: np.ndarray, spots: np.ndarray, sharpness: float) -> np.ndarray:
    """Eq. 30 over every spot: weights ``∝ exp(sharpness · score)``.

    The paper's estimate, the baseline of this experiment: the spots' positions
    weighted by ``L_i^sharpness`` (``L_i = exp(score_i)``, eq. 28), so a larger
    sharpness snaps to the best-fitting spot.

    Parameters
    ----------
    scores : array_like
        ``(M,)`` raw score of the frame under each spot's map.
    spots : array_like
        ``(M, 2)`` training spots ``(x, y)``, metres.
    sharpness : float
        Exponent of the goodness (> 0), e.g. the atlas' ``sharpness``.

    Returns
    -------
    numpy.ndarray
        ``(2,)`` the weighted mean of the spots.
    """
    spots = finite_array("spots", spots, (None, 2))
    scores = finite_array("scores", scores, (spots.shape[0],))
    if not (np.isfinite(sharpness) and sharpness > 0):
        raise ValueError(f"sharpness must be finite and > 0, got {sharpness}")
    logw = sharpness * (scores - scores.max())
    w = np.exp(logw)
    return (w / w.sum()) @ spots


def run_localization(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    scenes: Sequence[str] | None = None,
) -> dict[str, Any]:
    """Run the full-field localisation experiment; write results, run.json and the PNG.

    Parameters
    ----------
    out_dir : path-like
        The run folder (resumable).
    opts : ExperimentOptions
        Seed, size (spot grid spacing, test grid), backend, progress.
    scenes : sequence of str, optional
        One scene (default ``["robolab"]``).

    Returns
    -------
    dict
        Per method: position error statistics over the field; for the calibrated
        method also the share of true positions within its 2σ.
    """
    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    scene = one_scene(scenes, "localization experiment")
    run = open_run(out_dir, "localization", opts, {"scene": scene, **size})
    bounds = scene_field_bounds(scene)
    spots = field_grid(bounds, size["spot_spacing_m"], margin_m=SPOT_MARGIN_M)
    spot_list = [[round(float(x), 4), round(float(y), 4)] for x, y in spots]
    spec = {
        "scene": scene,
        "spots": spot_list,
        "steps": size["steps"],
        "calibration_headings": size["calibration_headings"],
        "turn_headings": size["turn_headings"],
        "turn_frames": size["turn_frames"],
        "seed": opts.seed,
    }
    digest = hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:10]
    folder = run.out / "atlases"
    folder.mkdir(exist_ok=True)
    path = str((folder / f"{scene}-grid-seed{opts.seed}-{digest}.npz").resolve())
    if not Path(path).is_file():
        run.job_file("learn", "grid").unlink(missing_ok=True)
    run.run("learn", [Job("grid", f"{__name__}:learn_grid_job", {**spec, "path": path})])
    if not Path(path).is_file():
        raise RuntimeError(f"learning the grid of spots failed; see {run.out / 'jobs' / 'learn'}")
    atlas, meta = CompassAtlas.load_with_metadata(path)
    cal = meta["calibration"]
    model = calibrate_goodness(atlas.positions, np.array(cal["positions"]), np.array(cal["scores"]))

    test = field_grid(bounds, size["test_spacing_m"], margin_m=0.25)
    poses = view_poses(test, size["headings"], np.random.default_rng([opts.seed, 91]))
    h = size["headings"]
    jobs = [
        Job(
            f"pos-{i:04d}",
            f"{__name__}:locate_job",
            {
                "scene": scene,
                "atlas": path,
                "poses": [[round(float(v), 4) for v in p] for p in poses[i * h : (i + 1) * h]],
                "frames": size["frames"],
                "seed": int(opts.seed * 1_000_000 + 1000 + i * 1000),
                "turn_headings": size["turn_headings"],
                "turn_frames": size["turn_frames"],
            },
        )
        for i in range(len(test))
    ]
    views = [v for o in run.run("views", jobs) if o is not None for v in o["views"]]
    results: dict[str, Any] = {
        "paper": {
            "claim": "eq. 30 answers only inside the spots' hull; the best related "
            "result the paper cites: ~50 cm"
        },
        "spots": spot_list,
        "calibration": {
            "a": model.a.round(5).tolist(),
            "b": model.b.round(5).tolist(),
            "sigma": model.sigma.round(5).tolist(),
            "length_m": model.length_m,
            "frames": len(cal["scores"]),
        },
        "methods": {},
    }
    if views:
        true = np.array([v["pose"][:2] for v in views])
        scores = np.array([v["scores"] for v in views])
        spots = atlas.positions
        estimates: dict[str, tuple[np.ndarray, np.ndarray | None]] = {
            "paper": (np.array([locate_eq30(s, spots, atlas.sharpness) for s in scores]), None),
            "calibrated": _stacked([locate_by_goodness(s, spots, model, bounds) for s in scores]),
        }
        if "turn_calibration" in meta and all("turn_scores" in v for v in views):
            places = np.array(meta["turn_calibration"]["positions"])
            place_scores = np.array(meta["turn_calibration"]["scores"])
            turn_model = calibrate_goodness(spots, places, place_scores)
            turns = np.array([v["turn_scores"] for v in views])
            estimates["turn_calibrated"] = _stacked(
                [locate_by_goodness(s, spots, turn_model, bounds) for s in turns]
            )
            estimates["turn_nearest"] = _stacked(
                [locate_by_turn_signature(s, places, place_scores, turn_model.sigma) for s in turns]
            )
            results["turn_calibration"] = {
                "sigma": turn_model.sigma.round(5).tolist(),
                "length_m": turn_model.length_m,
                "places": len(places),
                "nearest_k": NEAREST_K,
            }
        for name, (est, std) in estimates.items():
            results["methods"][name] = _errors(est, std, true)
        results["true_positions"] = true.round(4).tolist()
        _plot(
            run.out / "localization.png",
            true,
            {PLOT_NAMES[name]: est for name, (est, _) in estimates.items()},
            spots,
            bounds,
        )
    return run.finish(results)


#: Panel titles of the methods in the PNG.
PLOT_NAMES = {
    "paper": "paper (eq. 30, one view)",
    "calibrated": "calibrated (one view)",
    "turn_calibrated": "calibrated (full turn)",
    "turn_nearest": "nearest signatures (full turn)",
}


def _stacked(located: Sequence[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    return np.array([m for m, _ in located]), np.array([s for _, s in located])


def _errors(est: np.ndarray, std: np.ndarray | None, true: np.ndarray) -> dict[str, Any]:
    err = np.hypot(*(est - true).T)
    out: dict[str, Any] = {
        "mean_error_m": round(float(err.mean()), 4),
        "median_error_m": round(float(np.median(err)), 4),
        "p90_error_m": round(float(np.percentile(err, 90)), 4),
        "estimates": est.round(4).tolist(),
    }
    if std is not None:
        z = np.abs(est - true) / np.maximum(std, 1e-6)
        out["within_2_sigma"] = round(float(np.mean(np.all(z <= 2.0, axis=1))), 4)
        out["mean_std_m"] = std.mean(axis=0).round(4).tolist()
    return out


def _plot(
    path: Path,
    true: np.ndarray,
    estimates: Mapping[str, np.ndarray],
    spots: np.ndarray,
    bounds: Sequence[float],
) -> None:
    from matplotlib.patches import Rectangle

    cols = min(2, len(estimates))
    rows = -(-len(estimates) // cols)
    fig = new_figure(figsize=(6 * cols, 4.3 * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    for ax in axes[len(estimates) :]:
        ax.set_visible(False)
    x0, x1, y0, y1 = bounds
    # one colour scale for every panel, so that colours compare across methods
    vmax = max(
        1.0, *(float(np.percentile(np.hypot(*(e - true).T), 95)) for e in estimates.values())
    )
    for ax, (name, est) in zip(axes, estimates.items(), strict=False):
        err = np.hypot(*(est - true).T)
        sc = ax.scatter(
            true[:, 0],
            true[:, 1],
            c=err,
            cmap="viridis_r",
            vmin=0,
            vmax=vmax,
            s=40,
        )
        ax.quiver(
            true[:, 0],
            true[:, 1],
            est[:, 0] - true[:, 0],
            est[:, 1] - true[:, 1],
            angles="xy",
            scale_units="xy",
            scale=1,
            width=0.003,
            color="0.3",
        )
        ax.plot(spots[:, 0], spots[:, 1], "x", color="tab:red", ms=8, mew=2, label="spots")
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, color="0.4"))
        ax.set_aspect("equal")
        ax.set_title(f"{name}: mean error {err.mean() * 100:.0f} cm", fontsize=10)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.legend(fontsize=7, loc="upper right")
        fig.colorbar(sc, ax=ax, label="position error (m)", shrink=0.8)
    fig.suptitle(
        "position over the field from a grid of spots (arrows: true → estimate)", fontsize=11
    )
    save_figure(fig, path)


def summary_lines(results: Mapping[str, Any]) -> list[str]:
    """Position error per method."""
    lines = []
    for name, m in results.get("methods", {}).items():
        extra = ""
        if "within_2_sigma" in m:
            extra = f", {m['within_2_sigma']:.0%} of true positions within its 2σ"
        lines.append(
            f"{name:10s} mean error {m['mean_error_m'] * 100:.1f} cm, median "
            f"{m['median_error_m'] * 100:.1f} cm, 90th percentile {m['p90_error_m'] * 100:.1f} cm"
            + extra
        )
    for f in results.get("failed_jobs", []):
        lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
    return lines
