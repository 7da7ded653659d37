"""The paper's homing experiment repeated: stop positions over many kidnappings (5.2).

The robot learns the place once on ``vc_gym/LearnThenHome-v0`` (scripted learning,
like the paper) and is then kidnapped ``episodes`` times, each time with its own seed
(odometry errors and kidnapping pose), homing with the scripted agent or a learned one
on :class:`~vc_gym.envs.CompassObservation` outputs; episodes run in parallel worker
processes. The result holds every
stop position, their mean and standard deviation per axis (the paper: mean
(−22, +12) cm, standard deviation (17, 15) cm over 33 kidnappings), the mean stop
distance and the success rate, and a plot of the stop positions like the paper's
figure 5 (left).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np

from vc_gym.experiments.episode import make_homing_run, run_episode
from vc_gym.experiments.output import new_figure, save_figure, write_json
from vc_gym.localization import TrackerSpec, make_tracker
from vc_gym.validation import positive_float

__all__ = ["evaluate_agent", "PAPER_MEAN_CM", "PAPER_STD_CM"]

PAPER_MEAN_CM = (-22.0, 12.0)
PAPER_STD_CM = (17.0, 15.0)


_WORKER: dict = {}


def _init_pool_worker(seed: int, run_kwargs: dict) -> None:
    # numeric libraries single-threaded: the workers are the parallelism (DESIGN.md)
    import cv2

    cv2.setNumThreads(1)
    _init_worker(seed, run_kwargs)


def _init_worker(seed: int, run_kwargs: dict) -> None:
    run = make_homing_run(**run_kwargs)
    run.env.reset(seed=seed)  # the learning phase (every worker learns the same place)
    _WORKER["run"] = run


def _episode(episode_seed: int) -> dict:
    record = run_episode(_WORKER["run"], seed=episode_seed)
    out = record.summary()
    out["tracker_ms_per_update"] = (
        1e3 * record.tracker_time_s / record.tracker_updates if record.tracker_updates else None
    )
    return out


def evaluate_agent(
    agent: str = "scripted",
    tracker: TrackerSpec = "grid",
    episodes: int = 33,
    seed: int = 0,
    learn_time_s: float = 5.0,
    success_radius_m: float = 0.3,
    relearn: str = "scene",
    max_homing_s: float = 60.0,
    workers: int = 2,
    out_dir: str | os.PathLike | None = None,
    progress: bool = True,
) -> dict[str, object]:
    """Repeat the paper's homing experiment and summarise where the robot stopped.

    Parameters
    ----------
    agent : str
        ``"scripted"`` (:class:`~vc_gym.agents.scripted.ScriptedHomingPolicy`),
        ``"pretrained"`` (the PPO policy shipped with the package) or the path of a
        ``model.zip`` written by ``vc-gym train``.
    tracker : str or dict
        The tracker that turns frames and odometry into the agent's estimates:
        ``"grid"`` (the paper's filters), ``"particle"``, ``"kalman"``, or a
        ``{"type": name, **kwargs}`` dict (it must be picklable for the workers).
    episodes : int
        Kidnappings (paper: 33).
    seed : int
        Seed of the learning phase; kidnapping ``i`` uses ``seed + 1 + i``.
    learn_time_s : float
        Learning time per direction of the scripted learning phase (paper: 5 s).
    success_radius_m : float
        A stop within this distance of home is a success.
    relearn : str
        ``"scene"``: learn once, then kidnap ``episodes`` times (the paper's protocol);
        ``"episode"``: learn anew before every kidnapping (odometry errors and maps
        differ per episode; much slower).
    max_homing_s : float
        Homing time after which an episode ends as timed out (stop position: where the
        robot is then).
    workers : int
        Parallel processes (each learns the same place from the same seed).
    out_dir : path, optional
        Where to write ``evaluation.json`` and ``stop_positions.png``.
    progress : bool
        Show a progress bar.
    """
    if episodes < 1 or workers < 1:
        raise ValueError("episodes and workers must be >= 1")
    positive_float("success_radius_m", success_radius_m)
    positive_float("max_homing_s", max_homing_s)
    if relearn not in ("scene", "episode"):
        raise ValueError(f"relearn must be 'scene' or 'episode', got {relearn!r}")
    if agent == "pretrained":
        from vc_gym.agents.learned import PRETRAINED_MODEL

        agent = str(PRETRAINED_MODEL)
    scene = "robolab"
    if agent != "scripted":
        from vc_gym.agents.learned import LearnedHomingAgent

        # fail here, with a clear message, not in a worker
        scene = LearnedHomingAgent(agent).scene
    make_tracker(tracker)  # an unknown tracker fails here too
    from tqdm import tqdm

    t0 = time.perf_counter()
    run_kwargs = {
        "agent": agent,
        "tracker": tracker,
        "scene": scene,
        "learn_time_s": learn_time_s,
        "success_radius_m": success_radius_m,
        "relearn": relearn,
        "max_homing_s": max_homing_s,
    }
    init = (seed, run_kwargs)
    jobs = [seed + 1 + i for i in range(episodes)]
    workers = min(workers, episodes)
    if workers == 1:
        _init_worker(*init)
        try:
            results = [_episode(j) for j in tqdm(jobs, desc="episodes", disable=not progress)]
        finally:
            _WORKER.pop("run").close()
    else:
        # concurrent.futures notices a worker that dies (OOM killer, a crash in a
        # native library) and fails every pending job; multiprocessing.Pool would
        # wait for its result forever
        ctx = mp.get_context("spawn")
        with ProcessPoolExecutor(
            workers, mp_context=ctx, initializer=_init_pool_worker, initargs=init
        ) as pool:
            try:
                results = list(
                    tqdm(
                        pool.map(_episode, jobs),
                        total=len(jobs),
                        desc="episodes",
                        disable=not progress,
                    )
                )
            except BrokenProcessPool as exc:
                raise RuntimeError(
                    "a worker process died during the evaluation (killed, or crashed in "
                    "native code); no figures were written. Rerun, or use --workers 1 "
                    "to see the error in this process"
                ) from exc
    costs = [r.pop("tracker_ms_per_update") for r in results]
    costs = [c for c in costs if c is not None]
    offsets = np.array([r["stop_offset_m"] for r in results]) * 100.0
    dist = np.hypot(offsets[:, 0], offsets[:, 1])
    summary = {
        "agent": agent,
        "tracker": tracker,
        "scene": scene,
        "protocol": "learn once, then kidnap every episode (paper 5.2)"
        if relearn == "scene"
        else "learn anew before every kidnapping",
        "relearn": relearn,
        "episodes": episodes,
        "seed": seed,
        "learn_time_s": learn_time_s,
        "max_homing_s": max_homing_s,
        "mean_stop_offset_cm": offsets.mean(axis=0).round(1).tolist(),
        "std_stop_offset_cm": offsets.std(axis=0, ddof=1).round(1).tolist()
        if episodes > 1
        else None,
        "mean_stop_distance_cm": float(dist.mean().round(1)),
        "median_stop_distance_cm": float(np.median(dist).round(1)),
        "success_rate": float(np.mean([r["success"] for r in results])),
        "success_radius_m": success_radius_m,
        "stopped": int(sum(r["stopped"] for r in results)),
        "timed_out": int(sum(r["timed_out"] for r in results)),
        "fell": int(sum(r["fell"] for r in results)),
        "mean_homing_time_s": float(np.mean([r["sim_time_s"] for r in results]).round(1)),
        "paper_mean_stop_offset_cm": list(PAPER_MEAN_CM),
        "paper_std_stop_offset_cm": list(PAPER_STD_CM),
        "mean_heading_error_deg": float(
            np.mean([r["mean_heading_error_deg"] or 0.0 for r in results]).round(2)
        ),
        "timing": {  # wall time: machine-dependent, not a result
            "duration_s": round(time.perf_counter() - t0, 1),
            "tracker_ms_per_update_median": float(np.median(costs).round(3)) if costs else None,
            "workers": workers,
        },
        "per_episode": results,
    }
    if out_dir is not None:
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        write_json(out / "evaluation.json", summary)
        _plot(out / "stop_positions.png", offsets, summary)
    return summary


def _plot(path: Path, offsets_cm: np.ndarray, summary: dict) -> None:
    from matplotlib.patches import Circle

    fig = new_figure(figsize=(6, 5), layout="constrained")
    ax = fig.subplots()
    ax.scatter(offsets_cm[:, 0], offsets_cm[:, 1], s=25, color="tab:blue", label="stop positions")
    for x, y in ((100, 0), (0, 100), (-100, 0), (0, -100)):
        ax.plot(x, y, "x", color="goldenrod", ms=10, mew=3)
    ax.plot(0, 0, "+", color="k", ms=14, mew=2, label="home")
    m = summary["mean_stop_offset_cm"]
    ax.plot(*m, "o", mfc="none", mec="tab:red", ms=12, mew=2, label=f"mean ({m[0]}, {m[1]}) cm")
    ax.plot(*PAPER_MEAN_CM, "s", mfc="none", mec="k", ms=10, label="paper's mean (−22, 12) cm")
    circle = Circle((0, 0), summary["success_radius_m"] * 100, fill=False, ls="--", color="0.5")
    ax.add_patch(circle)
    ax.set_aspect("equal")
    # the paper's figure spans ±1.5 m; widen it so that no stop falls off the plot
    lim = max(150.0, float(np.abs(offsets_cm).max()) + 20.0)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_xlabel("x offset from home (cm)")
    ax.set_ylabel("y offset from home (cm)")
    name = "scripted" if summary["agent"] == "scripted" else Path(summary["agent"]).parent.name
    tracker = summary["tracker"] if isinstance(summary["tracker"], str) else "custom"
    ax.set_title(
        f"{name} ({tracker} tracker), {summary['episodes']} kidnappings:\n"
        f"success {summary['success_rate']:.0%}, "
        f"mean distance {summary['mean_stop_distance_cm']:.0f} cm",
        fontsize=10,
    )
    ax.legend(fontsize=7, loc="upper right")
    save_figure(fig, path, dpi=100)
