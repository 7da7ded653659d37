"""``vc-gym check``'s security suites: files that name code, bombs, runs that would destroy
runs, and arguments checked before work.

Each case does what a hostile file or a careless user would do and checks the promise of
README's *Safety and limits*: a file never chooses code (only the person at the keyboard
does), no file hangs the reader or exhausts memory, no run overwrites another, and every
argument is refused before any work starts. A case fails if code from a file runs, if
the refusal is not the documented error, or if it takes longer than its bound.
"""

from __future__ import annotations

import contextlib
import json
import shutil
import signal
import subprocess
import sys
import time
import zipfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.agents.learned import PRETRAINED_MODEL, LearnedHomingAgent
from vc_gym.config_files import read_settings
from vc_gym.experiments.check_case import Case, raises
from vc_gym.training.config import read_train_config
from vc_gym.training.safe_load import UnsafeModelError, load_sb3_model

__all__ = ["alias_bomb", "model_with_data", "security_cases"]

#: A refusal must come within this many seconds (a bomb refused late is a hang).
REFUSAL_LIMIT_S = 5.0


@contextlib.contextmanager
def _quick(what: str, limit_s: float = REFUSAL_LIMIT_S) -> Iterator[None]:
    t0 = time.perf_counter()
    yield
    took = time.perf_counter() - t0
    assert took < limit_s, f"{what} took {took:.1f} s (limit {limit_s:.0f} s)"


def _no_exit(fn: Callable[[], object]) -> Callable[[], object]:
    """``fn`` with ``SystemExit`` (a file that named ``sys:exit``) turned into a failure."""

    def run() -> object:
        try:
            return fn()
        except SystemExit as exc:
            raise AssertionError(f"a file made the process exit ({exc.code!r})") from None

    return run


#: Longest a refused command may run (it starts a Python interpreter and imports vc_gym).
COMMAND_LIMIT_S = 60.0


def _command(argv: list[str], timeout_s: float = COMMAND_LIMIT_S) -> subprocess.CompletedProcess:
    """Run ``vc-gym ARGV`` as a user would, in its own process; its exit status and output."""
    return subprocess.run(
        [sys.executable, "-m", "vc_gym.cli", *argv],
        capture_output=True,
        text=True,
        timeout=timeout_s,
        stdin=subprocess.DEVNULL,
        check=False,
    )


def _refused_command(argv: list[str], match: str = "") -> subprocess.CompletedProcess:
    """``vc-gym ARGV`` must exit 2 with ``match`` in its error and no traceback."""
    r = _command(argv)
    said = r.stderr[-300:]
    assert r.returncode == 2, f"vc-gym {argv[0]} exited {r.returncode}, expected 2: {said}"
    assert "Traceback" not in r.stderr, f"a traceback: {r.stderr[-300:]}"
    assert match.lower() in r.stderr.lower(), f"no {match!r} in: {r.stderr[-300:]}"
    return r


# ------------------------------------------------------------------- files that name code
def _agent_copy(tmp: Path, env_change: dict[str, Any]) -> tuple[Path, Path]:
    folder = tmp / "agent"
    shutil.copytree(PRETRAINED_MODEL.parent, folder)
    cfg = folder / "config.json"
    data = json.loads(cfg.read_text())
    data["env"].update(env_change)
    cfg.write_text(json.dumps(data))
    return folder / "model.zip", cfg


def _agent_config_names_code(change: dict[str, Any]) -> Callable[[Path], None]:
    def run(tmp: Path) -> None:
        marker = tmp / "code-ran"
        spec = json.loads(json.dumps(change).replace("MARKER", str(marker)))
        model, cfg = _agent_copy(tmp, spec)
        raises(ValueError, str(cfg), _no_exit(lambda: LearnedHomingAgent(model)))
        out = tmp / "run"
        _refused_command(["evaluate", "--agent", str(model), "--episodes", "1", "--out", str(out)])
        assert not marker.exists(), "code named by config.json ran"
        assert not out.exists(), "the refused command left an output folder"

    return run


def _train_settings_name_code(text: str, name: str) -> Callable[[Path], None]:
    def run(tmp: Path) -> None:
        path = tmp / name
        path.write_text(text)
        modules = set(sys.modules)
        raises(ValueError, str(path), _no_exit(lambda: read_train_config(path)))
        assert "this" not in set(sys.modules) - modules, "a settings file imported a module"
        out = tmp / "run"
        _refused_command(["train", "--config", str(path), "--out", str(out)], str(path))
        assert not out.exists(), "the refused command left an output folder"

    return run


