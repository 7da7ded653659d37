"""Long-run health of the simulated room: speed over time, memory per step and per env.

``vc-gym soak`` runs one ``vc_gym/AiboRoom-v0`` for ``steps`` steps with random actions
(resetting when an episode ends) and records, in windows, its steps per second and the
process's resident memory (RSS); then it makes, resets, steps and closes ``cycles`` envs
one after another and records the RSS again. The growth figures are least-squares slopes
of RSS against steps and against cycles, measured after a warm-up (the first window, the
first quarter of the cycles) in which the allocator's arenas and caches fill (RSS rises
in steps of about 2 MB over the first few dozen envs, then stays flat): a leak shows as
a slope well above that noise.
"""

from __future__ import annotations

import gc
import os
import time
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.validation import int_at_least

__all__ = ["GROWTH_TARGET_KB", "rss_bytes", "soak"]

ENV_ID = "vc_gym/AiboRoom-v0"
#: Growth per make/close cycle that counts as "within noise" (KB).
GROWTH_TARGET_KB = 5.0


def rss_bytes() -> int:
    """Resident memory of this process in bytes (Linux ``/proc``; 0 where unavailable)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _slope(x: list[float], y: list[float]) -> float | None:
    if len(x) < 2 or len(set(x)) < 2:
        return None
    return float(np.polyfit(np.asarray(x, float), np.asarray(y, float), 1)[0])


def soak(
    steps: int = 50_000,
    cycles: int = 200,
    window: int = 2_000,
    seed: int = 0,
    progress: bool = True,
    env_kwargs: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Step one env for a long time, then make and close many; measure speed and memory.

    Parameters
    ----------
    steps : int
        Steps of the long run (>= 2 windows).
    cycles : int
        Make / reset / step / close cycles (>= 10).
    window : int
        Steps per measurement window of the long run.
    seed : int
        Seed of the resets and the random actions.
    progress : bool
        Show progress bars.
    env_kwargs : dict, optional
        Arguments of ``vc_gym/AiboRoom-v0`` (e.g. a smaller camera for a quick check).

    Returns
    -------
    dict
        ``steps_per_s`` per window, its median and first/last ratio, ``rss_mb`` per
        window, ``rss_growth_kb_per_10k_steps``, ``rss_growth_kb_per_cycle``, the RSS
        before and after the cycles, and whether the cycle growth is within
        :data:`GROWTH_TARGET_KB`.
    """
    int_at_least("window", window, 10)
    int_at_least("steps", steps, 2 * window)
    int_at_least("cycles", cycles, 10)
    kwargs = dict(env_kwargs or {})
    rng = np.random.default_rng(seed)
    env = gym.make(ENV_ID, **kwargs)
    rates, rss, at = [], [], []
    try:
        env.reset(seed=seed)
        done = 0
        with tqdm(total=steps, desc="soak: steps", disable=not progress) as bar:
            while done < steps:
                n = min(window, steps - done)
                actions = rng.uniform(-1, 1, (n, 5)).astype(np.float32)
                t0 = time.perf_counter()
                for a in actions:
                    _, _, terminated, truncated, _ = env.step(a)
                    if terminated or truncated:
                        env.reset()
                rates.append(n / (time.perf_counter() - t0))
                done += n
                gc.collect()
                rss.append(rss_bytes())
                at.append(done)
                bar.update(n)
    finally:
        env.close()
    cycle_rss, cycle_at = [], []
    warm = max(1, cycles // 4)
    for k in tqdm(range(cycles), desc="soak: make/close", disable=not progress):
        env = gym.make(ENV_ID, **kwargs)
        try:
            env.reset(seed=seed + k)
            env.step(env.action_space.sample())
        finally:
            env.close()
        if k >= warm:
            gc.collect()
            cycle_rss.append(rss_bytes())
            cycle_at.append(k)
    per_step = _slope(at[1:], rss[1:])
    per_cycle = _slope(cycle_at, cycle_rss)
    return {
        "steps": steps,
        "cycles": cycles,
        "window": window,
        "steps_per_s": [round(r, 1) for r in rates],
        "median_steps_per_s": round(float(np.median(rates)), 1),
        "last_over_first_window": round(rates[-1] / rates[0], 3),
        "rss_mb": [round(r / 2**20, 1) for r in rss],
        "rss_growth_kb_per_10k_steps": None
        if per_step is None
        else round(per_step * 1e4 / 1024, 1),
        "rss_before_cycles_mb": round(cycle_rss[0] / 2**20, 1) if cycle_rss else None,
        "rss_after_cycles_mb": round(cycle_rss[-1] / 2**20, 1) if cycle_rss else None,
        "rss_growth_kb_per_cycle": None if per_cycle is None else round(per_cycle / 1024, 2),
        "growth_target_kb_per_cycle": GROWTH_TARGET_KB,
        "cycles_within_target": per_cycle is not None and per_cycle / 1024 <= GROWTH_TARGET_KB,
    }
