"""The paper's homing experiment repeated: stop positions over many kidnappings (5.2).

Each episode is a full learn-then-home run with its own seed (odometry errors and the
kidnapping pose); episodes run in parallel worker processes. The result holds every
stop position, their mean and standard deviation per axis (the paper: mean
(−22, +12) cm, standard deviation (17, 15) cm over 33 kidnappings), the mean stop
distance and the success rate, and a plot of the stop positions like the paper's
figure 5 (left).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import time
from pathlib import Path

import numpy as np

from vc_gym.experiments.output import save_figure, write_json

__all__ = ["evaluate_scripted", "PAPER_MEAN_CM", "PAPER_STD_CM"]

PAPER_MEAN_CM = (-22.0, 12.0)
PAPER_STD_CM = (17.0, 15.0)


def _episode(args: tuple[int, float]) -> dict:
    seed, learn_time_s = args
    import gymnasium as gym

    import vc_gym  # noqa: F401
    from vc_gym.agents.scripted import LearnThenHomeConfig, ScriptedLearnThenHome

    env = gym.make("vc_gym/AiboRoom-v0", scene="robolab", max_episode_steps=10**7)
    try:
        agent = ScriptedLearnThenHome(
            env, LearnThenHomeConfig(learn_time_s=learn_time_s), progress=False
        )
        record = agent.run(seed=seed)
        return {"seed": seed, **record.summary(), "start_pose": list(record.start or ())}
    finally:
        env.close()


def evaluate_scripted(
    episodes: int = 33,
    seed: int = 0,
    learn_time_s: float = 5.0,
    success_radius_m: float = 0.3,
    workers: int = 2,
    out_dir: str | os.PathLike | None = None,
    progress: bool = True,
) -> dict[str, object]:
    """Run ``episodes`` scripted learn-then-home episodes and summarise the stops."""
    if episodes < 1 or workers < 1:
        raise ValueError("episodes and workers must be >= 1")
    if not (np.isfinite(success_radius_m) and success_radius_m > 0):
        raise ValueError(f"success_radius_m must be > 0, got {success_radius_m}")
    t0 = time.perf_counter()
    jobs = [(seed + i, learn_time_s) for i in range(episodes)]
    if workers == 1:
        from tqdm import tqdm

        results = [_episode(j) for j in tqdm(jobs, desc="episodes", disable=not progress)]
    else:
        from tqdm import tqdm

        with mp.get_context("spawn").Pool(workers) as pool:
            results = list(
                tqdm(
                    pool.imap(_episode, jobs),
                    total=len(jobs),
                    desc="episodes",
                    disable=not progress,
                )
            )
    offsets = np.array([r["stop_offset_m"] for r in results]) * 100.0
    dist = np.hypot(offsets[:, 0], offsets[:, 1])
    summary = {
        "agent": "scripted",
        "scene": "robolab",
        "episodes": episodes,
        "seed": seed,
        "learn_time_s": learn_time_s,
        "mean_stop_offset_cm": offsets.mean(axis=0).round(1).tolist(),
        "std_stop_offset_cm": offsets.std(axis=0, ddof=1).round(1).tolist()
        if episodes > 1
        else None,
        "mean_stop_distance_cm": float(dist.mean().round(1)),
        "median_stop_distance_cm": float(np.median(dist).round(1)),
        "success_rate": float(np.mean(dist <= success_radius_m * 100)),
        "success_radius_m": success_radius_m,
        "fell": int(sum(r["fell"] for r in results)),
        "paper_mean_stop_offset_cm": list(PAPER_MEAN_CM),
        "paper_std_stop_offset_cm": list(PAPER_STD_CM),
        "duration_s": round(time.perf_counter() - t0, 1),
        "per_episode": results,
    }
    if out_dir is not None:
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        write_json(out / "evaluation.json", summary)
        _plot(out / "stop_positions.png", offsets, summary)
    return summary


def _plot(path: Path, offsets_cm: np.ndarray, summary: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 5), constrained_layout=True)
    ax.scatter(offsets_cm[:, 0], offsets_cm[:, 1], s=25, color="tab:blue", label="stop positions")
    for x, y in ((100, 0), (0, 100), (-100, 0), (0, -100)):
        ax.plot(x, y, "x", color="goldenrod", ms=10, mew=3)
    ax.plot(0, 0, "+", color="k", ms=14, mew=2, label="home")
    m = summary["mean_stop_offset_cm"]
    ax.plot(*m, "o", mfc="none", mec="tab:red", ms=12, mew=2, label=f"mean ({m[0]}, {m[1]}) cm")
    ax.plot(*PAPER_MEAN_CM, "s", mfc="none", mec="k", ms=10, label="paper's mean (−22, 12) cm")
    circle = plt.Circle((0, 0), summary["success_radius_m"] * 100, fill=False, ls="--", color="0.5")
    ax.add_patch(circle)
    ax.set_aspect("equal")
    ax.set_xlim(-150, 150)
    ax.set_ylim(-150, 150)
    ax.set_xlabel("x offset from home (cm)")
    ax.set_ylabel("y offset from home (cm)")
    ax.set_title(
        f"{summary['episodes']} kidnappings: success {summary['success_rate']:.0%}, "
        f"mean distance {summary['mean_stop_distance_cm']:.0f} cm"
    )
    ax.legend(fontsize=7, loc="upper right")
    save_figure(fig, path, dpi=100)
