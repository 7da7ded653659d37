"""The job runner: backends, saved job results, resume, retries, dead workers."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from vc_gym.jobs.backends import LocalBackend, make_backend
from vc_gym.jobs.job import Job
from vc_gym.jobs.output import check_out_dir
from vc_gym.jobs.run import ExperimentRun

HERE = Path(__file__).parent
JOBS = "runner_jobs"


def square_jobs(n, log=None, sleep_s=0.0, started=None):
    args = {"log": log, "sleep_s": sleep_s, **({"started": started} if started else {})}
    return [Job(f"x{i:02d}", f"{JOBS}:square", {"x": i, **args}) for i in range(n)]


def run_squares(out, workers, n=6, **kwargs):
    with LocalBackend(workers) as backend:
        run = ExperimentRun(out, "toy", backend, {"n": n}, progress=False)
        outs = run.run("squares", square_jobs(n, **kwargs))
        return run, outs, run.finish({"squares": [o["square"] for o in outs]})


@pytest.mark.parametrize("workers", [1, 2])
def test_outputs_in_job_order_with_timings_kept_apart(tmp_path, workers):
    run, outs, doc = run_squares(tmp_path, workers)
    assert [o["x"] for o in outs] == list(range(6))
    assert all("timing" not in o for o in outs)
    assert doc["squares"] == [i * i for i in range(6)] and doc["failed_jobs"] == []
    saved = json.loads((tmp_path / "run.json").read_text())
    assert saved["backend"] == "local" and saved["workers"] == workers
    assert saved["stages"]["squares"]["ran"] == 6 and saved["stages"]["squares"]["jobs_per_s"] > 0
    assert len(saved["job_timings"]["squares"]) == 6
    assert "timing" not in (tmp_path / "results.json").read_text()
    pids = {t["pid"] for t in saved["job_timings"]["squares"].values()}
    assert (pids == {os.getpid()}) == (workers == 1)


def test_the_same_jobs_give_the_same_bytes_whatever_the_worker_count(tmp_path):
    run_squares(tmp_path / "one", 1)
    run_squares(tmp_path / "two", 2)
    assert (tmp_path / "one" / "results.json").read_bytes() == (
        tmp_path / "two" / "results.json"
    ).read_bytes()


def test_resume_after_a_killed_run_redoes_nothing_and_loses_nothing(tmp_path):
    out, log = tmp_path / "run", tmp_path / "log.txt"
    script = (
        f"import sys; sys.path.insert(0, {str(HERE)!r}); from test_runner import run_squares; "
        f"run_squares({str(out)!r}, 1, n=8, log={str(log)!r}, sleep_s=0.4)"
    )
    proc = subprocess.Popen([sys.executable, "-c", script])
    jobs_dir = out / "jobs" / "squares"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if jobs_dir.is_dir() and len(list(jobs_dir.glob("x*.json"))) >= 3:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    # x*.json: a job killed while it was saved leaves its temporary file (.x02.json...)
    finished = sorted(p.stem for p in jobs_dir.glob("x*.json"))
    assert 3 <= len(finished) < 8
    before = log.read_text().split()
    run, outs, doc = run_squares(out, 1, n=8, log=str(log), sleep_s=0.4)
    assert doc["squares"] == [i * i for i in range(8)]
    counts = {x: log.read_text().split().count(x) for x in map(str, range(8))}
    for key in finished:  # a finished job is never redone
        assert counts[str(int(key[1:]))] == 1
    assert all(c >= 1 for c in counts.values())  # none is lost
    assert run.stages["squares"]["resumed"] == len(finished)
    assert len(log.read_text().split()) - len(before) == 8 - len(finished)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # a zombie (exited, not yet reaped by its new parent) counts as gone
    stat = Path(f"/proc/{pid}/stat")
    return not (stat.is_file() and stat.read_text().rsplit(")", 1)[1].split()[0] == "Z")


@pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="reads /proc")
def test_workers_of_a_killed_parent_stop_their_jobs(tmp_path):
    log = tmp_path / "done.txt"  # a job that ends writes here
    started = tmp_path / "started"  # a job that starts writes here
    started.mkdir()
    script = (
        f"import sys; sys.path.insert(0, {str(HERE)!r}); from test_runner import run_squares; "
        f"run_squares({str(tmp_path / 'run')!r}, 2, n=2, log={str(log)!r}, sleep_s=120, "
        f"started={str(started)!r})"
    )
    proc = subprocess.Popen([sys.executable, "-c", script])
    try:
        deadline = time.monotonic() + 60  # both workers are in their 120 s jobs
        while time.monotonic() < deadline and len(list(started.iterdir())) < 2:
            time.sleep(0.05)
        workers = _worker_pids(proc.pid)
        assert len(workers) == 2, "the pool did not start"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline and any(map(_alive, workers)):
        time.sleep(0.2)
    left = [pid for pid in workers if _alive(pid)]
    for pid in left:  # do not leave them running if the test fails
        os.kill(pid, signal.SIGKILL)
    assert not left, "the workers outlived their parent"
    assert not log.exists()  # no job ran to its end


def _worker_pids(parent: int) -> list[int]:
    """The pool workers among ``parent``'s children (not its resource tracker)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
            cmdline = (stat.parent / "cmdline").read_bytes()
        except OSError:
            continue
        ppid = int(text.rsplit(")", 1)[1].split()[1])
        if ppid == parent and b"spawn_main" in cmdline:
            found.append(int(stat.parent.name))
    return found


