"""Long-run health of the simulated room: speed over time, memory per step and per env.

``vc-gym soak`` runs one ``vc_gym/AiboRoom-v0`` for ``steps`` steps with random actions
(resetting when an episode ends) and records, in windows, its steps per second and the
process's resident memory (RSS); then it makes, resets, steps and closes ``cycles`` envs
one after another and records the RSS again. The growth figures are least-squares slopes
of RSS against steps and against cycles, measured after a warm-up (the first window, the
first quarter of the cycles) in which the allocator's arenas and caches fill.

Freed memory is not always given back to the system: glibc's allocator keeps it in its
arenas, and an env's worth of freed blocks (a few MB) makes RSS jump up and down by
whole megabytes between samples, which swamped the per-cycle slope (−8 to +69 KB per
cycle in runs of the same code). Where glibc is the allocator, every sample is
therefore taken after ``malloc_trim(0)``, which returns free memory and nothing that is
still allocated (a leak stays in RSS), and the bytes the allocator has handed out and
not taken back (``mallinfo2``: in-use blocks plus mmapped blocks) are reported too: the
exact count of C-level memory a leak would grow. Python objects are checked separately
(a test counts them with ``tracemalloc``).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import gc
import os
import time
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.validation import check_seed, int_in_range

__all__ = [
    "GROWTH_TARGET_KB",
    "MAX_SOAK_CYCLES",
    "MAX_SOAK_STEPS",
    "MIN_SOAK_CYCLES",
    "MIN_WINDOW",
    "check_soak_args",
    "heap_in_use_bytes",
    "release_free_memory",
    "rss_bytes",
    "soak",
]

ENV_ID = "vc_gym/AiboRoom-v0"
#: Growth per make/close cycle that counts as "within noise" (KB).
GROWTH_TARGET_KB = 5.0
#: Fewest steps per measurement window (a rate over fewer is noise).
MIN_WINDOW = 10
#: Most steps of the long run: 20 times the full soak's 50,000 (a few hours).
MAX_SOAK_STEPS = 1_000_000
#: Fewest make/close cycles (a slope needs a few after the warm-up quarter).
MIN_SOAK_CYCLES = 10
#: Most make/close cycles: 50 times the full soak's 200 (about an hour).
MAX_SOAK_CYCLES = 10_000


def check_soak_args(
    steps: object,
    cycles: object,
    window: object,
    seed: object = 0,
    names: tuple[str, str, str, str] = ("steps", "cycles", "window", "seed"),
) -> None:
    """Check :func:`soak`'s counts before any work (a command checks them first too).

    Parameters
    ----------
    steps, cycles, window, seed : int
        As :func:`soak`: ``window`` in ``MIN_WINDOW..MAX_SOAK_STEPS // 2``, ``steps`` in
        ``2 * window..MAX_SOAK_STEPS``, ``cycles`` in
        ``MIN_SOAK_CYCLES..MAX_SOAK_CYCLES``, ``seed`` in ``0..MAX_SEED``.
    names : tuple of str
        The names of the four in error messages (a command's flags, e.g.
        ``("--soak-steps", "--soak-cycles", "window", "seed")``).

    Raises
    ------
    ValueError
        Naming the argument and its accepted range.
    """
    n_steps, n_cycles, n_window, n_seed = names
    w = int_in_range(n_window, window, MIN_WINDOW, MAX_SOAK_STEPS // 2)
    int_in_range(n_steps, steps, 2 * w, MAX_SOAK_STEPS)
    int_in_range(n_cycles, cycles, MIN_SOAK_CYCLES, MAX_SOAK_CYCLES)
    check_seed(n_seed, seed)


def rss_bytes() -> int:
    """Resident memory of this process in bytes (Linux ``/proc``; 0 where unavailable)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


class _MallInfo2(ctypes.Structure):
    _fields_ = [
        (name, ctypes.c_size_t)
        for name in (
            "arena", "ordblks", "smblks", "hblks", "hblkhd",
            "usmblks", "fsmblks", "uordblks", "fordblks", "keepcost",
        )
    ]  # fmt: skip


def _load_glibc() -> ctypes.CDLL | None:
    """The C library if it is glibc ≥ 2.33 (``mallinfo2`` and ``malloc_trim``), else None."""
    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name)
        libc.mallinfo2.restype = _MallInfo2
        libc.malloc_trim.argtypes = [ctypes.c_size_t]
        libc.malloc_trim.restype = ctypes.c_int
    except (OSError, AttributeError, TypeError):
        return None
    return libc


