"""``vc-gym render``: pictures of the simulated scenes."""

from __future__ import annotations

import argparse

from vc_gym.cli.arguments import SceneChoices
from vc_gym.validation import check_seed

__all__ = ["add_parser", "run"]


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add ``render`` to the ``vc-gym`` commands."""
    p = commands.add_parser(
        "render",
        help="pictures of the simulated scenes (top view and a 360 deg strip of head views)",
        description=(
            "Write DIR/<scene>_top.png (top view with the robot, its heading and its camera's "
            "field of view) and DIR/<scene>_strip.png (8 head-camera frames, 45 deg apart, "
            "from the centre of the field) for one or every scene."
        ),
    )
    p.add_argument(
        "--scene",
        default="all",
        choices=SceneChoices("all"),
        metavar="SCENE",
        help="which scene (default: all, every registered scene): %(choices)s",
    )
    p.add_argument("--out", default="vc_gym_scenes", metavar="DIR", help="output folder")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--randomize", action="store_true", help="domain-randomised scene")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from vc_gym.experiments.render_scenes import render_scene_pictures
    from vc_gym.jobs.output import check_out_dir
    from vc_gym.sim.scenes import scene_names

    check_seed("--seed", args.seed)
    check_out_dir(args.out)
    scenes = scene_names() if args.scene == "all" else (args.scene,)
    for path in render_scene_pictures(args.out, scenes, seed=args.seed, randomize=args.randomize):
        print(f"wrote {path}")
    return 0
