"""``vc-gym compass learn/track`` driven by hypothesis over flags and paths: every outcome
is a success or a one-line error with exit status 2, no input file changes, an existing
output changes only with ``--overwrite``, and nothing but the outputs appears."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from vc_gym.cli import main
from vc_gym.cli.compass import TRACK_FILES
from vc_gym.experiments.check_footage import footage_fixture, in_process

run_command = in_process(main)

#: Paths the commands may be given ("TMP" is the example's own folder).
INPUTS = ["TMP/turn.mp4", "TMP/other.mp4", "TMP/frames", "TMP/missing.mp4", "TMP/yaws.csv",
          "TMP/room.npz", "TMP"]  # fmt: skip
LEARN_MAPS = ["TMP/new.npz", "TMP/new", "TMP/room.npz", "", "TMP/frames", "/dev/null",
              "TMP/turn.mp4", "TMP/yaws.csv", "TMP/a/b/m.npz", "TMP/frames/m.npz"]  # fmt: skip
TRACK_MAPS = ["TMP/room.npz", "TMP/missing.npz", "TMP/frames", "TMP/yaws.csv", "TMP/turn.mp4", ""]
YAWS = [
    None,
    "TMP/yaws.csv",
    "TMP/frames",
    "TMP/room.npz",
    "TMP/missing.csv",
    "TMP/tr/headings.csv",
]
OUTS = ["TMP/tr", "TMP/frames", "TMP", "TMP/yaws.csv", "", "TMP/a/b"]
VIDEOS = [None, "TMP/v.mp4", "TMP/other.mp4", "TMP/turn.mp4", "TMP/frames", "TMP/v.gif", "",
          "TMP/tr/v.mp4", "TMP/frames/v.mp4", "TMP/yaws.csv"]  # fmt: skip
HFOVS = ["60", "1e-300", "0", "179", "nan", "-5", "1e308"]
FOCALS = ["80", "1e-300", "1e300", "0", "-1"]


@pytest.fixture(scope="module")
def template(tmp_path_factory) -> Path:
    """The footage every example starts from (copied, so that no example sees another's)."""
    root = tmp_path_factory.mktemp("fuzz_template")
    footage_fixture(root, run_command)
    (root / "tr").mkdir()  # an earlier track, to be kept
    for name in TRACK_FILES:
        (root / "tr" / name).write_text("earlier run\n")
    return root


def _digest(root: Path) -> dict[str, str]:
    return {
        str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def _pick(draw, values: list, good: int = 1):
    """One of ``values``: one of the first ``good`` (sensible ones) 7 times in 10, else
    any (so that most commands get far enough to do work, and every mistake is tried)."""
    if draw(st.integers(0, 9)) < 7:
        return draw(st.sampled_from(values[:good]))
    return draw(st.sampled_from(values))


@st.composite
def commands(draw) -> tuple[list[str], list[str]]:
    """``(argv, outputs)``: a command line and the files it may write ("TMP" paths)."""
    learn = draw(st.booleans())
    source = _pick(draw, INPUTS, good=2 if learn else 3)
    argv = ["compass", "learn" if learn else "track", source]
    if draw(st.integers(0, 3)):
        argv += ["--hfov", _pick(draw, HFOVS)]
    else:
        argv += ["--focal", _pick(draw, FOCALS)]
    outputs: list[str] = []
    if learn:
        path = _pick(draw, LEARN_MAPS, good=2)
        argv += ["--map", path]
        outputs += [path, path + ".npz"]
        if draw(st.booleans()):
            argv += ["--n-colors", _pick(draw, ["3", "0", "33"])]
    else:
        out = _pick(draw, OUTS)
        argv += ["--map", _pick(draw, TRACK_MAPS), "--out", out]
        outputs += [f"{out}/{name}" for name in TRACK_FILES]
        video = _pick(draw, VIDEOS, good=2)
        if video is not None:
            argv += ["--video", video]
            outputs.append(video)
    yaws = _pick(draw, YAWS)
    if yaws is not None:
        argv += ["--yaws", yaws]
    for flag, values in (
        ("--width", ["64", "16", "15", "16384"]),
        ("--start", ["0", "3", "1000", "-1"]),
        ("--step", ["1", "5", "0"]),
        ("--max-frames", ["4", "1", "0"]),
    ):
        if draw(st.booleans()):
            argv += [flag, _pick(draw, values, good=2)]
    for switch in ("--overwrite", "--skip-bad-frames"):
        if draw(st.booleans()):
            argv.append(switch)
    return argv, outputs


@settings(
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(command=commands())
def test_every_outcome_is_a_success_or_one_line_and_no_input_changes(
    command, template, tmp_path_factory
):
    argv, outputs = command
    root = tmp_path_factory.mktemp("fuzz") / "t"
    shutil.copytree(template, root)
    argv = [a.replace("TMP", str(root)) for a in argv]
    allowed = {str(Path(o.replace("TMP", str(root))).resolve()) for o in outputs if o}
    before = _digest(root)
    code, _, err = run_command(argv)
    event(f"exit {code}")
    assert code in (0, 2), f"exit {code}: {err[-500:]}"
    assert "Traceback" not in err, err[-800:]
    if code == 2:
        last = err.rstrip("\n").split("\n")[-1]
        assert last.startswith("vc-gym compass") and ": error: " in last, err[-500:]
        assert err.count("\n") == 1 or err.startswith("usage:"), err[-500:]
    after = _digest(root)
    for name, digest in after.items():
        assert not Path(name).name.startswith("."), f"left a temporary file {name}"
        if str((root / name).resolve()) in allowed:
            if name in before and "--overwrite" not in argv:
                assert digest == before[name], f"replaced {name} without --overwrite"
        else:
            assert before.get(name) == digest, f"{name} changed or appeared"
    assert set(before) <= set(after), f"removed {sorted(set(before) - set(after))}"
    assert not Path("/dev/null.npz").exists()
