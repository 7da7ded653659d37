"""The calibration experiment at --quick: its files, its figures and a loose bound."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vc_gym.cli import main
from vc_gym.experiments.real_data import default_real_data_dir
from vc_gym.experiments.studies import get_experiment
from vc_gym.experiments.studies.calibration import (
    DISTANCES_M,
    SIGMAS,
    coverage_figures,
    summary_lines,
)
from vc_gym.jobs import workers


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """The quick run, its jobs in this process; the room they kept is closed after."""
    out = tmp_path_factory.mktemp("calibration") / "one"
    argv = ["experiment", "calibration", "--out", str(out), "--quick", "--workers", "1"]
    assert main([*argv, "--seed", "3", "--json"]) == 0
    yield out
    for key in [k for k in workers._CACHE if isinstance(k, tuple) and k[0] == "room"]:
        workers._CACHE.pop(key).close()


def test_it_writes_figures_a_plot_and_a_table(quick, capsys):
    text = (quick / "results.json").read_text()
    for word in ("seconds", "duration", "timing", "ms_per", str(quick)):
        assert word not in text, word  # figures only: no timings, no paths
    r = json.loads(text)
    assert r["experiment"] == "calibration" and r["failed_jobs"] == []
    assert r["settings"]["seeds"] == [3] and r["settings"]["scenes"] == ["robolab"]
    assert (quick / "calibration.png").stat().st_size > 0
    sim = r["simulated"]
    assert set(sim["all_scenes"]) == {f"{d:g}m" for d in DISTANCES_M}
    for fig in sim["all_scenes"].values():
        assert fig["n"] > 0
        for kind in ("uncalibrated", "calibrated"):
            f = fig[kind]
            assert 0.0 <= f["within_1sigma"] <= f["within_2sigma"] <= 1.0
            assert len(f["curve"]) == len(SIGMAS) and f["curve"] == sorted(f["curve"])
    assert sim["temperatures"]["robolab"]["3"] > 1.0  # tempered: the paper's is too sharp
    near = sim["all_scenes"]["0m"]
    # loose: at the learning spot the calibrated spread covers more than the paper's
    assert near["calibrated"]["within_2sigma"] >= max(0.5, near["uncalibrated"]["within_2sigma"])
    lines = get_experiment("calibration").summary_lines(r)
    assert lines[0].startswith("condition") and any(line.startswith("sim 0m") for line in lines)


@pytest.mark.skipif(default_real_data_dir() is None, reason="real photos not found")
def test_the_real_sets_are_cross_fitted(quick):
    r = json.loads((quick / "results.json").read_text())
    assert set(r["real"]) == {"rotation_grail 10 classes", "rotation_parrington 10 classes"}
    for fig in r["real"].values():
        assert fig["n"] == 27 and len(fig["temperatures"]) == 2
        # the 9 learning photos (34° views 40° apart) do not overlap: no leave-one-out
        assert fig["loo_usable_photos"] == "0 of 9"
        assert fig["calibrated"]["within_2sigma"] >= 0.6
        assert fig["calibrated"]["within_2sigma"] > fig["uncalibrated"]["within_2sigma"]


def test_coverage_figures_count_what_they_say():
    records = [
        {"error_deg": e, "uncalibrated": 0.1, "calibrated": s}
        for e, s in [(0.5, 1.0), (1.5, 1.0), (2.5, 1.0), (0.0, 1.0)]
    ]
    fig = coverage_figures(records)
    assert fig["n"] == 4 and fig["median_abs_error_deg"] == 1.0
    assert fig["calibrated"]["within_1sigma"] == 0.5 and fig["calibrated"]["within_2sigma"] == 0.75
    assert fig["uncalibrated"]["within_2sigma"] == 0.25  # only the zero error
    assert fig["calibrated"]["curve"][SIGMAS.index(3.0)] == 1.0
    empty = coverage_figures([])
    assert empty["n"] == 0 and empty["calibrated"] is None


def test_the_summary_reads_a_result_without_real_photos():
    fig = coverage_figures([{"error_deg": 1.0, "uncalibrated": 0.1, "calibrated": 2.0}])
    results = {
        "simulated": {"all_scenes": {"0m": fig}, "temperatures": {"robolab": {"0": 12.0}}},
        "real": None,
        "real_skipped": "no photos",
    }
    lines = summary_lines(results)
    assert "12" in lines[-2] and lines[-1] == "real photos skipped: no photos"
    assert np.isclose(fig["calibrated"]["within_1sigma"], 1.0)