def _resumed_run_names_code(tmp: Path) -> None:
    run = tmp / "run"
    run.mkdir()
    data = json.loads((PRETRAINED_MODEL.parent / "config.json").read_text())
    data["tracker"] = data["env"]["tracker"] = "os:abort"
    (run / "config.json").write_text(json.dumps(data))
    _refused_command(["train", "--resume", str(run)], "import path")


def model_with_data(tmp: Path, edit: Callable[[dict[str, Any]], None]) -> Path:
    """A copy of the shipped policy in ``tmp/model.zip`` whose ``data`` ``edit`` changed."""
    path = tmp / "model.zip"
    with zipfile.ZipFile(PRETRAINED_MODEL) as zin, zipfile.ZipFile(path, "w") as zout:
        for info in zin.infolist():
            content = zin.read(info.filename)
            if info.filename == "data":
                data = json.loads(content)
                edit(data)
                content = json.dumps(data).encode()
            zout.writestr(info.filename, content)
    return path


def _model_env_id(tmp: Path) -> None:
    module = "vc_gym_check_never_imported"
    path = model_with_data(tmp, lambda d: d.update(env=f"{module}:Foo-v0"))
    model = load_sb3_model("ppo", path)  # the id is dropped, never made
    assert module not in sys.modules and model.env is None


def _model_huge_network(tmp: Path) -> None:
    path = model_with_data(tmp, lambda d: d["policy_kwargs"].update(net_arch=[10_000, 10_000]))
    with _quick("a 10,000 x 10,000 network's refusal"):
        raises(UnsafeModelError, "layer sizes", lambda: load_sb3_model("ppo", path))


def _model_buffer_bomb(tmp: Path) -> None:
    path = model_with_data(tmp, lambda d: d.update(n_steps=10**9))
    with _quick("a 10^9-step rollout buffer's refusal"):
        raises(UnsafeModelError, "n_steps", lambda: load_sb3_model("ppo", path))


def _model_network_not_its_weights(tmp: Path) -> None:
    path = model_with_data(tmp, lambda d: d["policy_kwargs"].update(net_arch=[256, 256]))
    raises(UnsafeModelError, "do not match", lambda: load_sb3_model("ppo", path))


def _code_cases() -> list[Case]:
    suite = "code_in_files"
    command = {"type": "os:system", "command": "touch MARKER"}
    cases = [
        Case(
            suite,
            f"agent config.json: env.{key} = {value!r}",
            _agent_config_names_code({key: value}),
        )
        for key, value in (
            ("tracker", command),
            ("tracker", "os:abort"),
            ("tracker", "sys:exit"),
            ("tracker", "this:x"),
            ("scene", "os:system"),
            ("learner", "os:system"),
        )
    ]
    for spec in ("os:abort", "sys:exit", "this:x"):
        cases.append(
            Case(
                suite,
                f"train --config: tracker {spec!r}",
                _train_settings_name_code(f"tracker: {spec!r}\n", "t.yml"),
            )
        )
    cases += [
        Case(
            suite,
            "train --config: tracker {'type': 'os:system'}",
            _train_settings_name_code(
                json.dumps({"tracker": {"type": "os:system", "command": "true"}}), "t.json"
            ),
        ),
        Case(suite, "train --resume: the run's config.json: os:abort", _resumed_run_names_code),
        Case(suite, "model.zip: data names an env id 'module:Id'", _model_env_id),
        Case(suite, "model.zip: net_arch [10000, 10000]", _model_huge_network),
        Case(suite, "model.zip: n_steps 10^9", _model_buffer_bomb),
        Case(suite, "model.zip: net_arch not its weights'", _model_network_not_its_weights),
    ]
    return cases


# ------------------------------------------------------------------- bombs and exhaustion
def alias_bomb(levels: int = 9) -> str:
    """A YAML file of a few hundred bytes whose aliases expand to 10^levels strings."""
    lines = ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for i in range(1, levels):
        refs = ", ".join([f"*a{i - 1}"] * 10)
        lines.append(f"a{i}: &a{i} [{refs}]")
    return "\n".join(lines) + "\n"


def _settings_refused(text: str, name: str, match: str) -> Callable[[Path], None]:
    def run(tmp: Path) -> None:
        path = tmp / name
        path.write_text(text)
        with _quick(f"{name}'s refusal", 1.0):
            raises(ValueError, match, lambda: read_settings(path))

    return run


