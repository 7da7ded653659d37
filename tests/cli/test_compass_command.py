"""``vc-gym compass learn`` / ``track``: the compass on footage from the command line."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from vc_gym.cli import main
from vc_gym.compass import Camera, VisualCompass
from vc_gym.compass.footage import VideoSink
from vc_gym.experiments.real_data import default_real_data_dir
from vc_gym.worlds.panorama import render_view

HFOV = 60.0
#: The tracked views' true yaws (none on the learning grid).
TRUE_YAWS = np.random.default_rng(5).uniform(0.0, 360.0, 12)


def write_video(path: Path, pano, yaws) -> Path:
    with VideoSink(path, fps=10) as sink:
        for yaw in yaws:
            sink.write(render_view(pano, Camera(hfov_deg=HFOV, yaw_deg=yaw), 160, 120))
    return path


@pytest.fixture(scope="module")
def footage(room_pano, tmp_path_factory) -> dict[str, Path]:
    """turn.mp4 (36 views of a full turn to the left), other.mp4 and its true yaws."""
    d = tmp_path_factory.mktemp("compass_cli")
    truth = d / "truth.csv"
    truth.write_text("yaw_deg\n" + "".join(f"{y:.4f}\n" for y in TRUE_YAWS))
    return {
        "turn": write_video(d / "turn.mp4", room_pano, 10.0 * np.arange(36)),
        "other": write_video(d / "other.mp4", room_pano, TRUE_YAWS),
        "truth": truth,
    }


@pytest.fixture(scope="module")
def learned_map(footage, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("map") / "room.npz"
    assert main(["compass", "learn", str(footage["turn"]), "--hfov", "60", "--map", str(path)]) == 0
    return path


def test_learn_writes_a_map_of_every_frame(learned_map, footage, tmp_path, capsys):
    vc = VisualCompass.load(learned_map)
    assert vc.frames_learned == 36 and vc.learned_fraction == 1.0
    # --json: one JSON object as the last line; a map name without .npz gets it
    args = ["compass", "learn", str(footage["turn"]), "--hfov", "60", "--n-colors", "3"]
    assert main([*args, "--step", "2", "--map", str(tmp_path / "m"), "--json"]) == 0
    result = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert result["frames"] == 18 and result["map"] == str(tmp_path / "m.npz")
    assert VisualCompass.load(tmp_path / "m.npz").config.n_colors == 3


def test_track_writes_csv_plot_summary_and_video(learned_map, footage, tmp_path, capsys):
    out, video = tmp_path / "track", tmp_path / "annotated.mp4"
    argv = ["compass", "track", str(footage["other"]), "--hfov", "60", "--map", str(learned_map)]
    argv += ["--yaws", str(footage["truth"]), "--out", str(out), "--video", str(video)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "tracked 12 frames" in printed and "median |error|" in printed
    assert "within +-2 sigma" in printed
    with open(out / "headings.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == [
        "frame",
        "heading_deg",
        "spread_deg",
        "score",
        "has_evidence",
        "true_deg",
        "error_deg",
    ]
    assert [int(r["frame"]) for r in rows] == list(range(12))
    np.testing.assert_allclose([float(r["true_deg"]) for r in rows], TRUE_YAWS, atol=1e-3)
    errors = np.abs([float(r["error_deg"]) for r in rows])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["frames"] == 12
    assert summary["median_abs_error_deg"] == pytest.approx(np.median(errors), abs=2e-3)
    # measured: median 0.3 deg through the video's compression
    assert summary["median_abs_error_deg"] < 1.5
    # the map's spread is calibrated when learned (measured: temperature 2.0, 12 of 12
    # within 2σ at the 0.5° floor; the paper's spread, temperature 1 and no floor, holds
    # about a third of the truths)
    assert summary["within_2sigma"] >= 0.8 and summary["median_spread_deg"] < 5.0, summary
    assert cv2.imread(str(out / "headings.png")) is not None
    cap = cv2.VideoCapture(str(video))
    count = 0
    while cap.grab():
        count += 1
    cap.release()
    assert count == 12
    assert sorted(p.name for p in out.iterdir()) == ["headings.csv", "headings.png", "summary.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["annotated.mp4", "track"]


def test_track_without_truth_has_no_error_columns(learned_map, footage, tmp_path):
    out = tmp_path / "t"
    argv = ["compass", "track", str(footage["other"]), "--hfov", "60", "--map", str(learned_map)]
    assert main([*argv, "--out", str(out), "--max-frames", "4", "--json"]) == 0
    header = (out / "headings.csv").read_text().splitlines()[0]
    assert header == "frame,heading_deg,spread_deg,score,has_evidence"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["frames"] == 4 and "median_abs_error_deg" not in summary


def test_help_explains_with_examples(capsys):
    for action in ("learn", "track"):
        with pytest.raises(SystemExit) as e:
            main(["compass", action, "--help"])
        assert e.value.code == 0
        text = capsys.readouterr().out
        assert "examples:" in text and f"vc-gym compass {action} " in text
        assert "(default: " in text and "(default: None)" not in text
    with pytest.raises(SystemExit):
        main(["compass", "learn", "--help"])
    assert "counter-clockwise" in capsys.readouterr().out


# --------------------------------------------------------------------------- bad inputs
def _learn(tmp_path: Path, source: Path | str, *extra: str) -> int:
    return main(["compass", "learn", str(source), "--map", str(tmp_path / "out.npz"), *extra])


def _frames_folder(folder: Path, n: int = 4) -> Path:
    folder.mkdir()
    for k in range(n):
        cv2.imwrite(str(folder / f"f{k}.png"), np.full((40, 60, 3), 30 * k, np.uint8))
    return folder


@pytest.mark.parametrize(
    ("setup", "extra", "message"),
    [
        ("missing", ("--hfov", "60"), "no such file"),
        ("empty", ("--hfov", "60"), "holds no images"),
        ("corrupt", ("--hfov", "60"), "f2.png: not a PNG, JPEG or BMP"),
        ("short_csv", ("--hfov", "60"), "3 rows, but"),
        ("nan_csv", ("--hfov", "60"), "line 3: yaw 'nan' must be a finite"),
        ("text_csv", ("--hfov", "60"), "line 2: yaw 'east' is not a number"),
        ("frames", ("--hfov", "60", "--n-colors", "0"), "n_colors must be in 1..32"),
        ("frames", ("--hfov", "60", "--yaw-column", "yaw"), "--yaw-column needs --yaws"),
    ],
)
def test_bad_input_is_an_error_and_writes_nothing(tmp_path, capsys, setup, extra, message):
    source = tmp_path / "frames"
    if setup == "missing":
        source = tmp_path / "nothing.mp4"
    elif setup == "empty":
        source.mkdir()
    else:
        _frames_folder(source)
    if setup == "corrupt":
        (source / "f2.png").write_bytes(b"broken" * 20)
    csv_text = {"short_csv": "0\n90\n180\n", "nan_csv": "yaw\n0\nnan\n1\n2\n"}
    csv_text["text_csv"] = "yaw\neast\n1\n2\n3\n"
    if setup in csv_text:
        (tmp_path / "y.csv").write_text(csv_text[setup])
        extra = (*extra, "--yaws", str(tmp_path / "y.csv"))
    assert _learn(tmp_path, source, *extra) == 2
    err = capsys.readouterr().err
    assert err.startswith("vc-gym compass: error: ") and message in err, err
    assert not (tmp_path / "out.npz").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp files


@pytest.mark.parametrize("hfov", ["0", "180", "-10", "nan", "wide", "1e-300", "0.5", "179.5"])
def test_impossible_hfov_is_a_usage_error(tmp_path, capsys, hfov):
    folder = _frames_folder(tmp_path / "frames")
    with pytest.raises(SystemExit) as e:
        _learn(tmp_path, folder, "--hfov", hfov)
    assert e.value.code == 2
    assert "--hfov" in capsys.readouterr().err
    assert not (tmp_path / "out.npz").exists()


def test_a_camera_is_required(tmp_path, capsys):
    folder = _frames_folder(tmp_path / "frames")
    with pytest.raises(SystemExit) as e:
        _learn(tmp_path, folder)
    assert e.value.code == 2 and "--hfov" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        _learn(tmp_path, folder, "--hfov", "60", "--focal", "100")
    assert "not allowed with" in capsys.readouterr().err


def test_track_with_a_file_that_is_not_a_map(tmp_path, footage, capsys):
    fake = tmp_path / "fake.npz"
    fake.write_bytes(b"PK not a map")
    out = tmp_path / "out"
    argv = ["compass", "track", str(footage["other"]), "--hfov", "60", "--map", str(fake)]
    assert main([*argv, "--out", str(out)]) == 2
    assert "fake.npz" in capsys.readouterr().err
    assert not out.exists()


def test_track_refuses_a_video_name_it_cannot_write(tmp_path, learned_map, footage, capsys):
    out = tmp_path / "out"
    argv = ["compass", "track", str(footage["other"]), "--hfov", "60", "--map", str(learned_map)]
    assert main([*argv, "--out", str(out), "--video", str(tmp_path / "v.gif")]) == 2
    assert "suffixes .mp4" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_learn_takes_yaws_or_a_turn_not_both(tmp_path, footage, capsys):
    argv = [str(footage["turn"]), "--hfov", "60", "--yaws", str(footage["truth"]), "--turn", "-360"]
    assert _learn(tmp_path, *argv) == 2
    assert "give --yaws or --turn, not both" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_track_with_wrong_truth_writes_nothing(tmp_path, learned_map, footage, capsys):
    truth = tmp_path / "truth.csv"
    truth.write_text("yaw\n" + "1\n" * 5)
    out, video = tmp_path / "out", tmp_path / "v.mp4"
    argv = ["compass", "track", str(footage["other"]), "--hfov", "60", "--map", str(learned_map)]
    argv += ["--yaws", str(truth), "--out", str(out), "--video", str(video)]
    assert main(argv) == 2
    assert "5 rows, but" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["truth.csv"]


def test_a_failure_while_tracking_leaves_no_output(tmp_path, learned_map, capsys):
    # the header is whole, the image data cut: found only when the frame is decoded
    folder = _frames_folder(tmp_path / "frames", 6)
    data = (folder / "f4.png").read_bytes()
    (folder / "f4.png").write_bytes(data[: len(data) // 2])
    out, video = tmp_path / "out", tmp_path / "v.mp4"
    argv = ["compass", "track", str(folder), "--hfov", "60", "--map", str(learned_map)]
    assert main([*argv, "--out", str(out), "--video", str(video), "--json"]) == 2
    assert "f4.png: the PNG ends before its image does" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frames"]


# --------------------------------------------------------------------------- real photos
def test_real_rotation_set_from_the_command_line(tmp_path, capsys):
    root = default_real_data_dir()
    if root is None or not (root / "rotation_grail").is_dir():
        pytest.skip("the real photo sets are not here (set VC_GYM_REAL_DATA)")
    folder = root / "rotation_grail"
    truth = str(folder / "yaw_ground_truth.csv")
    common = [str(folder), "--focal", "628", "--yaws", truth, "--step", "2", "--json"]
    assert main(["compass", "learn", *common, "--map", str(tmp_path / "grail.npz")]) == 0
    capsys.readouterr()
    track = ["compass", "track", *common, "--start", "1", "--map", str(tmp_path / "grail.npz")]
    assert main([*track, "--out", str(tmp_path / "t")]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["frames"] == 9
    # measured: median 0.48 deg
    assert summary["median_abs_error_deg"] < 2.0
