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
from pathlib import Path

import numpy as np

from vc_gym.experiments.output import save_figure, write_json
from vc_gym.validation import positive_float

__all__ = ["evaluate_agent", "PAPER_MEAN_CM", "PAPER_STD_CM"]

PAPER_MEAN_CM = (-22.0, 12.0)
PAPER_STD_CM = (17.0, 15.0)


_WORKER: dict = {}


def _make(
    agent: str, learn_time_s: float, success_radius_m: float, relearn: str, max_homing_s: float
):
    """The evaluation env and a policy ``obs -> action`` (with an optional ``reset``)."""
    import gymnasium as gym

    import vc_gym  # noqa: F401
    from vc_gym.agents.scripted import LearnThenHomeConfig, ScriptedHomingPolicy
    from vc_gym.envs.compass_observation import CompassObservation

    task = {
        "scene": "robolab",
        "relearn": relearn,
        "learn_time_s": learn_time_s,
        "stop_time_s": 5.0,  # the paper's rule, also for agents trained with a shorter one
        "success_radius_m": success_radius_m,
        "max_homing_s": max_homing_s,
    }
    if agent == "scripted":
        env = gym.make("vc_gym/LearnThenHome-v0", **task)
        env = CompassObservation(env, keep_image=False)
        policy = ScriptedHomingPolicy(LearnThenHomeConfig(), dt_s=env.unwrapped.control_dt)
        return env, policy.predict, policy.reset
    from vc_gym.agents.learned import LearnedHomingAgent

    learned = LearnedHomingAgent(agent)
    if learned.config.scene != "robolab":
        task["scene"] = learned.config.scene
    return learned.make_env(**task), learned.predict, None


def _init_worker(
    agent: str, seed: int, learn_time_s: float, radius: float, relearn: str, max_homing_s: float
) -> None:
    env, act, reset = _make(agent, learn_time_s, radius, relearn, max_homing_s)
    env.reset(seed=seed)  # the learning phase (every worker learns the same place)
    _WORKER.update(env=env, act=act, reset=reset)


def _episode(episode_seed: int) -> dict:
    env, act, reset = _WORKER["env"], _WORKER["act"], _WORKER["reset"]
    obs, info = env.reset(seed=episode_seed)
    start = [float(v) for v in info["pose"]]
    if reset is not None:
        reset()
    total, decisions = 0.0, 0
    while True:
        obs, r, terminated, truncated, info = env.step(act(obs))
        total += float(r)
        decisions += 1
        if terminated or truncated:
            break
    stop = [float(v) for v in info["stop_position"]]
    return {
        "seed": episode_seed,
        "start_pose": start,
        "stop_offset_m": stop,  # home is the origin
        "home_error_m": float(info["stop_error_m"]),
        "stopped": bool(info["stopped"]),
        "success": bool(info["success"]),
        "fell": bool(info.get("fallen", False)),
        "timed_out": bool(truncated),
        "decisions": decisions,
        "sim_time_s": float(info["sim_time"]),
        "return": total,
    }


def evaluate_agent(
    agent: str = "scripted",
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
    if agent != "scripted":
        from vc_gym.agents.learned import LearnedHomingAgent

        LearnedHomingAgent(agent)  # fail here, with a clear message, not in a worker
    from tqdm import tqdm

    t0 = time.perf_counter()
    init = (agent, seed, learn_time_s, success_radius_m, relearn, max_homing_s)
    jobs = [seed + 1 + i for i in range(episodes)]
    workers = min(workers, episodes)
    if workers == 1:
        _init_worker(*init)
        try:
            results = [_episode(j) for j in tqdm(jobs, desc="episodes", disable=not progress)]
        finally:
            _WORKER.pop("env").close()
    else:
        ctx = mp.get_context("spawn")
        with ctx.Pool(workers, initializer=_init_worker, initargs=init) as pool:
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
        "agent": agent,
        "scene": "robolab",
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
    # the paper's figure spans ±1.5 m; widen it so that no stop falls off the plot
    lim = max(150.0, float(np.abs(offsets_cm).max()) + 20.0)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_xlabel("x offset from home (cm)")
    ax.set_ylabel("y offset from home (cm)")
    name = "scripted" if summary["agent"] == "scripted" else Path(summary["agent"]).parent.name
    ax.set_title(
        f"{name}, {summary['episodes']} kidnappings: success {summary['success_rate']:.0%}, "
        f"mean distance {summary['mean_stop_distance_cm']:.0f} cm"
    )
    ax.legend(fontsize=7, loc="upper right")
    save_figure(fig, path, dpi=100)