def _huge_config_json(tmp: Path) -> None:
    model, cfg = _agent_copy(tmp, {})
    data = json.loads(cfg.read_text())
    data["padding"] = "x" * 50_000_000
    cfg.write_text(json.dumps(data))
    with _quick("a 50 MB config.json's refusal", 1.0):
        raises(ValueError, "more than", lambda: LearnedHomingAgent(model))


def _member_bomb(tmp: Path) -> None:
    from vc_gym.compass import VisualCompass
    from vc_gym.errors import MapFileError

    path = tmp / "members.npz"
    with zipfile.ZipFile(path, "w") as z:
        for i in range(100_000):
            z.writestr(f"a{i}.npy", b"")
    with _quick("a 100,000-member .npz's refusal", 1.0):
        raises(MapFileError, "entries", lambda: VisualCompass.load(path))


def _map_claiming_gigabytes(tmp: Path) -> None:
    from vc_gym.compass import CompassConfig

    # a few kB on disk, gigabytes to score one frame: refused when built or loaded
    raises(
        ValueError,
        "MAX_MAP_BYTES",
        lambda: CompassConfig(n_colors=3, sector_deg=360 / 512, heading_step_deg=0.01),
    )


def _billion_particles(_: Path) -> None:
    from vc_gym.filters import ParticleFilter

    with _quick("ParticleFilter(10**9)'s refusal", 1.0):
        raises(ValueError, "particles", lambda: ParticleFilter(10**9))


def _exhaustion_cases() -> list[Case]:
    suite = "exhaustion"
    return [
        Case(suite, "npz: 100,000 members", _member_bomb),
        Case(suite, "map config claiming gigabytes", _map_claiming_gigabytes),
        Case(suite, "ParticleFilter(10**9)", _billion_particles),
        Case(
            suite,
            "settings: YAML alias bomb (9 levels)",
            _settings_refused(alias_bomb(), "bomb.yml", "aliases"),
        ),
        Case(
            suite,
            "settings: a key given twice",
            _settings_refused("gamma: 0.9\ngamma: 0.5\n", "dup.yml", "twice"),
        ),
        Case(
            suite,
            "settings: a JSON key given twice",
            _settings_refused('{"gamma": 0.9, "gamma": 0.5}', "dup.json", "twice"),
        ),
        Case(suite, "agent config.json of 50 MB", _huge_config_json),
    ]


# ------------------------------------------------------------------- runs that destroy runs
def _existing_run_kept(tmp: Path) -> None:
    run = tmp / "run"
    shutil.copytree(PRETRAINED_MODEL.parent, run)
    before = {p.name: p.read_bytes() for p in run.iterdir()}
    _refused_command(["train", "--out", str(run), "--timesteps", "64", "--seed", "5"], "--resume")
    after = {p.name: p.read_bytes() for p in run.iterdir()}
    assert after == before, "a refused train changed the run it was pointed at"