_GLIBC = _load_glibc()


def release_free_memory() -> bool:
    """Collect Python garbage and give the allocator's free memory back to the system.

    Returns whether the allocator could be asked (glibc's ``malloc_trim``); memory that
    is still allocated is never released, so a leak still shows in :func:`rss_bytes`.
    """
    gc.collect()
    if _GLIBC is None:
        return False
    _GLIBC.malloc_trim(0)
    return True


def heap_in_use_bytes() -> int | None:
    """Bytes the C allocator has handed out and not taken back (glibc ``mallinfo2``:
    in-use blocks of every arena plus mmapped blocks); None without glibc ≥ 2.33."""
    if _GLIBC is None:
        return None
    info = _GLIBC.mallinfo2()
    return int(info.uordblks + info.hblkhd)


def _slope(x: list[float], y: list[float | None]) -> float | None:
    if len(x) < 2 or len(set(x)) < 2 or any(v is None for v in y):
        return None
    return float(np.polyfit(np.asarray(x, float), np.asarray(y, float), 1)[0])


def _kb(per: float | None, scale: float = 1.0, digits: int = 2) -> float | None:
    return None if per is None else round(per * scale / 1024, digits)


def _sample(rss: list[int], heap: list[int | None]) -> None:
    """Append this moment's RSS and heap in use, after giving free memory back."""
    release_free_memory()
    rss.append(rss_bytes())
    heap.append(heap_in_use_bytes())


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
        Steps of the long run (2 windows to :data:`MAX_SOAK_STEPS`).
    cycles : int
        Make / reset / step / close cycles (:data:`MIN_SOAK_CYCLES` to
        :data:`MAX_SOAK_CYCLES`).
    window : int
        Steps per measurement window of the long run (at least :data:`MIN_WINDOW`).
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
        before and after the cycles, whether the cycle growth is within
        :data:`GROWTH_TARGET_KB`, the C heap's growth (``heap_growth_kb_per_10k_steps``,
        ``heap_growth_kb_per_cycle``; None without glibc) and whether free memory was
        given back before each sample (``free_memory_released``).
    """
    check_soak_args(steps, cycles, window, seed)
    kwargs = dict(env_kwargs or {})
    rng = np.random.default_rng(seed)
    env = gym.make(ENV_ID, **kwargs)
    rates: list[float] = []
    rss: list[int] = []
    heap: list[int | None] = []
    at: list[int] = []
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
                _sample(rss, heap)
                at.append(done)
                bar.update(n)
    finally:
        env.close()
    cycle_rss: list[int] = []
    cycle_heap: list[int | None] = []
    cycle_at: list[int] = []
    warm = max(1, cycles // 4)
    for k in tqdm(range(cycles), desc="soak: make/close", disable=not progress):
        env = gym.make(ENV_ID, **kwargs)
        try:
            env.reset(seed=seed + k)
            env.step(env.action_space.sample())
        finally:
            env.close()
        if k >= warm:
            _sample(cycle_rss, cycle_heap)
            cycle_at.append(k)
    per_step = _slope(at[1:], rss[1:])
    per_cycle = _slope(cycle_at, cycle_rss)
    heap_per_cycle = _slope(cycle_at, cycle_heap)
    return {
        "steps": steps,
        "cycles": cycles,
        "window": window,
        "steps_per_s": [round(r, 1) for r in rates],
        "median_steps_per_s": round(float(np.median(rates)), 1),
        "last_over_first_window": round(rates[-1] / rates[0], 3),
        "rss_mb": [round(r / 2**20, 1) for r in rss],
        "rss_growth_kb_per_10k_steps": _kb(per_step, 1e4, 1),
        "heap_growth_kb_per_10k_steps": _kb(_slope(at[1:], heap[1:]), 1e4, 1),
        "rss_before_cycles_mb": round(cycle_rss[0] / 2**20, 1) if cycle_rss else None,
        "rss_after_cycles_mb": round(cycle_rss[-1] / 2**20, 1) if cycle_rss else None,
        "rss_growth_kb_per_cycle": _kb(per_cycle),
        "heap_growth_kb_per_cycle": _kb(heap_per_cycle),
        "free_memory_released": _GLIBC is not None,
        "growth_target_kb_per_cycle": GROWTH_TARGET_KB,
        "cycles_within_target": per_cycle is not None and per_cycle / 1024 <= GROWTH_TARGET_KB,
    }
