"""``vc-gym evaluate``: the homing experiment without its likelihood field."""

from __future__ import annotations

import argparse

from vc_gym.cli import experiment as experiment_command
from vc_gym.cli.arguments import add_allow_imports_option, add_json_option, add_tracker_option
from vc_gym.experiments.options import HOMING_MODE_CHOICES, HOMING_MODE_HELP
from vc_gym.experiments.studies import EXPERIMENTS

__all__ = ["add_parser", "run"]


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add ``evaluate`` to the ``vc-gym`` commands."""
    p = commands.add_parser(
        "evaluate",
        help="repeat the homing experiment: stop positions over many kidnappings",
        description=(
            "The paper's homing experiment on vc_gym/LearnThenHome-v0 in the robolab: the "
            "robot learns the place once (scripted learning, seed SEED), then is kidnapped "
            "EPISODES times (seeds SEED+1, ...) and walks home with the scripted agent or a "
            "trained one (--agent DIR/model.zip from vc-gym train); it must stand still 5 s "
            "to stop. Reports the stop positions: mean and standard deviation per axis "
            "(paper: (-22, +12) cm and (17, 15) cm), mean distance and success rate. It is "
            "'vc-gym experiment homing' without the likelihood field: writes "
            "DIR/results.json, DIR/run.json and DIR/stop_positions.png, and resumes an "
            "interrupted run in the same DIR."
        ),
    )
    p.add_argument(
        "--agent",
        default="scripted",
        metavar="scripted|pretrained|DIR/model.zip",
        help="the scripted homing agent, the shipped PPO policy, or a model from vc-gym train",
    )
    add_allow_imports_option(p, "the agent's config.json")
    p.add_argument(
        "--relearn",
        choices=["scene", "episode"],
        default="scene",
        help="learn once (paper) or before every kidnapping",
    )
    p.add_argument("--episodes", type=int, default=33, help="kidnappings (paper: 33)")
    p.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the learning phase; kidnapping i uses seed + 1 + i",
    )
    p.add_argument(
        "--learn-time", type=float, default=5.0, metavar="S", help="seconds per direction"
    )
    p.add_argument(
        "--max-homing",
        type=float,
        default=60.0,
        metavar="S",
        help="homing seconds before an episode ends as timed out",
    )
    p.add_argument("--workers", type=int, default=2, help="parallel processes (1: in this process)")
    p.add_argument(
        "--mode",
        choices=HOMING_MODE_CHOICES,
        help="how the place is learned and the scripted agent homes (default: check-home; "
        "paper for a learned agent, whose training places were learned the paper's way): "
        + HOMING_MODE_HELP,
    )
    add_tracker_option(p)
    p.add_argument(
        "--out", default="vc_gym_homing", metavar="DIR", help="output folder (resumable)"
    )
    add_json_option(p)
    p.set_defaults(func=run, hint=experiment_command.resume_hint)


def run(args: argparse.Namespace) -> int:
    """Run the homing experiment with the evaluation's options."""
    options = {
        "agent": args.agent,
        "tracker": args.tracker,
        "relearn": args.relearn,
        "episodes": args.episodes,
        "learn_time_s": args.learn_time,
        "max_homing_s": args.max_homing,
        "field": False,
    }
    if args.mode is not None:
        options["mode"] = args.mode
    if args.allow_imports:
        options["allow_imports"] = True
    return experiment_command.run_experiment(
        EXPERIMENTS["homing"],
        options,
        command=args.command,
        out=args.out,
        seed=args.seed,
        workers=args.workers,
        json_output=args.json,
    )
