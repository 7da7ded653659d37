"""The runner's bounds: worker counts, saved files read within limits, every stage in
run.json, and Ctrl-C stopping the workers at once."""

from __future__ import annotations

import importlib.util
import json
import os
import signal
import threading
import time
from pathlib import Path

import pytest

from vc_gym.jobs import job as job_files
from vc_gym.jobs.backends import LocalBackend, RayBackend, make_backend
from vc_gym.jobs.job import Job
from vc_gym.jobs.run import ExperimentRun
from vc_gym.jobs.workers import MAX_WORKERS, MAX_WORKERS_PER_CPU, check_workers, max_workers

JOBS = "runner_jobs"


def square_jobs(n, log=None, sleep_s=0.0, started=None):
    args = {"log": log, "sleep_s": sleep_s, **({"started": started} if started else {})}
    return [Job(f"x{i:02d}", f"{JOBS}:square", {"x": i, **args}) for i in range(n)]


def _runs(log: Path) -> int:
    return len(log.read_text().split()) if log.exists() else 0


def test_max_workers_follows_the_cpus_within_the_hard_bound():
    assert max_workers() == min(MAX_WORKERS, MAX_WORKERS_PER_CPU * (os.cpu_count() or 1))
    assert check_workers(max_workers()) == max_workers()


@pytest.mark.parametrize("workers", [0, -1, 100_000, 2.0, True, "2"])
def test_backends_refuse_worker_counts_out_of_range(workers):
    with pytest.raises(ValueError, match=r"workers must be an int in 1\.\.\d+"):
        make_backend("local", workers)
    with pytest.raises(ValueError, match="workers"):
        LocalBackend(workers)


def test_too_many_workers_are_refused_before_any_process_starts():
    with pytest.raises(ValueError, match=f"in 1..{max_workers()}"):
        make_backend("local", max_workers() + 1)


@pytest.mark.skipif(importlib.util.find_spec("ray") is None, reason="Ray not installed")
def test_ray_backend_refuses_worker_counts_out_of_range():
    with pytest.raises(ValueError, match="workers"):
        RayBackend(workers=100_000)
    with pytest.raises(ValueError, match="workers"):
        make_backend("ray", 100_000)


def test_run_json_records_a_stage_skipped_on_resume(tmp_path):
    """An experiment skips a stage whose products are saved (ensure_atlases with its
    atlases on disk): run.json still lists it, its jobs as resumed."""
    with LocalBackend(1) as backend:
        run = ExperimentRun(tmp_path, "toy", backend, {"n": 2}, progress=False)
        run.run("learn", square_jobs(1))
        run.run("squares", square_jobs(2))
        run.finish({})
    with LocalBackend(1) as backend:
        run = ExperimentRun(tmp_path, "toy", backend, {"n": 2}, progress=False)
        run.run("squares", square_jobs(2))  # "learn" is not called this time
        run.finish({})
    saved = json.loads((tmp_path / "run.json").read_text())
    assert list(saved["stages"]) == ["learn", "squares"]  # the skipped stage first
    learn = saved["stages"]["learn"]
    assert (learn["jobs"], learn["ran"], learn["resumed"]) == (1, 0, 1)
    assert learn["resumed_keys"] == ["x00"]
    assert saved["stages"]["squares"]["resumed_keys"] == ["x00", "x01"]
    assert set(saved["job_timings"]["learn"]) == {"x00"}


def test_run_json_names_the_resumed_jobs_of_a_partly_resumed_stage(tmp_path):
    with LocalBackend(1) as backend:
        run = ExperimentRun(tmp_path, "toy", backend, {}, progress=False)
        run.run("squares", square_jobs(2))
    (tmp_path / "jobs" / "squares" / "x01.json").unlink()
    with LocalBackend(1) as backend:
        run = ExperimentRun(tmp_path, "toy", backend, {}, progress=False)
        run.run("squares", square_jobs(3))
        run.finish({})
    stage = json.loads((tmp_path / "run.json").read_text())["stages"]["squares"]
    assert (stage["ran"], stage["resumed"], stage["resumed_keys"]) == (2, 1, ["x00"])


def test_an_oversized_job_file_is_not_trusted_and_its_job_runs_again(tmp_path, monkeypatch):
    log = tmp_path / "log.txt"
    out = tmp_path / "run"
    with LocalBackend(1) as backend:
        ExperimentRun(out, "toy", backend, {}, progress=False).run(
            "squares", square_jobs(2, str(log))
        )
    assert _runs(log) == 2
    monkeypatch.setattr(job_files, "MAX_JOB_FILE_BYTES", 2_000)
    path = out / "jobs" / "squares" / "x01.json"
    rec = json.loads(path.read_text())
    rec["padding"] = "x" * 5_000  # valid JSON, same job, too large to be read
    path.write_text(json.dumps(rec))
    with LocalBackend(1) as backend:
        run = ExperimentRun(out, "toy", backend, {}, progress=False)
        outs = run.run("squares", square_jobs(2, str(log)))
    assert _runs(log) == 3  # only the oversized one ran again
    assert [o["square"] for o in outs] == [0, 1]
    assert run.stages["squares"]["resumed_keys"] == ["x00"]
    assert path.stat().st_size < 2_000  # replaced by a fresh record


@pytest.mark.parametrize(
    "text",
    [
        '{"experiment": "toy", "experiment": "toy"}',  # a key twice
        "[" * 100 + "]" * 100,  # nested too deeply
        '{"experiment": "' + "x" * 1_100_000 + '"}',  # larger than MAX_SETTINGS_BYTES
    ],
)
def test_an_unreadable_settings_file_is_a_clear_error(tmp_path, text):
    (tmp_path / "jobs").mkdir()
    (tmp_path / "jobs" / "settings.json").write_text(text)
    with pytest.raises(ValueError, match="settings cannot be read"):
        ExperimentRun(tmp_path, "toy", LocalBackend(1), {}, progress=False)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def test_ctrl_c_stops_the_workers_at_once(tmp_path):
    """Interrupted, the backend terminates its workers instead of waiting for their
    jobs (here 60 s each) to end."""
    log = tmp_path / "done.txt"  # a job that ran its 60 s to the end writes here
    started = tmp_path / "started"
    started.mkdir()
    jobs = square_jobs(2, str(log), sleep_s=60.0, started=str(started))
    pids: list[int] = []
    # Ctrl-C raises KeyboardInterrupt here even if the tests run with SIGINT ignored
    # (started as a background job)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _interrupt_two_busy_workers(jobs, pids, log, started)
    finally:
        signal.signal(signal.SIGINT, previous)


def _interrupt_two_busy_workers(jobs, pids, log, started):
    with LocalBackend(2) as backend:

        def interrupt() -> None:  # Ctrl-C once both workers are in their jobs
            deadline = time.monotonic() + 60
            while len(list(started.iterdir())) < 2 and time.monotonic() < deadline:
                time.sleep(0.02)
            pids.extend(p.pid for p in backend._executor._processes.values())
            os.kill(os.getpid(), signal.SIGINT)  # wakes the main thread's wait, as Ctrl-C

        poller = threading.Thread(target=interrupt, daemon=True)
        with pytest.raises(KeyboardInterrupt):
            with backend:
                poller.start()
                for _ in backend.run(jobs):
                    pass
        poller.join()
    assert len(pids) == 2
    assert backend._executor is None
    assert not [pid for pid in pids if _alive(pid)]
    # had the backend waited for its workers, their 60 s jobs would have ended and logged
    assert not log.exists()
