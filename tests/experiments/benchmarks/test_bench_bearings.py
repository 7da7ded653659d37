"""``vc-gym bench bearings``: the bearing sensor's cost per frame in the robot lab."""

from __future__ import annotations

import json

import pytest

from vc_gym.cli import main


@pytest.mark.slow  # renders 300 learning frames
def test_bench_bearings_reports_per_frame_costs(capsys):
    argv = ["bench", "bearings", "--frames", "2", "--repeats", "2", "--poses", "50", "--json"]
    assert main(argv) == 0
    r = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert r["frames"] == 2 and r["poses"] == 50 and r["learning_frames"] == 300
    # the robot lab's learned turns see dozens of colour edges (measured: 96)
    assert r["landmarks"] >= 30
    assert r["bearings_ms"] > 0 and r["likelihood_ms"] > 0


def test_bad_bearings_arguments_are_refused_before_any_work(capsys):
    assert main(["bench", "bearings", "--poses", "0"]) == 2
    assert "--poses" in capsys.readouterr().err
