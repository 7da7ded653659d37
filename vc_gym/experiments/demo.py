"""The package's main job: one learn-then-home episode in the simulated robot lab.

The scripted robot learns the panorama at four spots 1 m around home, is kidnapped to
a random pose on the field and walks back home with its tracker (by default the
paper's orientational and translational filters, 4.3, 5.2). It is exactly the first
episode of ``vc-gym evaluate --seed S`` (same env, same policy, same episode runner).
Writes ``summary.json`` and ``demo.png``.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from vc_gym.envs.learning import LearningResult, ScriptedLearning
from vc_gym.experiments.episode import (
    DEFAULT_HOMING_MODE,
    HOMING_MODES,
    EpisodeRecord,
    canonical_homing_mode,
    homing_mode,
    make_homing_run,
    run_episode,
)
from vc_gym.jobs.output import new_figure, new_out_dir, save_figure, write_json
from vc_gym.localization import TrackerSpec, make_tracker, tracker_label
from vc_gym.sim.top_view import TopView
from vc_gym.validation import (
    MAX_HOMING_S,
    MAX_LEARN_TIME_S,
    MAX_SEED,
    flag,
    int_in_range,
    positive_float,
    positive_float_at_most,
)

__all__ = ["check_demo_args", "run_demo"]


def run_demo(
    out_dir: str | os.PathLike = "vc_gym_demo",
    seed: int = 0,
    learn_time_s: float = 5.0,
    success_radius_m: float = 0.3,
    tracker: TrackerSpec = None,
    max_homing_s: float = 60.0,
    progress: bool = True,
    mode: str = DEFAULT_HOMING_MODE,
) -> dict[str, object]:
    """Run one scripted learn-then-home episode in the robolab and save the results.

    The place is learned after ``reset(seed=seed)`` and the robot is kidnapped with
    ``reset(seed=seed + 1)``: the first episode of ``vc-gym experiment homing`` with
    the same seed and mode.

    Parameters
    ----------
    out_dir : path-like
        Where ``summary.json`` and ``demo.png`` go (created only once every argument
        has been checked, and removed again if the run fails before writing them).
    seed : int
        Seed of the learning phase, ``0..MAX_SEED - 1``; the kidnapping uses
        ``seed + 1``.
    learn_time_s : float
        Learning time per direction (paper: 5 s; at most
        :data:`~vc_gym.validation.MAX_LEARN_TIME_S`).
    success_radius_m : float
        The episode succeeds if the robot stops within this distance of home.
    tracker : str, dict or callable
        The tracker (:func:`vc_gym.localization.make_tracker`); default the mode's
        (the paper's filters, ``grid``; ``pose-grid`` for ``pose-home``).
    max_homing_s : float
        Homing time limit (at most :data:`~vc_gym.validation.MAX_HOMING_S`).
    progress : bool
        Progress bars per phase.
    mode : str
        How the place is learned and the robot homes
        (:data:`~vc_gym.experiments.episode.HOMING_MODES`): ``"check-home"`` (default:
        normalised at the true home, home checked with a full turn before stopping) or
        ``"paper"`` (the paper's procedure).

    Returns
    -------
    dict
        The summary also written to ``summary.json``.

    Raises
    ------
    ValueError
        For any argument out of range, before the folder is made or anything is run.
    """
    check_demo_args(seed, learn_time_s, success_radius_m, tracker, max_homing_s, progress, mode)
    mode = canonical_homing_mode(mode)
    tracker = homing_mode(mode).tracker if tracker is None else tracker
    with new_out_dir(out_dir) as out:
        t0 = time.perf_counter()
        run = make_homing_run(
            "scripted",
            tracker=tracker,
            learn_time_s=learn_time_s,
            success_radius_m=success_radius_m,
            max_homing_s=max_homing_s,
            learner=ScriptedLearning(progress=progress),
            mode=mode,
        )
        try:
            run.env.reset(seed=seed)  # the learning phase
            record = run_episode(run, seed=seed + 1, progress=progress)
            u = run.env.unwrapped
            learned = u.learning_result
            summary = {
                "task": "learn 4 spots 1 m around home, kidnapping, homing (scripted)",
                "scene": "robolab",
                "tracker": tracker_label(tracker),
                "learning_seed": seed,
                "mode": mode,
                **record.summary(),
                "success_radius_m": success_radius_m,
                "odometry_turn_calibration": learned.odometry_turn_scale,
            }
            _plot(out / "demo.png", record, learned, TopView(u.room.client, u.room.scene))
        finally:
            run.close()
        summary["duration_s"] = round(time.perf_counter() - t0, 1)
        write_json(out / "summary.json", summary)
    return summary


def check_demo_args(
    seed: object = 0,
    learn_time_s: object = 5.0,
    success_radius_m: object = 0.3,
    tracker: TrackerSpec = None,
    max_homing_s: object = 60.0,
    progress: object = True,
    mode: object = DEFAULT_HOMING_MODE,
    names: dict[str, str] | None = None,
) -> None:
    """Check :func:`run_demo`'s arguments before anything is made or run.

    Parameters
    ----------
    seed, learn_time_s, success_radius_m, tracker, max_homing_s, progress, mode
        As :func:`run_demo`.
    names : dict, optional
        The names to use in error messages, by argument (a command's flags, e.g.
        ``{"seed": "--seed", "learn_time_s": "--learn-time"}``).

    Raises
    ------
    ValueError
        Naming the argument and its accepted range.
    """
    names = dict(names or {})

    def name(arg: str) -> str:
        return names.get(arg, arg)

    int_in_range(name("seed"), seed, 0, MAX_SEED - 1)  # the kidnapping uses seed + 1
    positive_float_at_most(name("learn_time_s"), learn_time_s, MAX_LEARN_TIME_S)
    positive_float(name("success_radius_m"), success_radius_m)
    positive_float_at_most(name("max_homing_s"), max_homing_s, MAX_HOMING_S)
    flag(name("progress"), progress)
    try:
        canonical_homing_mode(mode)
    except ValueError:
        raise ValueError(
            f"{name('mode')} must be one of {list(HOMING_MODES)}, got {mode!r}"
        ) from None
    make_tracker(tracker)


def _plot(path: Path, record: EpisodeRecord, learned: LearningResult, top: TopView) -> None:
    extent = top.extent  # the floor the top view shows
    fig = new_figure(figsize=(13, 6), layout="constrained")
    ax, ax2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.2]})
    ax.imshow(top.background, extent=extent, alpha=0.85)
    learn = np.array(learned.true_path)
    if learn.size:
        ax.plot(learn[:, 0], learn[:, 1], color="0.8", lw=1, label="learning walk (true)")
    for name, (x, y) in learned.spots.items():
        if "." in name:  # a turn learned around a spot (around_m): marked, not named
            ax.plot(x, y, "x", color="yellow", ms=5, mew=1.5)
            continue
        ax.plot(x, y, "x", color="yellow", ms=10, mew=3)
        ax.annotate(name, (x, y), color="yellow", xytext=(5, 5), textcoords="offset points")
    ax.plot(*record.home, "+", color="white", ms=14, mew=2, label="home")
    true = np.array(record.true)
    est = np.array(record.estimated)
    if true.size:
        ax.plot(true[:, 0], true[:, 1], color="tab:red", lw=2, label="homing, true")
        ax.plot(est[:, 0], est[:, 1], color="tab:cyan", lw=1.5, ls="--", label="homing, estimated")
        ax.plot(*record.start_pose[:2], "o", color="tab:red", ms=8, label="kidnapped to")
    if record.stop_position is not None:
        ax.plot(*record.stop_position, "*", color="magenta", ms=16, label="stop")
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(
        f"robolab: learn 4 spots, kidnap, walk home (stop {record.stop_error_m * 100:.0f} cm "
        "from home)"
    )
    ax.legend(loc="lower left", fontsize=8)
    if record.heading_error:
        t = np.arange(len(record.heading_error)) * record.dt_s
        ax2.plot(t, np.maximum(np.abs(record.heading_error), 1e-2), color="tab:blue")
        ax2.set_yscale("log")
        d = np.hypot(true[:, 0] - record.home[0], true[:, 1] - record.home[1])
        ax3 = ax2.twinx()
        ax3.plot(np.arange(len(d)) * record.dt_s, d, color="tab:red", lw=1)
        ax3.set_ylim(0.0, 1.1 * max(float(d.max()), 0.1))  # from 0: never an offset axis
        ax3.set_ylabel("true distance to home (m)", color="tab:red")
    ax2.set_xlabel("homing time (s)")
    ax2.set_ylabel("|heading error| (deg)", color="tab:blue")
    ax2.set_title("heading error of the tracker and distance to home during homing")
    save_figure(fig, path, dpi=90)
