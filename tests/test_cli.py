"""The ``vc-gym`` command end to end (small budgets)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from vc_gym.cli import main


def test_help_lists_subcommands(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    for cmd in ("demo", "bench", "experiment"):
        assert cmd in out


def test_console_script_is_installed():
    r = subprocess.run(
        [sys.executable, "-m", "vc_gym.cli", "--version"], capture_output=True, text=True
    )
    assert r.returncode == 0 and "vc_gym" in r.stdout


def test_synthetic_compass_writes_summary_and_plot(tmp_path, capsys):
    assert main(["experiment", "synthetic-compass", "--out", str(tmp_path), "--seed", "3"]) == 0
    summary = json.loads((tmp_path / "results.json").read_text())
    assert set(summary["results"]) == {
        f"{scene}/exposure={e}"
        for scene in ("room", "outdoor")
        for e in ("none", "mean", "map", "session")
    }
    normal = summary["results"]["room/exposure=none"]["illumination_1.0"]
    assert normal["median_error_deg"] < 5.0
    # every correction keeps the heading at half light, where the paper's compass loses it
    for e in ("mean", "map", "session"):
        assert summary["results"][f"room/exposure={e}"]["illumination_0.5"]["within_5deg"] >= 0.85
    session = summary["results"]["room/exposure=session"]
    assert session["illumination_1.0"]["session_gain"] == 1.0
    assert session["illumination_0.5"]["session_gain"] == 2.0
    assert session["illumination_1.0"]["median_error_deg"] == normal["median_error_deg"]
    assert "duration_s" not in summary  # results.json holds figures only
    png = (tmp_path / "synthetic_compass.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_bench_compass_json_last_line(capsys):
    assert main(["bench", "compass", "--json", "--frames", "2", "--repeats", "1"]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    result = json.loads(last)
    for key in ("learn_ms", "localize_ms", "floor_ms", "pixels_per_s"):
        assert result[key] > 0
    assert result["scanned_pixels"] == 104 * 40
    assert result["median_heading_error_deg"] < 5.0


def test_experiment_without_data_fails_clearly(tmp_path, capsys):
    assert main(["experiment", "real-rotation", "--data", str(tmp_path / "nope")]) == 2
    assert "not found" in capsys.readouterr().err


def test_demo_runs_the_main_job(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path), "--learn-time", "0.3", "--seed", "1"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    for key in ("home_error_m", "final_heading_error_deg", "success", "duration_s"):
        assert key in summary
    assert (tmp_path / "demo.png").read_bytes()[:4] == b"\x89PNG"
    assert "cm from home" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["evaluate", "--tracker", "kalmann", "--episodes", "1"], "unknown tracker"),
        (["demo", "--tracker", '{"type": "grid", "half_life_s": -1}'], "half_life_s"),
        (["demo", "--tracker", "no_such_module:Tracker"], "cannot import"),
    ],
)
def test_bad_trackers_fail_before_any_work(tmp_path, capsys, argv, message):
    assert main([*argv, "--out", str(tmp_path / "out")]) == 2
    assert message in capsys.readouterr().err


def test_tracker_json_must_be_an_object(capsys):
    with pytest.raises(SystemExit) as e:
        main(["demo", "--tracker", "{not json"])
    assert e.value.code == 2
    assert "JSON" in capsys.readouterr().err
