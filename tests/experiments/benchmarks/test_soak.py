"""vc-gym soak: the figures of a short run (the memory targets are for the full run)."""

from __future__ import annotations

import json

import pytest

from vc_gym.cli import main
from vc_gym.experiments.benchmarks.soak import rss_bytes, soak


@pytest.mark.slow
def test_a_short_soak_reports_speed_and_memory(tmp_path, capsys):
    r = soak(steps=60, cycles=12, window=20, seed=1, progress=False)
    assert len(r["steps_per_s"]) == len(r["rss_mb"]) == 3
    assert all(v > 0 for v in r["steps_per_s"]) and r["median_steps_per_s"] > 0
    assert r["rss_growth_kb_per_10k_steps"] is not None
    assert r["rss_growth_kb_per_cycle"] is not None and r["rss_after_cycles_mb"] > 0
    assert isinstance(r["cycles_within_target"], bool)
    if r["free_memory_released"]:  # glibc: the C heap is measured too
        assert r["heap_growth_kb_per_cycle"] is not None
        assert r["heap_growth_kb_per_10k_steps"] is not None
    assert rss_bytes() > 0
    out = tmp_path / "soak.json"
    code = main(["soak", "--steps", "40", "--window", "20", "--cycles", "10", "--out", str(out)])
    assert code == 0 and json.loads(out.read_text())["steps"] == 40
    assert "make/close cycles" in capsys.readouterr().out


@pytest.mark.parametrize(
    "kwargs", [{"steps": 10, "window": 10}, {"cycles": 3}, {"window": 0}, {"steps": 1.5}]
)
def test_bad_soak_settings(kwargs):
    with pytest.raises(ValueError):
        soak(**{"steps": 40, "window": 20, "cycles": 10, **kwargs}, progress=False)


_HEAP_PROBE = """
import ctypes, json
from vc_gym.experiments.benchmarks.soak import (
    _GLIBC, heap_in_use_bytes, release_free_memory, rss_bytes,
)
if _GLIBC is None:
    print(json.dumps(None))
    raise SystemExit
size = 64 * 2**20
released = release_free_memory()
heap0, rss0 = heap_in_use_bytes(), rss_bytes()
_GLIBC.malloc.restype = ctypes.c_void_p
_GLIBC.malloc.argtypes = [ctypes.c_size_t]
_GLIBC.free.argtypes = [ctypes.c_void_p]
block = _GLIBC.malloc(size)
ctypes.memset(block, 1, size)
release_free_memory()  # never releases memory still in use
held = (heap_in_use_bytes() - heap0, rss_bytes() - rss0)
_GLIBC.free(block)
release_free_memory()
after = (heap_in_use_bytes() - heap0, rss_bytes() - rss0)
print(json.dumps({"size": size, "released": released, "block": bool(block),
                  "held": held, "after": after}))
"""


def test_the_heap_figure_counts_what_c_code_allocates_and_frees():
    """A known answer: 64 MiB malloc'ed by C code shows in the heap in use (and in RSS
    once touched), and is gone from both after free, even after the trim. Measured in a
    process of its own: the heap is the whole process', and other threads of a test
    worker allocate and free at the same time."""
    import subprocess
    import sys

    run = subprocess.run(
        [sys.executable, "-c", _HEAP_PROBE], capture_output=True, text=True, check=True
    )
    r = json.loads(run.stdout.strip().splitlines()[-1])
    if r is None:
        pytest.skip("the C library is not glibc >= 2.33 (no mallinfo2 / malloc_trim)")
    size = r["size"]
    assert r["released"] is True and r["block"]
    assert r["held"][0] >= size
    assert r["held"][1] >= 0.9 * size
    assert abs(r["after"][0]) < 2**20
    assert r["after"][1] < 0.5 * size
