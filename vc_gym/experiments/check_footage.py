"""``vc-gym check``'s footage suite: ``vc-gym compass learn/track`` and the env limits
against a careless or hostile user.

Each case builds small footage of a synthetic room in its own folder, runs the command
as a user would and checks the promise of ``docs/file-formats.md``: an output never
replaces an input, an existing output is kept unless ``--overwrite`` is given, no frame
is scaled past the pixel limit, a truncated frame is refused by name (or skipped and
counted with ``--skip-bad-frames``), SIGTERM leaves nothing half-written, every error is
one line naming the flag the user typed, and the envs refuse time limits beyond their
documented bounds at once. A case fails if an input's bytes change, if anything is
left behind, or if the answer is not the promised one.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import io
import json
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import cv2
import gymnasium as gym
import numpy as np

from vc_gym.compass import Camera
from vc_gym.compass.footage import VideoSink
from vc_gym.experiments.check_case import Case, raises
from vc_gym.worlds.panorama import Panorama, render_view
from vc_gym.worlds.panorama_painters import make_panorama

__all__ = ["Runner", "footage_cases", "footage_fixture", "in_process", "in_subprocess"]

#: ``run(argv) -> (exit status, standard output, standard error)`` of ``vc-gym ARGV``.
Runner = Callable[[list[str]], tuple[int, str, str]]

#: The synthetic camera's field of view (degrees) and frame size (width, height).
HFOV = "60"
_SIZE = (96, 72)


# ------------------------------------------------------------------------ the footage
@functools.cache
def _panorama() -> Panorama:
    """The synthetic room every case films (painted once per process)."""
    return make_panorama(np.random.default_rng(11), width=1200, height=300, kind="room")


def _views(yaws: np.ndarray, size: tuple[int, int] = _SIZE) -> list[np.ndarray]:
    pano = _panorama()
    return [render_view(pano, Camera(hfov_deg=float(HFOV), yaw_deg=y), *size) for y in yaws]


def _video(path: Path, frames: list[np.ndarray]) -> Path:
    with VideoSink(path, fps=10) as sink:
        for frame in frames:
            sink.write(frame)
    return path


def footage_fixture(tmp: Path, run: Runner) -> dict[str, Path]:
    """Small footage in ``tmp``: ``turn.mp4`` (a full turn, 24 frames), ``other.mp4``
    (6 views), ``frames/`` (the 6 views as JPEGs), ``yaws.csv`` (their yaws) and
    ``room.npz`` (the map ``vc-gym compass learn`` makes of the turn, run by ``run``)."""
    turn = _video(tmp / "turn.mp4", _views(15.0 * np.arange(24)))
    yaws = np.random.default_rng(3).uniform(0.0, 360.0, 6)
    views = _views(yaws)
    other = _video(tmp / "other.mp4", views)
    folder = tmp / "frames"
    folder.mkdir()
    for k, view in enumerate(views):
        cv2.imwrite(str(folder / f"f{k}.jpg"), cv2.cvtColor(view, cv2.COLOR_RGB2BGR))
    csv = tmp / "yaws.csv"
    csv.write_text("yaw_deg\n" + "".join(f"{y:.3f}\n" for y in yaws))
    room = tmp / "room.npz"
    code, _, err = run(["compass", "learn", str(turn), "--hfov", HFOV, "--map", str(room)])
    assert code == 0, f"learning the check's map failed: {err}"
    return {"turn": turn, "other": other, "frames": folder, "yaws": csv, "map": room}


def in_process(main: Callable[[list[str]], int]) -> Runner:
    """A :data:`Runner` calling ``main`` (:func:`vc_gym.cli.main`, passed in: this layer
    does not import the command line) in this process, its output captured."""

    def run(argv: list[str]) -> tuple[int, str, str]:
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse's usage errors
                code = int(exc.code or 0)
        return code, out.getvalue(), err.getvalue()

    return run


def in_subprocess(argv: list[str]) -> tuple[int, str, str]:
    """A :data:`Runner`: ``vc-gym ARGV`` in a process of its own, as a user runs it."""
    r = subprocess.run(
        [sys.executable, "-m", "vc_gym.cli", *argv],
        capture_output=True,
        text=True,
        timeout=120,
        stdin=subprocess.DEVNULL,
        check=False,
    )
    return r.returncode, r.stdout, r.stderr


def _digest(root: Path) -> dict[str, str]:
    """Every file under ``root`` and the SHA-256 of its bytes."""
    return {
        str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def _refused(run: Runner, argv: list[str], match: str) -> str:
    """``vc-gym ARGV`` must exit 2 with one line of error holding ``match`` (after
    argparse's usage lines for a usage error); ``vc-gym check`` bounds each case's time."""
    code, _, err = run(argv)
    assert code == 2, f"vc-gym {' '.join(argv[:2])} exited {code}, expected 2: {err[-300:]}"
    # one line of error (a usage error has argparse's usage lines above it)
    last = err.rstrip("\n").split("\n")[-1]
    assert "Traceback" not in err and " error: " in last, f"not one line: {err[-300:]}"
    assert match in last, f"no {match!r} in: {last}"
    assert err.count("\n") == 1 or err.startswith("usage:"), f"more than the error: {err[-300:]}"
    return err


def _unchanged(
    run: Runner, make: Callable[[Path, dict[str, Path]], list[str]], match: str
) -> Callable[[Path], None]:
    """A case: the command ``make(tmp, footage)`` is refused with ``match`` and no file
    under ``tmp`` changes, appears or disappears."""

    def case(tmp: Path) -> None:
        footage = footage_fixture(tmp, run)
        argv = [a.replace("TMP", str(tmp)) for a in make(tmp, footage)]
        before = _digest(tmp)
        _refused(run, argv, match.replace("TMP", str(tmp)))
        after = _digest(tmp)
        assert after == before, f"files changed: {sorted(set(after) ^ set(before))}"

    return case


def _track(footage: dict[str, Path], source: str = "other") -> list[str]:
    argv = ["compass", "track", str(footage[source]), "--hfov", HFOV]
    return [*argv, "--map", str(footage["map"])]


def _learn(footage: dict[str, Path], source: str = "turn") -> list[str]:
    return ["compass", "learn", str(footage[source]), "--hfov", HFOV]


# ------------------------------------------------------------------ outputs and inputs
def _video_over_input(tmp: Path, footage: dict[str, Path]) -> list[str]:
    return [*_track(footage), "--out", "TMP/tr", "--video", str(footage["other"])]


def _video_link_to_input(tmp: Path, footage: dict[str, Path]) -> list[str]:
    (tmp / "link.mp4").symlink_to(footage["other"])
    return [*_track(footage), "--out", "TMP/tr", "--video", "TMP/link.mp4"]


def _video_hard_link_to_input(tmp: Path, footage: dict[str, Path]) -> list[str]:
    (tmp / "hard.mp4").hardlink_to(footage["other"])
    return [*_track(footage), "--out", "TMP/tr", "--video", "TMP/hard.mp4"]


def _out_is_the_frames(tmp: Path, footage: dict[str, Path]) -> list[str]:
    return [*_track(footage, "frames"), "--out", str(footage["frames"])]


def _out_holds_the_yaws(tmp: Path, footage: dict[str, Path]) -> list[str]:
    (tmp / "tr").mkdir()
    (tmp / "tr" / "headings.csv").write_bytes(footage["yaws"].read_bytes())
    return [*_track(footage, "frames"), "--yaws", "TMP/tr/headings.csv", "--out", "TMP/tr"]


def _existing_track_kept(run: Runner, tmp: Path) -> None:
    footage = footage_fixture(tmp, run)
    argv = [*_track(footage), "--out", str(tmp / "tr"), "--video", str(tmp / "tr" / "v.mp4")]
    assert run(argv)[0] == 0
    before = _digest(tmp)
    _refused(run, [*argv, "--max-frames", "2"], f"--out: {tmp / 'tr' / 'headings.csv'} exists")
    _refused(run, [*argv[:-4], "--out", str(tmp / "new"), *argv[-2:]], "--video: ")
    assert _digest(tmp) == before and not (tmp / "new").exists()
    code, _, err = run([*argv, "--max-frames", "2", "--overwrite"])
    assert code == 0, err
    assert json.loads((tmp / "tr" / "summary.json").read_text())["frames"] == 2


def _existing_map_kept(run: Runner, tmp: Path) -> None:
    footage = footage_fixture(tmp, run)
    atlas = tmp / "atlas.npz"
    atlas.write_bytes(footage["map"].read_bytes())  # any file there: an atlas, a map
    before = _digest(tmp)
    argv = [*_learn(footage), "--step", "4", "--map", str(atlas)]
    _refused(run, argv, f"--map: {atlas} exists; write elsewhere, or give --overwrite")
    assert _digest(tmp) == before
    code, _, err = run([*argv, "--overwrite"])
    assert code == 0, err


# ----------------------------------------------------------------------- frames
def _width_past_the_limit(tmp: Path, footage: dict[str, Path]) -> list[str]:
    return [*_learn(footage), "--width", "16384", "--map", "TMP/w.npz"]


def _truncated_jpeg(run: Runner, tmp: Path) -> None:
    footage = footage_fixture(tmp, run)
    cut = footage["frames"] / "f3.jpg"
    cut.write_bytes(cut.read_bytes()[: int(cut.stat().st_size * 0.7)])
    before = _digest(tmp)
    argv = [*_track(footage, "frames"), "--out", str(tmp / "tr"), "--json"]
    _refused(run, argv, "f3.jpg: the JPEG ends before its image does (truncated file)")
    assert _digest(tmp) == before
    code, out, err = run([*argv, "--skip-bad-frames"])
    assert code == 0, err
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["frames"] == 5 and summary["skipped_frames"] == 1, summary


# ----------------------------------------------------------------------- SIGTERM
def _sigterm_while_tracking(run: Runner, tmp: Path) -> None:
    footage = footage_fixture(tmp, run)
    big = _video(tmp / "big.mp4", _views(np.linspace(0.0, 720.0, 300), (320, 240)))
    before = _digest(tmp)
    out = tmp / "sigtr"
    argv = ["compass", "track", str(big), "--hfov", HFOV, "--map", str(footage["map"])]
    argv += ["--out", str(out), "--video", str(out / "v.mp4"), "--json"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "vc_gym.cli", *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        stdin=subprocess.DEVNULL,
        text=True,
    )
    try:
        deadline = time.monotonic() + 45.0
        while not list(out.glob(".v.mp4.*.tmp.mp4")):  # the video is being written
            assert proc.poll() is None, f"ended before the signal: {proc.communicate()[1]}"
            assert time.monotonic() < deadline, "the annotated video was never started"
            time.sleep(0.02)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 143, f"exit {proc.returncode} after SIGTERM: {err[-300:]}"
    assert "Traceback" not in err, err[-600:]
    assert err.endswith("vc-gym compass: terminated (SIGTERM)\n"), err[-300:]
    assert not out.exists(), f"left {sorted(p.name for p in out.iterdir())}"
    assert _digest(tmp) == before


# ----------------------------------------------------------------------- messages
def _map_config_disagrees(tmp: Path, footage: dict[str, Path]) -> list[str]:
    from vc_gym.compass.map_files import MAP_SCHEMA, MAP_SCHEMA_VERSION, read_map_file
    from vc_gym.persistence import save_npz_atomic

    arrays = read_map_file(footage["map"])
    config = json.loads(str(arrays["config"]))
    config["n_colors"] = 32
    arrays["config"] = np.array(json.dumps(config))
    save_npz_atomic(tmp / "bad.npz", MAP_SCHEMA, MAP_SCHEMA_VERSION, arrays)
    argv = _track(footage)
    return [*argv[:-1], "TMP/bad.npz", "--out", "TMP/tr"]


def _folder(tmp: Path, name: str = "dir") -> Path:
    (tmp / name).mkdir()
    return tmp / name


def _message_cases(suite: str, run: Runner) -> list[Case]:
    def case(name: str, make: Callable[[Path, dict[str, Path]], list[str]], match: str) -> Case:
        return Case(suite, name, _unchanged(run, make, match))

    return [
        case("learn --map '': names --map", lambda t, f: [*_learn(f), "--map", ""], "--map: give"),
        case(
            "learn --map a folder: refused, nothing written beside it",
            lambda t, f: [*_learn(f), "--map", str(_folder(t))],
            "--map TMP/dir is a folder",
        ),
        case(
            "learn --map /dev/null: refused, nothing written beside it",
            lambda t, f: [*_learn(f), "--map", "/dev/null"],
            "--map /dev/null is not a regular file",
        ),
        case(
            "track --map a folder: says it is a folder",
            lambda t, f: [*_track(f)[:-1], str(_folder(t)), "--out", "TMP/tr"],
            "--map TMP/dir: a folder, not a file",
        ),
        case(
            "learn --yaws a folder: says it is a folder",
            lambda t, f: [*_learn(f), "--yaws", str(_folder(t)), "--map", "TMP/m.npz"],
            "--yaws TMP/dir: a folder, not a CSV file",
        ),
        case(
            "track --video a folder: no example of another command",
            lambda t, f: [*_track(f), "--out", "TMP/tr", "--video", str(_folder(t))],
            "--video TMP/dir is a folder; give a file name",
        ),
        case(
            "track --video '': names --video",
            lambda t, f: [*_track(f), "--out", "TMP/tr", "--video", ""],
            "--video: give a file name",
        ),
        case(
            "a map whose config says 32 colours but holds 10: names the file",
            _map_config_disagrees,
            "--map TMP/bad.npz: its config says 32 colour classes, but it holds 10",
        ),
        case(
            "learn --focal 1e-300: names --focal",
            lambda t, f: [
                "compass",
                "learn",
                str(f["turn"]),
                "--focal",
                "1e-300",
                "--map",
                "TMP/m",
            ],
            "--focal 1e-300: frames 96 pixels wide would see 180 degrees",
        ),
        case(
            "learn --hfov 1e-300: refused",
            lambda t, f: ["compass", "learn", str(f["turn"]), "--hfov", "1e-300", "--map", "TMP/m"],
            "must be in [1, 179] degrees",
        ),
    ]


# ----------------------------------------------------------------------- env limits
def _env_refuses(env_id: str, **kwargs: float) -> Callable[[Path], None]:
    def run(_: Path) -> None:
        raises(ValueError, "seconds", lambda: gym.make(env_id, **kwargs))

    return run


def footage_cases(main: Callable[[list[str]], int] | None = None) -> list[Case]:
    """Every case of the footage suite; the commands run through ``main``
    (:func:`vc_gym.cli.main`) in this process, or each in a process of its own without it.
    """
    suite = "footage"
    run = in_subprocess if main is None else in_process(main)
    refused = [  # (case, the command, what its one line of error says)
        (
            "track --video INPUT: refused, the video unchanged",
            _video_over_input,
            "--video TMP/other.mp4 is INPUT TMP/other.mp4",
        ),
        ("track --video a symbolic link to INPUT: refused", _video_link_to_input, "is INPUT"),
        ("track --video a hard link to INPUT: refused", _video_hard_link_to_input, "is INPUT"),
        (
            "track FRAMES --out FRAMES: refused, the footage folder unchanged",
            _out_is_the_frames,
            "--out TMP/frames is INPUT TMP/frames",
        ),
        (
            "track --yaws OUT/headings.csv: refused",
            _out_holds_the_yaws,
            "is --yaws TMP/tr/headings.csv",
        ),
        (
            "learn --width 16384 on 96x72 frames: refused before decoding",
            _width_past_the_limit,
            "--width 16384: frames of 96x72 pixels",
        ),
    ]
    flows = [  # (case, a run of several commands)
        ("track --out an earlier track: kept; --overwrite replaces", _existing_track_kept),
        ("learn --map an existing file: kept; --overwrite replaces", _existing_map_kept),
        ("a truncated JPEG: refused by name; --skip-bad-frames counts it", _truncated_jpeg),
        ("SIGTERM while tracking: exit 143, nothing half-written", _sigterm_while_tracking),
    ]
    return [
        *(Case(suite, name, _unchanged(run, make, match)) for name, make, match in refused),
        *(Case(suite, name, functools.partial(flow, run)) for name, flow in flows),
        *_message_cases(suite, run),
        *(
            Case(
                suite, f"{env_id} {arg}=1e12: refused at once", _env_refuses(env_id, **{arg: 1e12})
            )
            for env_id in ("vc_gym/LearnThenHome-v0", "vc_gym/Homing-v0")
            for arg in ("learn_time_s", "max_homing_s", "stop_time_s", "max_learning_s")
        ),
    ]
