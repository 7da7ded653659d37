"""The ``vc-gym`` command end to end (small budgets)."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys

import numpy as np
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


def test_bench_compass_json_last_line(capsys):
    assert main(["bench", "compass", "--json", "--frames", "2", "--repeats", "1"]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    result = json.loads(last)
    for key in ("learn_ms", "localize_ms", "floor_ms", "pixels_per_s"):
        assert result[key] > 0
    assert result["scanned_pixels"] == 104 * 40
    assert result["median_heading_error_deg"] < 5.0


def test_real_rotation_without_any_photo_folder_says_where_to_put_them(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.setattr("vc_gym.experiments.real_rotation.default_real_data_dir", lambda: None)
    out = tmp_path / "out"
    assert main(["experiment", "real-rotation", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "real photos not found" in err and "VC_GYM_REAL_DATA" in err
    assert not out.exists()


@pytest.mark.slow
def test_demo_runs_the_main_job(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path), "--learn-time", "0.3", "--seed", "1"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    for key in ("home_error_m", "final_heading_error_deg", "success", "duration_s"):
        assert key in summary
    # it walks home: measured kidnapped 1.38 m from home, stopped 0.19 m from it (a
    # homing that stays where it was put would stop 1.38 m away)
    from vc_gym.envs.learning import HOME

    kidnapped = float(np.hypot(*np.subtract(summary["start_pose"][:2], HOME)))
    assert kidnapped > 1.0, summary
    assert summary["success"] and summary["stopped"], summary
    assert summary["home_error_m"] <= summary["success_radius_m"], summary
    assert summary["home_error_m"] < 0.25 * kidnapped, summary
    assert summary["home_error_m"] == pytest.approx(float(np.hypot(*summary["stop_offset_m"])))
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


# ------------------------------------------------------ bounds, checked before any work
#: What each command would start: replaced in the tests below by a function that fails
#: the test, so that an argument checked too late shows up as that failure.
WORK = [
    "vc_gym.jobs.output.new_out_dir",
    "vc_gym.jobs.output.check_out_dir",
    "vc_gym.jobs.output.check_out_file",
    "vc_gym.experiments.check.run_check",
    "vc_gym.experiments.benchmarks.soak.soak",
    "vc_gym.experiments.demo.run_demo",
    "vc_gym.experiments.render_scenes.render_scene_pictures",
    "vc_gym.experiments.benchmarks.compass.bench_compass",
    "vc_gym.experiments.benchmarks.env.bench_env",
    "vc_gym.experiments.benchmarks.backends.bench_backends",
]


@pytest.fixture
def no_work(monkeypatch):
    def started(*args, **kwargs):
        raise AssertionError("work started before the arguments were checked")

    # every module that binds these names at import is imported first: one imported while
    # they are replaced would keep the replacement after the test
    import pkgutil

    import vc_gym

    for info in pkgutil.walk_packages(vc_gym.__path__, "vc_gym."):
        if not info.name.endswith("__main__") and not info.name.startswith("vc_gym.baselines"):
            importlib.import_module(info.name)
    for target in WORK:
        monkeypatch.setattr(target, started)


MANY_SEEDS = ",".join(str(s) for s in range(1001))


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["evaluate", "--workers", "100000"], "--workers must be an int in 1.."),
        (["experiment", "homing", "--workers", "100000"], "--workers must be an int in 1.."),
        (["evaluate", "--workers", "0"], "--workers must be an int in 1.."),
        (["evaluate", "--episodes", "100000000"], "--episodes must be in 1..10000"),
        (["experiment", "homing", "--episodes", "0"], "--episodes must be in 1..10000"),
        (["experiment", "homing", "--seeds", MANY_SEEDS], "--seeds must name 1..1000 seeds"),
        (["experiment", "homing", "--seeds=-1"], "--seeds must be in 0.."),
        (["experiment", "homing", "--seed", "-1"], "--seed must be in 0.."),
        (["experiment", "homing", "--video", "100000"], "--video must be in 0..1000"),
        (["evaluate", "--learn-time", "1e9"], "--learn-time must be in (0, 60]"),
        (["evaluate", "--max-homing", "1e9"], "--max-homing must be in (0, 3600]"),
        (["experiment", "homing", "--atlas", "/no/such/folder"], "--atlas /no/such/folder"),
        (["experiment", "synthetic-compass", "--seed", "-1"], "--seed must be in 0.."),
        (["demo", "--seed", "-1"], "--seed must be in 0.."),
        (["demo", "--learn-time", "1e9"], "--learn-time must be in (0, 60]"),
        (["render", "--seed", "-1"], "--seed must be in 0.."),
    ],
)
def test_folder_commands_check_every_argument_first(tmp_path, capsys, no_work, argv, message):
    assert main([*argv, "--out", str(tmp_path / "out")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["check", "--soak-steps", "-1"], "--soak-steps must be in 20..1000000, got -1"),
        (["check", "--soak-steps", "100000000"], "--soak-steps must be in 20..1000000"),
        (["check", "--soak-cycles", "100000"], "--soak-cycles must be in 10..10000"),
        (["soak", "--steps", "100000000"], "--steps must be in 4000..1000000"),
        (["soak", "--cycles", "1000000"], "--cycles must be in 10..10000"),
        (["soak", "--window", "5"], "--window must be in 10.."),
        (["soak", "--seed", "-1"], "--seed must be in 0.."),
        (["bench", "compass", "--repeats", "0"], "--repeats must be in 1..1000"),
        (["bench", "env", "--repeats", "100000"], "--repeats must be in 1..1000"),
        (["bench", "compass", "--frames", "100000"], "--frames must be in 1..1000"),
        (["bench", "compass", "--seed", "-1"], "--seed must be in 0.."),
        (["bench", "backends", "--workers", "100000"], "--workers must be an int in 2.."),
        (["bench", "backends", "--episodes", "100000000"], "--episodes must be in 1..10000"),
        (["bench", "train", "--n-envs", "100000"], "--n-envs must be an int in 1.."),
        (["bench", "train", "--timesteps", "1000000000"], "--timesteps must be in 1..1000000"),
        (["bench", "compass", "--plot", "x.png"], "--plot is for 'bench filters'"),
    ],
)
def test_file_commands_check_every_argument_first(tmp_path, capsys, no_work, argv, message):
    assert main([*argv, "--out", str(tmp_path / "out" / "result.json")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "argv", [["check"], ["soak"], ["bench", "compass"], ["bench", "filters", "--plot", "p.png"]]
)
def test_a_result_file_name_too_long_for_its_temporary_file_fails_first(
    tmp_path, capsys, monkeypatch, argv
):
    """A 245-byte name passes a plain write test, but the atomic writer's temporary
    ``.{name}.XXXXXXXX.tmp.json`` would not fit: refused before the run, not after."""
    for target in WORK[3:]:  # the work, not the checks of --out
        monkeypatch.setattr(target, lambda *a, **k: pytest.fail("work started"))
    name = "r" * 240 + ".json"
    assert main([*argv, "--out", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and "temporary file" in err
    assert list(tmp_path.iterdir()) == []


def test_a_plot_name_too_long_fails_first(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(
        "vc_gym.experiments.benchmarks.filters.bench_filters",
        lambda *a, **k: pytest.fail("work started"),
    )
    assert main(["bench", "filters", "--plot", str(tmp_path / ("p" * 245 + ".png"))]) == 2
    assert "--plot" in capsys.readouterr().err


def test_real_rotation_without_photos_leaves_no_folder(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["experiment", "real-rotation", "--data", str(tmp_path / "nope"), "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--data" in err and "not a folder" in err
    assert not out.exists()


# ---------------------------------------------------------------------------- Ctrl-C
def _interrupted(*args, **kwargs):
    raise KeyboardInterrupt


@pytest.mark.parametrize(
    ("command", "argv", "hint"),
    [
        ("check.run", ["check"], ""),
        ("demo.run", ["demo"], ""),
        (
            "experiment.run_experiment",
            ["experiment", "homing", "--out", "RUN"],
            "; rerun the same command to resume from the jobs saved in RUN",
        ),
        (
            "experiment.run_experiment",
            ["evaluate", "--out", "RUN"],
            "; rerun the same command to resume from the jobs saved in RUN",
        ),
        (
            "experiment.run_experiment",
            ["experiment", "homing"],
            "; rerun the same command to resume from the jobs saved in vc_gym_homing",
        ),
    ],
)
def test_ctrl_c_is_one_line_and_status_130(monkeypatch, capsys, command, argv, hint):
    monkeypatch.setattr(f"vc_gym.cli.{command}", _interrupted)
    assert main(argv) == 130
    captured = capsys.readouterr()
    assert captured.err == f"vc-gym {argv[0]}: interrupted{hint}\n"


def test_ctrl_c_in_train_says_how_to_resume(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr("vc_gym.cli.train.run", _interrupted)
    run = tmp_path / "agent"
    assert main(["train", "--out", str(run)]) == 130
    assert "no checkpoint was saved" in capsys.readouterr().err
    (run / "checkpoints").mkdir(parents=True)
    (run / "checkpoints" / "model_2048_steps.zip").write_bytes(b"")
    assert main(["train", "--out", str(run)]) == 130
    err = capsys.readouterr().err
    assert err == (
        f"vc-gym train: interrupted; 'vc-gym train --resume {run}' continues from its last "
        "checkpoint\n"
    )
    assert main(["train", "--seeds", "0,1", "--out", str(run)]) == 130
    assert "rerun the same command to resume the sweep" in capsys.readouterr().err


def _pool_workers(parent: int) -> list[int]:
    """The process-pool workers among ``parent``'s children (read from ``/proc``)."""
    from pathlib import Path

    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            ppid = int(stat.read_text().rsplit(")", 1)[1].split()[1])
            cmdline = (stat.parent / "cmdline").read_bytes()
        except (OSError, ValueError, IndexError):
            continue
        if ppid == parent and b"spawn_main" in cmdline:
            found.append(int(stat.parent.name))
    return found


