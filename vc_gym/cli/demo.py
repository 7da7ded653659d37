"""``vc-gym demo``: one learn-then-home episode, its summary and its picture."""

from __future__ import annotations

import argparse
from pathlib import Path

from vc_gym.cli.arguments import add_tracker_option
from vc_gym.experiments.options import HOMING_MODE_CHOICES, HOMING_MODE_HELP

__all__ = ["add_parser", "run"]


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add ``demo`` to the ``vc-gym`` commands."""
    p = commands.add_parser(
        "demo",
        help="the main job: learn a place, get kidnapped, walk home (summary.json, demo.png)",
        description=(
            "One learn-then-home episode in the simulated robot lab with the scripted agents "
            "(paper 4.3, 5.2): learn the panorama at 4 spots 1 m around home (8 x 45 deg, "
            "head scanning), normalise at home, get kidnapped to a random pose, walk home "
            "with a tracker (default: the paper's orientational and translational filters). "
            "It is the first kidnapping of 'vc-gym evaluate' with the same --seed. Writes "
            "DIR/summary.json (home error, heading error, success, duration) and DIR/demo.png."
        ),
    )
    p.add_argument("--out", default="vc_gym_demo", metavar="DIR", help="output folder")
    p.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the learning phase; the kidnapping uses seed + 1 (as in evaluate)",
    )
    p.add_argument(
        "--learn-time",
        type=float,
        default=5.0,
        metavar="S",
        help="seconds per learning direction (paper: 5)",
    )
    p.add_argument(
        "--mode",
        choices=HOMING_MODE_CHOICES,
        default="check-home",
        help=HOMING_MODE_HELP,
    )
    add_tracker_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the demo and print its result."""
    from vc_gym.experiments.demo import check_demo_args, run_demo

    # every argument, named by its flag, before the folder is made
    check_demo_args(
        args.seed,
        args.learn_time,
        tracker=args.tracker,
        mode=args.mode,
        names={"seed": "--seed", "learn_time_s": "--learn-time", "mode": "--mode"},
    )
    s = run_demo(
        args.out,
        seed=args.seed,
        learn_time_s=args.learn_time,
        tracker=args.tracker,
        mode=args.mode,
    )
    dx, dy = (100 * v for v in s["stop_offset_m"])
    how = "stopped" if s["stopped"] else f"did not stop (timed out after {s['sim_time_s']:.0f} s),"
    print(
        f"{how} {s['home_error_m'] * 100:.1f} cm from home "
        f"(offset x {dx:+.1f} cm, y {dy:+.1f} cm), "
        f"final heading error {s['final_heading_error_deg']:.1f} deg, "
        f"success: {s['success']}, {s['duration_s']:.0f} s"
    )
    print(f"wrote {Path(args.out) / 'summary.json'} and {Path(args.out) / 'demo.png'}")
    return 0
