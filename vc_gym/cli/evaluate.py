"""``vc-gym evaluate``: the homing experiment without its likelihood field."""

from __future__ import annotations

import argparse
import json
import shlex
from pathlib import Path
from typing import Any

from vc_gym.agents.learned import PRETRAINED_MODEL, LearnedHomingAgent, parse_env_kwargs
from vc_gym.cli import experiment as experiment_command
from vc_gym.cli.arguments import add_allow_imports_option, add_json_option, add_tracker_option
from vc_gym.experiments.options import HOMING_MODE_CHOICES, HOMING_MODE_HELP
from vc_gym.experiments.studies import EXPERIMENTS
from vc_gym.persistence import write_atomic

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
            "trained one (--agent MODEL.zip: from vc-gym train, from the RL Baselines3 Zoo, "
            "whose run folder says how the env was set up, or any stable-baselines3 PPO/SAC "
            "model of vc_gym/Homing-v0 with --env-kwargs); it must stand still 5 s "
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
        metavar="scripted|pretrained|MODEL.zip",
        help="the scripted homing agent, the shipped PPO policy, or a stable-baselines3 "
        "model of vc_gym/Homing-v0 (vc-gym train's, the RL Zoo's, or one saved alone)",
    )
    p.add_argument(
        "--env-kwargs",
        nargs="+",
        default=[],
        metavar="KEY=VALUE",
        help="vc_gym/Homing-v0 arguments of a learned agent, on top of those saved with it "
        "(values read as JSON, e.g. previous_action=true confirm_stop_m=0.25 "
        "scene=office); the model's spaces are checked against the env's",
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
        "for a learned agent the mode its training places were learned in, from its "
        "config.json: pose-home for the shipped one): " + HOMING_MODE_HELP,
    )
    add_tracker_option(p)
    p.add_argument(
        "--out", default="vc_gym_homing", metavar="DIR", help="output folder (resumable)"
    )
    p.add_argument(
        "--page",
        metavar="FILE.md",
        help="also write a results page of the docs (e.g. docs/results/homing.md): "
        "command, version and commit, date, machine, seeds, figures, plots",
    )
    add_json_option(p)
    p.set_defaults(func=run, hint=experiment_command.resume_hint)


def _staged_agent(model: str, env_kwargs: dict[str, Any], out: Path, allow_imports: bool) -> str:
    """The model a learned agent's evaluation runs: ``model`` itself when ``vc-gym train``
    wrote it and no ``--env-kwargs`` are given, else a copy in ``OUT/agent/`` beside a
    ``config.json`` holding the settings found for it (its Zoo run's, the flags'), which
    every worker and a resumed run then read. A different agent already staged in
    ``OUT`` is refused rather than mixed with it."""
    agent = LearnedHomingAgent(model, allow_imports, env_kwargs)  # every check, here
    if agent.settings_source == "vc-gym train" and not env_kwargs:
        return model
    folder = out / "agent"
    config = json.dumps(
        {"schema": 2, "algo": agent.algo, "env": agent.env_kwargs, "model": str(agent.path)},
        indent=2,
        sort_keys=True,
    )
    staged = {"model.zip": agent.path.read_bytes(), "config.json": config.encode()}
    if folder.is_dir():
        differs = [
            n
            for n, b in staged.items()
            if not (folder / n).is_file() or (folder / n).read_bytes() != b
        ]
        if differs:
            raise ValueError(
                f"{folder} holds another agent's {', '.join(differs)}; evaluate this one "
                "with another --out"
            )
        return str(folder / "model.zip")
    folder.mkdir(parents=True)
    for name, content in staged.items():
        write_atomic(folder / name, lambda tmp, content=content: Path(tmp).write_bytes(content))
    return str(folder / "model.zip")


def run(args: argparse.Namespace) -> int:
    """Run the homing experiment with the evaluation's options."""
    agent = args.agent
    env_kwargs = parse_env_kwargs(args.env_kwargs)
    if agent == "scripted":
        if env_kwargs:
            raise ValueError("--env-kwargs sets a learned agent's env; the scripted agent has none")
    else:
        model = str(PRETRAINED_MODEL) if agent == "pretrained" else agent
        staged = _staged_agent(model, env_kwargs, Path(args.out), bool(args.allow_imports))
        if agent != "pretrained" or staged != model:
            agent = staged
    options = {
        "agent": agent,
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
        page=args.page,
        command_line="vc-gym " + shlex.join(getattr(args, "argv", [])),
    )