def test_a_failing_job_is_retried_once_then_reported(tmp_path):
    run = ExperimentRun(tmp_path, "toy", LocalBackend(1), {}, progress=False)
    jobs = [
        Job("flaky", f"{JOBS}:flaky", {"marker": str(tmp_path / "marker")}),
        Job("broken", f"{JOBS}:broken", {"reason": "always wrong"}),
        Job("fine", f"{JOBS}:square", {"x": 3}),
    ]
    outs = run.run("mixed", jobs)
    assert outs[0] == {"ok": True} and outs[1] is None and outs[2]["square"] == 9
    doc = run.finish({})
    assert doc["failed_jobs"] == [
        {"stage": "mixed", "key": "broken", "attempts": 2, "error": "ValueError: always wrong"}
    ]
    assert run.stages["mixed"]["retried"] == 2 and run.stages["mixed"]["failed"] == 1
    rec = json.loads((tmp_path / "jobs" / "mixed" / "broken.json").read_text())
    assert not rec["ok"] and "always wrong" in rec["traceback"]
    # a resumed run tries the failed job again, not the finished ones
    run2 = ExperimentRun(tmp_path, "toy", LocalBackend(1), {}, progress=False)
    run2.run("mixed", jobs)
    assert run2.stages["mixed"]["resumed"] == 2 and run2.stages["mixed"]["ran"] == 1


def test_a_dead_worker_fails_its_job_not_the_run(tmp_path):
    jobs = [Job("dies", f"{JOBS}:die", {}), *square_jobs(4)]
    with LocalBackend(2) as backend:  # a hang here is ended by the suite's timeout
        run = ExperimentRun(tmp_path, "toy", backend, {}, progress=False)
        outs = run.run("mixed", jobs)
    assert outs[0] is None and [o["square"] for o in outs[1:]] == [0, 1, 4, 9]
    (failure,) = run.failures
    assert failure["key"] == "dies" and failure["attempts"] == 2
    assert "worker process died" in failure["error"]


class PoolThatBreaks:
    """A process pool whose worker died just before the next submission: it runs the
    first ``good`` jobs, then refuses every new one (as a broken ProcessPoolExecutor
    does) and fails those still pending."""

    def __init__(self, good):
        import concurrent.futures as cf

        self.cf, self.good, self.futures = cf, good, []

    def submit(self, fn, *args):
        from concurrent.futures.process import BrokenProcessPool

        if self.good == 0:
            for f in self.futures:
                if not f.done():
                    f.set_exception(BrokenProcessPool("a worker died"))
            raise BrokenProcessPool("a worker died")
        self.good -= 1
        fut = self.cf.Future()
        fut.set_result(fn(*args))
        self.futures.append(fut)
        return fut

    def shutdown(self, wait=True, cancel_futures=False):
        pass


@pytest.mark.parametrize("good", [0, 1, 3])
def test_a_pool_that_breaks_between_submissions_loses_no_job(tmp_path, good):
    with LocalBackend(2) as backend:
        backend._executor = PoolThatBreaks(good)  # the next pool is a fresh, real one
        run = ExperimentRun(tmp_path, "toy", backend, {}, progress=False)
        outs = run.run("squares", square_jobs(5))
    assert [o["square"] for o in outs] == [0, 1, 4, 9, 16]
    assert run.failures == []


def test_a_folder_of_another_run_is_refused(tmp_path):
    run_squares(tmp_path, 1, n=2)
    with pytest.raises(ValueError, match="another run"):
        ExperimentRun(tmp_path, "toy", LocalBackend(1), {"n": 3}, progress=False)
    with pytest.raises(ValueError, match="another run"):
        ExperimentRun(tmp_path, "other", LocalBackend(1), {"n": 2}, progress=False)


def test_bad_outputs_and_arguments_are_clear_errors(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(ValueError, match="not a folder"):
        check_out_dir(tmp_path / "file")
    with pytest.raises(ValueError, match="safe file name"):
        Job("../up", f"{JOBS}:square")
    with pytest.raises(ValueError, match="module:function"):
        Job("a", "square")
    with pytest.raises(ValueError, match="JSON"):
        Job("a", f"{JOBS}:square", {"x": object()})
    with pytest.raises(ValueError, match="workers"):
        LocalBackend(0)
    with pytest.raises(ValueError, match="unknown backend"):
        make_backend("slurm")
    with pytest.raises(ValueError, match="address"):
        make_backend("local", address="auto")
    run = ExperimentRun(tmp_path / "r", "toy", LocalBackend(1), {}, progress=False)
    with pytest.raises(ValueError, match="not unique"):
        run.run("s", [Job("a", f"{JOBS}:square", {"x": 1})] * 2)


# --- the deprecated import place vc_gym.jobs.runner ---------------------------------------


def test_names_read_from_the_old_runner_module_warn_and_are_the_same_objects():
    from vc_gym.jobs import runner

    assert {"Job", "ExperimentRun", "LocalBackend", "make_backend", "check_workers"} <= set(
        runner.MOVED
    )
    for name, module in runner.MOVED.items():
        moved = rf"jobs\.runner\.{name} moved to {module.__name__}\.{name}"
        with pytest.warns(DeprecationWarning, match=moved):
            assert getattr(runner, name) is getattr(module, name)
    with pytest.raises(AttributeError, match="no_such_name"):
        runner.no_such_name  # noqa: B018


def test_from_import_of_the_old_runner_module_warns():
    with pytest.warns(DeprecationWarning, match="vc_gym.jobs.backends.make_backend"):
        from vc_gym.jobs.runner import make_backend as old
    assert old is make_backend
