"""vc-gym check: every robustness case passes, and a failing case is reported as failed."""

from __future__ import annotations

import json

import pytest

from vc_gym.cli import main
from vc_gym.experiments import check
from vc_gym.experiments.check import Case, all_cases, run_check


@pytest.mark.slow
def test_every_case_passes_and_the_soak_reports(tmp_path, capsys, monkeypatch):
    # the footage suite's cases run one by one in tests/experiments/test_check_footage.py
    monkeypatch.setattr(check, "footage_cases", lambda main=None: [])
    out = tmp_path / "check.json"
    code = main(["check", "--soak-steps", "40", "--soak-cycles", "10", "--out", str(out)])
    r = json.loads(out.read_text())
    assert code == 0, r["failures"]
    assert r["failed"] == 0 and r["tried"] == r["passed"] == len(all_cases()) >= 80
    assert set(r["suites"]) == {
        "hostile_file",
        "envs",
        "fault",
        "code_in_files",
        "exhaustion",
        "runs",
        "arguments",
    }
    assert r["soak"]["steps"] == 40 and r["soak"]["median_steps_per_s"] > 0
    assert "failed 0" in capsys.readouterr().out


def test_the_env_suite_covers_every_registered_env():
    import gymnasium as gym

    names = [c.name for c in all_cases() if c.suite == "envs"]
    for env_id in (k for k in gym.registry if k.startswith("vc_gym/")):
        mine = [n for n in names if n.startswith(env_id + ":")]
        assert len(mine) == 13 and mine[0].endswith("step before reset")
        assert mine[-1].endswith("after close")


def test_the_footage_suite_is_part_of_the_check():
    from vc_gym.cli import main as cli_main

    names = {c.suite for c in all_cases(cli_main)}
    assert "footage" in names


def test_a_case_that_escapes_is_reported():
    def escapes(_):
        raise KeyError("not the promised error")

    def passes(_):
        return None

    r = run_check(
        20, 10, progress=False, cases=[Case("x", "escapes", escapes), Case("x", "ok", passes)]
    )
    assert r["tried"] == 2 and r["failed"] == 1 and r["passed"] == 1
    assert r["failures"][0]["case"] == "escapes" and "KeyError" in r["failures"][0]["error"]
