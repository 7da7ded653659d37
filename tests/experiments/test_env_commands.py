"""`vc-gym render` and `vc-gym bench env` end to end (tiny budgets)."""

from __future__ import annotations

import cv2

from vc_gym.cli import main
from vc_gym.experiments.benchmarks.env import bench_env


def test_render_writes_top_view_and_strip(tmp_path, capsys):
    assert main(["render", "--scene", "home", "--out", str(tmp_path)]) == 0
    top = cv2.imread(str(tmp_path / "home_top.png"))
    strip = cv2.imread(str(tmp_path / "home_strip.png"))
    assert top is not None and top.shape[0] == top.shape[1]
    assert strip.shape == (160, 8 * 208, 3)
    assert "home_strip.png" in capsys.readouterr().out


def test_bench_env_reports_rates():
    r = bench_env(steps=3, rounds=1, vector=False)
    assert r["steps_per_s"] > 0 and r["bare_steps_per_s"] > 0
    assert r["physics_substeps"] == 24
    assert r["env_over_bare"] == r["steps_per_s"] / r["bare_steps_per_s"]
