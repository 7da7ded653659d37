"""vc-gym soak: the figures of a short run (the memory targets are for the full run)."""

from __future__ import annotations

import json

import pytest

from vc_gym.cli import main
from vc_gym.experiments.soak import rss_bytes, soak


def test_a_short_soak_reports_speed_and_memory(tmp_path, capsys):
    r = soak(steps=60, cycles=12, window=20, seed=1, progress=False)
    assert len(r["steps_per_s"]) == len(r["rss_mb"]) == 3
    assert all(v > 0 for v in r["steps_per_s"]) and r["median_steps_per_s"] > 0
    assert r["rss_growth_kb_per_10k_steps"] is not None
    assert r["rss_growth_kb_per_cycle"] is not None and r["rss_after_cycles_mb"] > 0
    assert isinstance(r["cycles_within_target"], bool)
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
