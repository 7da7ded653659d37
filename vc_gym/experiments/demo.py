"""The package's main job: one learn-then-home episode in the simulated robot lab.

The scripted robot learns the panorama at four spots 1 m around home, is kidnapped to
a random pose on the field and walks back home with its orientational and translational
filters (paper 4.3, 5.2). Writes ``summary.json`` and ``demo.png``.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.agents.scripted import EpisodeRecord, LearnThenHomeConfig, ScriptedLearnThenHome
from vc_gym.envs.top_view import TopView
from vc_gym.experiments.output import save_figure, write_json

__all__ = ["run_demo"]


def run_demo(
    out_dir: str | os.PathLike = "vc_gym_demo",
    seed: int = 0,
    learn_time_s: float = 5.0,
    success_radius_m: float = 0.3,
    progress: bool = True,
) -> dict[str, object]:
    """Run one scripted learn-then-home episode in the robolab and save the results.

    Parameters
    ----------
    out_dir : path-like
        Where ``summary.json`` and ``demo.png`` go.
    seed : int
        Seed of the env (odometry errors) and of the kidnapping pose.
    learn_time_s : float
        Learning time per direction (paper: 5 s).
    success_radius_m : float
        The episode succeeds if the robot stops within this distance of home.
    progress : bool
        Progress bars per phase.

    Returns
    -------
    dict
        The summary also written to ``summary.json``.
    """
    if not (np.isfinite(success_radius_m) and success_radius_m > 0):
        raise ValueError(f"success_radius_m must be > 0, got {success_radius_m}")
    t0 = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    env = gym.make("vc_gym/AiboRoom-v0", scene="robolab", max_episode_steps=10**7)
    try:
        agent = ScriptedLearnThenHome(
            env, LearnThenHomeConfig(learn_time_s=learn_time_s), progress=progress
        )
        record = agent.run(seed=seed)
        result = record.summary()
        summary = {
            "task": "learn 4 spots 1 m around home, kidnapping, homing (scripted)",
            "scene": "robolab",
            "seed": seed,
            **result,
            "success": bool(record.stopped and result["home_error_m"] <= success_radius_m),
            "success_radius_m": success_radius_m,
            "start_pose": list(record.start) if record.start else None,
            "odometry_turn_calibration": agent.learner.rot_scale,
        }
        _plot(out / "demo.png", record, TopView(env.unwrapped.client, env.unwrapped.scene))
    finally:
        env.close()
    summary["duration_s"] = round(time.perf_counter() - t0, 1)
    write_json(out / "summary.json", summary)
    return summary


def _plot(path: Path, record: EpisodeRecord, top: TopView) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # world extent of the top view at floor level
    half = (top.size / 2.0) / top.focal * 40.0
    cx, cy = top.center
    extent = (cx - half, cx + half, cy - half, cy + half)
    fig, (ax, ax2) = plt.subplots(
        1, 2, figsize=(13, 6), gridspec_kw={"width_ratios": [1, 1.2]}, constrained_layout=True
    )
    ax.imshow(top.background, extent=extent, alpha=0.85)
    learn = np.array(record.learn_true)
    if learn.size:
        ax.plot(learn[:, 0], learn[:, 1], color="0.8", lw=1, label="learning walk (true)")
    for name, (x, y) in record.spots.items():
        ax.plot(x, y, "x", color="yellow", ms=10, mew=3)
        ax.annotate(name, (x, y), color="yellow", xytext=(5, 5), textcoords="offset points")
    ax.plot(*record.home, "+", color="white", ms=14, mew=2, label="home")
    true = np.array(record.true)
    est = np.array(record.estimated)
    if true.size:
        ax.plot(true[:, 0], true[:, 1], color="tab:red", lw=2, label="homing, true")
        ax.plot(est[:, 0], est[:, 1], color="tab:cyan", lw=1.5, ls="--", label="homing, estimated")
        ax.plot(true[0, 0], true[0, 1], "o", color="tab:red", ms=8, label="kidnapped to")
    if record.stop is not None:
        ax.plot(*record.stop, "*", color="magenta", ms=16, label="stop")
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    err = record.summary()["home_error_m"] if record.stop is not None else float("nan")
    ax.set_title(f"robolab: learn 4 spots, kidnap, walk home (stop {err * 100:.0f} cm from home)")
    ax.legend(loc="lower left", fontsize=8)
    if record.heading_error:
        t = np.arange(len(record.heading_error)) * 0.1
        ax2.plot(t, np.abs(record.heading_error), color="tab:blue")
        ax2.set_yscale("log")
        d = np.hypot(true[:, 0] - record.home[0], true[:, 1] - record.home[1])
        ax3 = ax2.twinx()
        ax3.plot(t, d, color="tab:red", lw=1)
        ax3.set_ylabel("true distance to home (m)", color="tab:red")
    ax2.set_xlabel("homing time (s)")
    ax2.set_ylabel("|heading error| (deg)", color="tab:blue")
    ax2.set_title("orientational filter error and distance to home during homing")
    save_figure(fig, path, dpi=90)
