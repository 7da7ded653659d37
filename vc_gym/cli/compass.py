"""``vc-gym compass``: the compass on your own footage, with no Python.

``vc-gym compass learn`` learns a map from a video (or a folder of frames) of a camera
turning in place; ``vc-gym compass track`` estimates the heading of every frame of
another video with that map and writes a CSV, a plot, a summary and, on request, the
video with the estimate drawn on it. The work is done by :mod:`vc_gym.compass.footage`.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable, Iterable
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from vc_gym.cli.arguments import add_json_option, argument_type
from vc_gym.compass.camera import MAX_HFOV_DEG, MIN_HFOV_DEG
from vc_gym.compass.config import EXPOSURE_MODES, CompassConfig

if TYPE_CHECKING:  # imported when the command runs: `vc-gym --help` stays light
    import numpy as np

    from vc_gym.compass import Camera, CompassEstimate, VisualCompass
    from vc_gym.compass.footage import Footage, FootageTrack, Progress, YawTable

__all__ = ["TRACK_FILES", "add_parser", "run_learn", "run_track"]

T = TypeVar("T")

#: The folder ``vc-gym compass track`` writes to by default.
DEFAULT_OUT = "vc_gym_track"
#: Frames per second of ``--video`` when the tracked input does not say (a folder).
DEFAULT_VIDEO_FPS = 10.0

_DEFAULTS = {f.name: f.default for f in fields(CompassConfig)}

_LEARN_EXAMPLES = """\
examples:
  # a phone video of a full turn to the left, 66 deg wide, at a constant rate
  vc-gym compass learn turn.mp4 --hfov 66 --map room.npz
  # every 2nd photo of a folder, yaws from a CSV matched by file name
  vc-gym compass learn photos/ --focal 628 --step 2 --yaws yaws.csv --map room.npz

yaws: degrees, counter-clockwise positive seen from above (turning left increases
the yaw). Without --yaws the camera is taken to turn --turn degrees at a constant rate
over the whole input: frame k of N is at TURN * k / N, the first at 0.
"""

_TRACK_EXAMPLES = """\
examples:
  vc-gym compass track other.mp4 --hfov 66 --map room.npz --out track/
  # with the true yaws, to measure the errors, and the annotated video
  vc-gym compass track photos/ --focal 628 --start 1 --step 2 --map room.npz \\
      --yaws yaws.csv --out track/ --video track/headings.mp4

