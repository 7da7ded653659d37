"""Every script in examples/ runs end to end (with small sizes) and does what it says."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SMALL = ["--learn-time", "0.2", "--max-homing", "4"]
#: script -> (small arguments, a line its output must hold, marks)
RUNS = {
    "compass_in_a_room.py": (["--views", "6", "--out", "errors.png"], "wrote errors.png", []),
    "own_tracker.py": (["--episodes", "1", *SMALL], "mean stop", [pytest.mark.slow]),
    "train_ppo.py": (
        ["--timesteps", "64", "--n-envs", "2", "--episodes", "1", *SMALL, "--out", "m.zip"],
        "model saved to m.zip",
        [pytest.mark.slow],
    ),
}


def test_every_example_is_run() -> None:
    assert sorted(p.name for p in (ROOT / "examples").glob("*.py")) == sorted(RUNS)


@pytest.mark.parametrize(
    "script", [pytest.param(s, marks=RUNS[s][2], id=s) for s in RUNS]
)
def test_example_runs(script: str, tmp_path: Path) -> None:
    args, expected, _ = RUNS[script]
    done = subprocess.run(
        [sys.executable, str(ROOT / "examples" / script), *args],
        cwd=tmp_path,
        env=dict(os.environ, MPLBACKEND="Agg"),
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert expected in done.stdout, done.stdout[-2000:]
    for arg in args:
        if arg.endswith((".png", ".zip")):
            assert (tmp_path / arg).stat().st_size > 0
    if script == "compass_in_a_room.py":
        errors = [float(line.split()[-1].rstrip("°")) for line in done.stdout.splitlines()
                  if "median heading error" in line]
        assert len(errors) == 6 and errors[0] < 2.0  # exact at the learned spot