def _torn_checkpoint_skipped(tmp: Path) -> None:
    from vc_gym.training.config import read_train_config
    from vc_gym.training.run_folder import resume_state

    run = tmp / "run"
    shutil.copytree(PRETRAINED_MODEL.parent, run)
    (run / "checkpoints").mkdir()
    whole = run / "checkpoints" / "model_64_steps.zip"
    shutil.copy2(run / "model.zip", whole)
    torn = run / "checkpoints" / "model_128_steps.zip"
    torn.write_bytes(whole.read_bytes()[: whole.stat().st_size // 2])
    start = resume_state(run, read_train_config(run / "config.json"))
    assert start.checkpoint == whole, f"resumed from {start.checkpoint}, not the whole one"
    assert [path for path, _ in start.skipped] == [torn]


def _largest_map_round_trip(tmp: Path) -> None:
    from vc_gym.compass import Camera, CompassConfig, VisualCompass

    config = None
    for n_sectors in range(512, 1, -1):  # the most sectors 32 classes and 32 bins may have
        try:
            config = CompassConfig(n_colors=32, n_bins=32, sector_deg=360 / n_sectors)
        except ValueError:
            continue
        break
    assert config is not None, "no map of 32 classes and 32 bins is allowed"
    vc = VisualCompass(config)
    frame = np.random.default_rng(0).integers(0, 256, (160, 208, 3), dtype=np.uint8)
    vc.fit_colors([frame])
    vc.learn(frame, Camera())
    again = VisualCompass.load(vc.save(tmp / "largest.npz"))
    assert again.config == vc.config


def _runs_cases() -> list[Case]:
    suite = "runs"
    return [
        Case(suite, "train --out an existing run: refused, the run untouched", _existing_run_kept),
        Case(suite, "train --resume: a torn checkpoint is skipped", _torn_checkpoint_skipped),
        Case(suite, "the largest map the saver writes loads", _largest_map_round_trip),
    ]


# ------------------------------------------------------------------- arguments before work
def _refused_at_once(
    argv: list[str], match: str, made: str | None = None
) -> Callable[[Path], None]:
    def run(tmp: Path) -> None:
        args = [a.replace("TMP", str(tmp)) for a in argv]
        with _quick(f"vc-gym {argv[0]}'s refusal", 30.0):
            _refused_command(args, match)
        if made is not None:
            left = Path(made.replace("TMP", str(tmp)))
            assert not left.exists(), f"the refused command left {left}"

    return run


def _hear_ctrl_c() -> None:
    """In the child before it runs: SIGINT back to its default, so that the child hears
    the check's Ctrl-C even when this process was started with SIGINT ignored (a
    shell's background job), which a child would otherwise inherit."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _interrupted(tmp: Path) -> None:
    err_path = tmp / "stderr.txt"
    with open(err_path, "w") as err_file:
        proc = subprocess.Popen(
            [sys.executable, "-m", "vc_gym.cli", "soak", "--steps", "100000", "--cycles", "10"],
            stdout=subprocess.DEVNULL,
            stderr=err_file,
            stdin=subprocess.DEVNULL,
            preexec_fn=_hear_ctrl_c,
        )
    deadline = time.monotonic() + COMMAND_LIMIT_S
    while "soak: steps" not in err_path.read_text() and time.monotonic() < deadline:
        time.sleep(0.05)  # Ctrl-C once the soak is stepping
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        raise AssertionError("vc-gym soak did not stop within 30 s of Ctrl-C") from None
    err = err_path.read_text()
    assert proc.returncode == 130, f"exit {proc.returncode} after Ctrl-C, expected 130"
    assert "Traceback" not in err and "interrupted" in err, f"after Ctrl-C: {err[-300:]}"


def _tracker_json(_: Path) -> None:
    from vc_gym.training.config import TrainConfig, check_names

    config = TrainConfig(tracker={"type": "particle", "n_particles": 500})
    check_names(config)
    assert config.env_kwargs()["tracker"] == {"type": "particle", "n_particles": 500}


def _argument_cases() -> list[Case]:
    suite = "arguments"
    long_name = "TMP/" + "x" * 250 + ".json"
    return [
        Case(
            suite,
            "check --soak-steps -1: refused before any case",
            _refused_at_once(["check", "--soak-steps", "-1"], "soak"),
        ),
        Case(
            suite,
            "soak --out with a 250-character name",
            _refused_at_once(["soak", "--steps", "4000", "--out", long_name], "name"),
        ),
        Case(
            suite,
            "bench compass --out with a 250-character name",
            _refused_at_once(["bench", "compass", "--out", long_name], "name"),
        ),
        Case(
            suite,
            "check --out with a 250-character name",
            _refused_at_once(["check", "--soak-steps", "20", "--out", long_name], "name"),
        ),
        Case(
            suite,
            "demo --seed -1: refused, no folder",
            _refused_at_once(["demo", "--seed", "-1", "--out", "TMP/demo"], "seed", "TMP/demo"),
        ),
        Case(
            suite,
            "evaluate --workers 100000",
            _refused_at_once(
                ["evaluate", "--workers", "100000", "--out", "TMP/ev"], "workers", "TMP/ev"
            ),
        ),
        Case(
            suite,
            "experiment homing --episodes 100000000",
            _refused_at_once(
                ["experiment", "homing", "--episodes", "100000000", "--out", "TMP/h"],
                "episodes",
                "TMP/h",
            ),
        ),
        Case(suite, "train --tracker as a JSON object", _tracker_json),
        Case(suite, "Ctrl-C: one line, exit 130", _interrupted),
    ]


def security_cases() -> list[Case]:
    """Every case of the security suites."""
    return [*_code_cases(), *_exhaustion_cases(), *_runs_cases(), *_argument_cases()]