writes DIR/headings.csv (frame, heading_deg, spread_deg, score, has_evidence, and
true_deg, error_deg with --yaws), DIR/headings.png (heading, and truth, against the
frame with a +-2 sigma band) and DIR/summary.json (the figures printed at the end).
"""

_YAW_CSV_HELP = (
    "degrees, one row per frame of the input (header optional; a file-name column "
    "such as 'image' matches a folder's frames by name)"
)


def _hfov(text: str) -> float:
    v = float(text)
    if not (math.isfinite(v) and MIN_HFOV_DEG <= v <= MAX_HFOV_DEG):
        raise ValueError(
            f"the horizontal field of view must be in [{MIN_HFOV_DEG:g}, {MAX_HFOV_DEG:g}] "
            f"degrees, got {text}"
        )
    return v


def _positive(text: str) -> float:
    v = float(text)
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"must be a finite number > 0, got {text}")
    return v


def _finite(text: str) -> float:
    v = float(text)
    if not math.isfinite(v):
        raise ValueError(f"must be a finite number, got {text}")
    return v


def _count(minimum: int) -> Callable[[str], int]:
    def parse(text: str) -> int:
        v = int(text)
        if v < minimum:
            raise ValueError(f"must be an integer >= {minimum}, got {text}")
        return v

    return parse


def _add_footage_options(p: argparse.ArgumentParser, what: str, yaws_help: str) -> None:
    """INPUT, the camera, the frame selection and the yaw CSV."""
    p.add_argument("input", metavar="INPUT", help=f"{what}: a video file or a folder of images")
    cam = p.add_mutually_exclusive_group(required=True)
    cam.add_argument(
        "--hfov",
        type=argument_type(_hfov, "hfov"),
        metavar="DEG",
        help="the camera's horizontal field of view in degrees (one of --hfov, --focal)",
    )
    cam.add_argument(
        "--focal",
        type=argument_type(_positive, "focal"),
        metavar="PX",
        help="the camera's focal length in pixels of the frames as stored (the frame "
        "width then gives the field of view: 2 atan(W / 2f))",
    )
    p.add_argument(
        "--pitch",
        type=argument_type(_finite, "pitch"),
        default=0.0,
        metavar="DEG",
        help="how far the camera looks up (negative: down)",
    )
    p.add_argument("--yaws", metavar="CSV", help=yaws_help + "; " + _YAW_CSV_HELP)
    p.add_argument(
        "--yaw-column",
        metavar="NAME|INDEX",
        help="the CSV column holding the yaw (default: the first whose header contains "
        "'yaw', or the only numeric one)",
    )
    p.add_argument(
        "--start",
        type=argument_type(_count(0), "start"),
        default=0,
        metavar="N",
        help="first frame used (0-based)",
    )
    p.add_argument(
        "--step",
        type=argument_type(_count(1), "step"),
        default=1,
        metavar="N",
        help="use every N-th frame",
    )
    p.add_argument(
        "--max-frames",
        type=argument_type(_count(1), "max-frames"),
        metavar="N",
        help="use at most N frames (default: all)",
    )
    p.add_argument(
        "--width",
        type=argument_type(_count(16), "width"),
        metavar="PX",
        help="scale frames to this width first (faster; the field of view is kept; "
        "default: as stored); the scaled frames must stay within 50 megapixels",
    )
    p.add_argument(
        "--skip-bad-frames",
        action="store_true",
        help="leave out frames that cannot be read (a truncated or corrupt image, a video "
        "frame that does not decode) and count them, instead of stopping with an error",
    )
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="replace output files that exist (without it an existing output is an error "
        "and is kept)",
    )


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add ``compass`` (``learn``, ``track``) to the ``vc-gym`` commands."""
    p = commands.add_parser(
        "compass",
        help="the compass on your own camera: learn a map from a video, track another",
        description=(
            "The visual compass on your own footage. 'learn' builds a map from a video "
            "(or a folder of frames) of a camera turning in place at one spot; 'track' "
            "estimates the heading of every frame of another video of that place. Run "
            "'vc-gym compass learn --help' and 'vc-gym compass track --help' for the options."
        ),
    )
    actions = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    learn = actions.add_parser(
        "learn",
        help="learn a map from a video or folder of a camera turning in place",
        description=(
            "Learn a compass map from a video file or a folder of images of a camera\n"
            "turning in place (level, at one spot, the views overlapping). The colour\n"
            "classes are fitted on up to 16 frames spread over the footage, then every\n"
            "frame is added to the map at its yaw. Writes the map (.npz) for 'track'."
        ),
        epilog=_LEARN_EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_footage_options(
        learn, "the learning footage", "the yaw of each frame (default: see --turn)"
    )
    learn.add_argument("--map", required=True, metavar="OUT.npz", help="the map file to write")
    learn.add_argument(
        "--turn",
        type=argument_type(_finite, "turn"),
        metavar="DEG",
        help="without --yaws: the angle turned over the whole input, at a constant rate "
        "(positive: to the left; -360: a full turn to the right) (default: 360)",
    )
    learn.add_argument(
        "--n-colors",
        type=int,
        default=_DEFAULTS["n_colors"],
        metavar="C",
        help="colour classes (paper: 10; 3 suffice and are steadier on real photos)",
    )
    learn.add_argument(
        "--sector-deg",
        type=float,
        default=_DEFAULTS["sector_deg"],
        metavar="DEG",
        help="sector width (must divide 360)",
    )
    learn.add_argument(
        "--coverage",
        type=float,
        default=_DEFAULTS["coverage"],
        metavar="SHARE",
        help="share of the pixels scanned",
    )
    learn.add_argument(
        "--exposure",
        choices=EXPOSURE_MODES,
        default=_DEFAULTS["exposure"],
        help="exposure correction (none: the paper's; mean, map, session: see CompassConfig)",
    )
    learn.add_argument(
        "--seed",
        type=argument_type(_count(0), "seed"),
        default=0,
        metavar="N",
        help="seed of the colour fit",
    )
    add_json_option(learn, "print one JSON object as the last line (and no progress bar)")
    learn.set_defaults(func=run_learn)

    track = actions.add_parser(
        "track",
        help="estimate the heading of every frame of a video with a learned map",
        description=(
            "Estimate the heading of every frame of a video file or a folder of images,\n"
            "each frame on its own, with a map from 'vc-gym compass learn'. With --yaws\n"
            "(the true yaws, measured from the same 0 as the learning footage's) it also\n"
            "measures the errors: the median absolute error, and the share of frames\n"
            "whose true yaw lies within +-2 sigma of the estimate (sigma: the reported\n"
            "spread; a calibrated compass has about 95 %)."
        ),
        epilog=_TRACK_EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_footage_options(
        track, "the footage to track", "the true yaw of each frame, to measure the errors"
    )
    track.add_argument("--map", required=True, metavar="MAP.npz", help="a map from 'learn'")
    track.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", help="output folder")
    track.add_argument(
        "--video",
        metavar="OUT.mp4",
        help="also write the frames with the estimate drawn on them (mp4v codec; "
        ".mp4, .avi, .mov or .m4v)",
    )
    add_json_option(track, "print one JSON object as the last line (and no progress bar)")
    track.set_defaults(func=run_track)


# --------------------------------------------------------------------------- shared
def _progress(args: argparse.Namespace, desc: str) -> Progress | None:
    if args.json:
        return None
    from tqdm import tqdm

    def wrap(items: Iterable[Any], total: int) -> Iterable[Any]:
        return tqdm(items, total=total, desc=desc, unit="frame")

    return wrap


#: Names of the footage functions' arguments as this command's flags (for errors).
_FLAGS = {
    "hfov_deg": "--hfov",
    "focal_px": "--focal",
    "pitch_deg": "--pitch",
    "start": "--start",
    "step": "--step",
    "max_frames": "--max-frames",
    "width": "--width",
    "skip_bad_frames": "--skip-bad-frames",
}


def _named(flag: str, load: Callable[[], T]) -> T:
    """``load()``, its errors starting with ``flag`` (the option that named the file)."""
    try:
        return load()
    except FileNotFoundError as exc:
        raise FileNotFoundError(f"{flag} {exc}") from None
    except ValueError as exc:
        raise ValueError(f"{flag} {exc}") from None


def _footage_and_camera(args: argparse.Namespace) -> tuple[Footage, Camera]:
    from vc_gym.compass.footage import Footage, footage_camera

    footage = Footage(
        args.input,
        start=args.start,
        step=args.step,
        max_frames=args.max_frames,
        width=args.width,
        skip_bad_frames=args.skip_bad_frames,
        names=_FLAGS,
    )
    camera = footage_camera(footage, args.hfov, args.focal, args.pitch, names=_FLAGS)
    return footage, camera


def _yaw_table(args: argparse.Namespace) -> YawTable | None:
    from vc_gym.compass.footage import read_yaw_csv

    if args.yaws is None:
        if args.yaw_column is not None:
            raise ValueError("--yaw-column needs --yaws CSV")
        return None
    return _named("--yaws", lambda: read_yaw_csv(args.yaws, args.yaw_column))


def _is_frame_name(path: Path) -> bool:
    """Whether a footage folder would read a file of this name as a frame."""
    from vc_gym.compass.footage import IMAGE_SUFFIXES

    return path.suffix.lower() in IMAGE_SUFFIXES and not path.name.startswith(".")


def _inputs(args: argparse.Namespace, *more: tuple[str, str | None]) -> list[tuple[str, Any]]:
    """The files and folders a footage command reads, with the options that named them."""
    return [("INPUT", args.input), ("--yaws", args.yaws), *more]


def _map_path(text: str) -> Path:
    """``learn``'s ``--map``: the file to write (``.npz`` added when missing, as numpy
    does), refused at once when empty or naming a folder or a device."""
    from vc_gym.jobs.output import check_new_files

    if text == "":
        raise ValueError("--map: give a file name (e.g. room.npz)")
    path = Path(text)
    check_new_files([("--map", path)], overwrite=True)  # a folder or device as typed
    return path if path.suffix == ".npz" else path.with_name(path.name + ".npz")


def _skipped_note(footage: Footage) -> str | None:
    """The line saying which frames ``--skip-bad-frames`` left out, if any."""
    skipped = footage.skipped
    if not skipped:
        return None
    first = next(iter(skipped.values()))
    return f"note: skipped {len(skipped)} frames that could not be read (first: {first})"


# --------------------------------------------------------------------------- learn
def run_learn(args: argparse.Namespace) -> int:
    """``vc-gym compass learn``: learn and save a map."""
    import numpy as np

    from vc_gym.compass.footage import calibrate_footage, footage_yaws, learn_footage
    from vc_gym.jobs.output import check_apart, check_new_files, check_out_file, removed_on_failure

    # outputs first: a refused name costs nothing, and nothing an input holds is replaced
    map_path = _map_path(args.map)
    check_apart([("--map", map_path)], _inputs(args), reads=_is_frame_name)
    check_new_files([("--map", map_path)], args.overwrite)
    config = CompassConfig(
        n_colors=args.n_colors,
        sector_deg=args.sector_deg,
        coverage=args.coverage,
        exposure=args.exposure,
    )
    footage, camera = _footage_and_camera(args)
    table = _yaw_table(args)
    if table is not None and args.turn is not None:
        raise ValueError("give --yaws or --turn, not both")
    turn = 360.0 if args.turn is None else args.turn
    yaws = footage_yaws(footage, table, turn)
    with removed_on_failure(map_path.parent):
        check_out_file(map_path, "--map")
        vc = learn_footage(
            footage,
            camera,
            yaws,
            config,
            rng=np.random.default_rng(args.seed),
            progress=_progress(args, "learn"),
        )
        calibration = calibrate_footage(vc, footage, camera, yaws)
        written = vc.save(map_path)
    source = f"from {args.yaws}" if table is not None else f"{turn:g} deg at a constant rate"
    learned = len(footage) - len(footage.skipped)
    result = {
        "map": str(written),
        "frames": learned,
        "skipped_frames": len(footage.skipped),
        "hfov_deg": camera.hfov_deg,
        "yaws": source,
        "learned_fraction": vc.learned_fraction,
        "spread_temperature": vc.spread_temperature,
        "calibration_frames": calibration.frames if calibration else 0,
    }
    print(
        f"learned {learned} frames of {footage.path} (hfov {camera.hfov_deg:.1f} deg, "
        f"yaws {source}); they cover {vc.learned_fraction:.0%} of the circle"
    )
    note = _skipped_note(footage)
    if note:
        print(note)
    if vc.learned_fraction < 1.0:
        print(
            "note: part of the circle was never in view; frames looking there cannot be "
            "placed (film a full turn with overlapping views)"
        )
    if calibration is None:
        print(
            "note: too few learning frames overlap to calibrate the spread on them; the map "
            "keeps the paper's spread (too small: calibrate it in Python with "
            "VisualCompass.calibrate on frames of known yaw)"
        )
    else:
        print(
            f"spread calibrated on {calibration.frames} learning frames: temperature "
            f"{calibration.temperature:.3g}, truth within 2 sigma "
            f"{calibration.within_2sigma:.0%} of them"
        )
    print(f"wrote {written}")
    if args.json:
        print(json.dumps(result))
    return 0


# --------------------------------------------------------------------------- track
#: The files ``track`` writes in its ``--out`` folder.
TRACK_FILES = ("headings.csv", "headings.png", "summary.json")


def run_track(args: argparse.Namespace) -> int:
    """``vc-gym compass track``: estimate every frame, write CSV, plot and summary."""
    from vc_gym.compass import VisualCompass
    from vc_gym.compass.footage import (
        VideoSink,
        footage_yaws,
        track_footage,
        write_track_csv,
    )
    from vc_gym.jobs.output import (
        check_apart,
        check_new_files,
        check_out_file,
        new_out_dir,
        removed_on_failure,
        write_json,
    )

    # outputs first: a refused name costs nothing, and nothing an input holds is replaced
    if args.out == "":
        raise ValueError("--out: give a folder name")
    if args.video == "":
        raise ValueError("--video: give a file name (e.g. track.mp4)")
    out = Path(args.out)
    files = [("--out", out / name) for name in TRACK_FILES]
    video = None if args.video is None else Path(args.video)
    written_files = [*files, *([("--video", video)] if video else [])]
    outputs = [("--out", out), *written_files]
    check_apart(outputs, _inputs(args, ("--map", args.map)), reads=_is_frame_name)
    check_new_files(written_files, args.overwrite)
    if video is not None:  # an unknown suffix is refused before the work starts
        _named("--video", lambda: VideoSink(video))
    compass = _named("--map", lambda: VisualCompass.load(args.map))
    footage, camera = _footage_and_camera(args)
    table = _yaw_table(args)
    truth = footage_yaws(footage, table) if table is not None else None
    with removed_on_failure(*([video.parent] if video else [])), new_out_dir(out):
        if video is not None:
            check_out_file(video, "--video")
        progress = _progress(args, "track")
        if video is None:
            track = track_footage(compass, footage, camera, truth, progress=progress)
        else:
            fps = footage.fps / footage.step if footage.fps else DEFAULT_VIDEO_FPS
            track = _track_with_video(compass, footage, camera, truth, progress, video, fps)
        summary = {
            "input": str(footage.path),
            "map": str(args.map),
            "hfov_deg": camera.hfov_deg,
            "start": footage.start,
            "step": footage.step,
            **track.summary(),
        }
        write_track_csv(out / "headings.csv", track)
        _plot(track, out / "headings.png")
        write_json(out / "summary.json", summary)
    print(_summary_line(summary))
    note = _skipped_note(footage)
    if note:
        print(note)
    written = [path for _, path in files]
    if video is not None:
        written.append(video)
    print("wrote " + ", ".join(map(str, written)))
    if args.json:
        print(json.dumps(summary))
    return 0


def _track_with_video(
    compass: VisualCompass,
    footage: Footage,
    camera: Camera,
    truth: np.ndarray | None,
    progress: Progress | None,
    video: Path,
    fps: float,
) -> FootageTrack:
    """:func:`track_footage` writing each annotated frame to ``video`` (atomically)."""
    from vc_gym.compass.footage import VideoSink, draw_estimate, track_footage
    from vc_gym.persistence import write_atomic

    true_at = (
        {} if truth is None else dict(zip(footage.indices.tolist(), truth.tolist(), strict=True))
    )
    result: list[FootageTrack] = []

    def write(tmp: str) -> None:
        # write_atomic's temporary name keeps the suffix, which picks the container
        with VideoSink(tmp, fps) as sink:

            def draw(index: int, frame: np.ndarray, est: CompassEstimate) -> None:
                sink.write(draw_estimate(frame, est, true_at.get(index)))

            result.append(
                track_footage(compass, footage, camera, truth, progress=progress, on_frame=draw)
            )

    write_atomic(video, write)
    return result[0]


def _summary_line(summary: dict[str, Any]) -> str:
    """The figures printed at the end of ``track``."""
    text = f"tracked {summary['frames']} frames ({summary['frames_with_evidence']} with evidence)"
    if summary["median_spread_deg"] is not None:
        text += f"; median spread {summary['median_spread_deg']:.2g} deg"
    if summary.get("median_abs_error_deg") is not None:
        text += (
            f"; median |error| {summary['median_abs_error_deg']:.2f} deg, "
            f"within 5 deg {summary['within_5deg']:.0%}, "
            f"true yaw within +-2 sigma {summary['within_2sigma']:.0%}"
        )
    return text


def _plot(track: FootageTrack, path: Path) -> None:
    """``headings.png``: the heading (and truth) against the frame with a +-2 sigma
    band; with the truth also the error against the frame inside its +-2 sigma band."""
    import numpy as np
    from matplotlib.ticker import MaxNLocator

    from vc_gym.angles import wrap360
    from vc_gym.jobs.output import new_figure, save_figure

    err = track.error_deg
    fig = new_figure(figsize=(10.0, 6.5 if err is not None else 4.0))
    axes = fig.subplots(2 if err is not None else 1, 1, sharex=True, squeeze=False)[:, 0]
    ev = track.has_evidence
    x = track.indices
    band = np.minimum(2.0 * track.spread_deg, 180.0)
    ax = axes[0]
    if track.true_deg is not None:
        # markers, not a line: the truth wraps from 360 to 0 where the camera passes 0
        ax.plot(
            x, wrap360(track.true_deg), "s", ms=5, mfc="none", color="tab:green", label="true yaw"
        )
    ax.errorbar(
        x[ev],
        track.heading_deg[ev],
        yerr=band[ev],
        fmt="o",
        ms=3,
        color="tab:blue",
        ecolor="tab:blue",
        elinewidth=0.8,
        alpha=0.8,
        label="estimate ± 2σ",
    )
    if np.any(~ev):
        ax.plot(x[~ev], np.zeros(int((~ev).sum())), "x", color="grey", label="no evidence")
    ax.set_ylim(0, 360)
    ax.set_yticks(range(0, 361, 90))
    ax.set_ylabel("heading (deg)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)  # outside: no dot hidden
    summary = track.summary()
    title = f"{summary['frames']} frames"
    if err is not None and summary["median_abs_error_deg"] is not None:
        title += (
            f": median |error| {summary['median_abs_error_deg']:.2f}°, true yaw within ±2σ "
            f"in {summary['within_2sigma']:.0%} of frames"
        )
        bx = axes[1]
        bx.fill_between(x, -band, band, color="tab:blue", alpha=0.2, step="mid", label="±2σ")
        bx.plot(x[ev], err[ev], "o", ms=3, color="tab:red", label="error")
        bx.axhline(0.0, color="black", lw=0.6)
        bx.set_ylabel("error (deg)")
        lim = float(np.max(np.abs(err[ev]))) if np.any(ev) else 1.0
        bx.set_ylim(-max(5.0, 1.2 * lim), max(5.0, 1.2 * lim))
        bx.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    axes[-1].set_xlabel("frame")
    axes[-1].xaxis.set_major_locator(MaxNLocator(integer=True))
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)