@pytest.mark.slow
@pytest.mark.skipif(not os.path.isfile("/proc/self/stat"), reason="reads /proc")
def test_ctrl_c_stops_a_running_experiment_and_its_workers(tmp_path):
    """SIGINT to the whole process group, as Ctrl-C in a terminal sends it: one line,
    status 130, no traceback from the command or its two workers, and a prompt exit."""
    import os
    import signal
    import time

    err_path = tmp_path / "stderr.txt"
    out = tmp_path / "run"
    with open(err_path, "w") as err:
        proc = subprocess.Popen(
            # far more episodes than it runs before the Ctrl-C: still busy when it comes
            ["vc-gym", "experiment", "homing", "--quick", "--episodes", "200", "--workers", "2",
             "--out", str(out)],  # fmt: skip
            stdout=subprocess.DEVNULL,
            stderr=err,
            start_new_session=True,
            # a terminal's Ctrl-C, even if this test runs with SIGINT ignored (started
            # as a background job), which the command would otherwise inherit
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )
    try:
        deadline = time.monotonic() + 120  # both workers are busy with episodes
        while time.monotonic() < deadline and not (
            "homing: episodes" in err_path.read_text() and len(_pool_workers(proc.pid)) == 2
        ):
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGINT)
        rc = proc.wait(timeout=60)  # a command that waited for its jobs would hang here
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    text = err_path.read_text()
    assert rc == 130, text
    assert "Traceback" not in text and "KeyboardInterrupt" not in text
    assert "leaked" not in text  # no resource the stopped workers held is left over
    hint = f"rerun the same command to resume from the jobs saved in {out}"
    assert f"vc-gym experiment: interrupted; {hint}\n" in text
