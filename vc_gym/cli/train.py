"""``vc-gym train``: train a learned homing agent, or a sweep of them over seeds."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from vc_gym.cli.arguments import (
    SceneChoices,
    add_allow_imports_option,
    argument_type,
)
from vc_gym.envs.homing_modes import HOMING_MODES
from vc_gym.experiments.options import parse_int_list, parse_tracker_spec

__all__ = ["add_parser", "resume_hint", "run"]

#: ``vc-gym train`` options that set a :class:`TrainConfig` field of the same name.
_TRAIN_FIELDS = {
    "algo": "algo",
    "timesteps": "timesteps",
    "n_envs": "n_envs",
    "seed": "seed",
    "scene": "scene",
    "learn_time": "learn_time_s",
    "tracker": "tracker",
    "eval_freq": "eval_freq",
    "eval_episodes": "eval_episodes",
    "save_freq": "save_freq",
    "demo_episodes": "demo_episodes",
    "places": "places",
    "collector": "collector",
    "closeness_bonus": "closeness_bonus",
    "min_walk": "min_walk_m",
    "previous_action": "previous_action",
    "home_offset_episodes": "home_offset_episodes",
    "home_offset_places": "home_offset_places",
    "home_offset_centre": "home_offset_centre",
    "mode": "mode",
    "position_std": "position_std",
    "expert_speed": "expert_speed_m_s",
}


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add ``train`` to the ``vc-gym`` commands."""
    p = commands.add_parser(
        "train",
        help="train a learned homing agent (stable-baselines3) on the compass' outputs",
        description=(
            "Train PPO (default) or SAC on vc_gym/LearnThenHome-v0 wrapped in "
            "CompassObservation: the agent sees the filters' heading and position estimates "
            "and the spots' goodness (never the image or the true pose) and acts by walking, "
            "turning and deciding to stop. The place is learned once (DIR/atlas.npz; with "
            "--places each place, DIR/atlas-place<s>.npz) and "
            "loaded by the environments, which run in parallel worker processes "
            "(SubprocVecEnv) and are kidnapped again and again. Writes DIR/model.zip, "
            "DIR/config.json, DIR/train_log.json, DIR/learning_curve.png, "
            "DIR/monitor/<i>.monitor.csv, DIR/eval and DIR/best (held-out evaluations) and "
            "DIR/checkpoints (--save-freq). Settings: TrainConfig's defaults, then --config "
            "FILE, then the options given here."
        ),
    )
    # every setting defaults to None here: a value given on the command line overrides
    # --config FILE, which overrides TrainConfig's defaults
    p.add_argument(
        "--config",
        metavar="FILE",
        help="YAML or JSON file of TrainConfig fields (any subset; a run's config.json works)",
    )
    p.add_argument("--algo", choices=["ppo", "sac"], help="algorithm (default ppo)")
    p.add_argument("--timesteps", type=int, help="agent decisions to train for (default 60000)")
    p.add_argument("--out", metavar="DIR", help="output folder (default vc_gym_agent)")
    p.add_argument("--n-envs", type=int, help="parallel environments (processes; default 2)")
    p.add_argument("--seed", type=int, help="seed of the model, the envs and the learning phase")
    p.add_argument(
        "--scene",
        choices=SceneChoices(),
        metavar="SCENE",
        help="scene to train in (default: robolab): %(choices)s",
    )
    p.add_argument("--learn-time", type=float, help="seconds per learning direction (default 5)")
    p.add_argument(
        "--places",
        type=argument_type(parse_int_list, "seeds"),
        metavar="S,S,...",
        help="train over a pool of places: the learning seeds of the places, each learned "
        "once (DIR/atlas-place<s>.npz), every episode in one of them (default: the one "
        "place of --seed)",
    )
    p.add_argument(
        "--mode",
        choices=list(HOMING_MODES),
        help="how the training places are learned and which tracker the agent homes on: "
        "pose-home (default: turns learned 0.5 m around home and every spot, normalised at "
        "the true home, the pose-grid tracker), check-home (normalised at the true home, "
        "grid) or paper (the paper's procedure, grid); every evaluation of the agent "
        "learns its places the same way",
    )
    p.add_argument(
        "--tracker",
        type=argument_type(parse_tracker_spec, "tracker"),
        metavar="SPEC",
        help="tracker of the agent's env (default: the mode's): grid (the paper's "
        "filters), pose-grid, particle, kalman, 'package.module:factory', or a JSON object "
        'such as \'{"type": "particle", "n_particles": 500}\'',
    )
    p.add_argument(
        "--position-std",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the policy also sees the tracker's position spread, so that it can learn "
        "when to trust the position (default on)",
    )
    add_allow_imports_option(p, "--config FILE and a --resume run's config.json")
    p.add_argument(
        "--collector",
        choices=["lockstep", "async"],
        help="how PPO collects rollouts from the workers: async (default with PPO and 2+ "
        "workers; each worker runs its rollout on its own, choosing its actions itself: the "
        "same rollouts, faster when a checked stop stands) or lockstep (SB3's: every step "
        "waits for the slowest worker; the default otherwise, and what runs saved without "
        "this setting used)",
    )
    p.add_argument(
        "--eval-freq",
        type=int,
        help="decisions between evaluations on held-out kidnappings, best model kept in "
        "DIR/best (default 20000; 0: none)",
    )
    p.add_argument("--eval-episodes", type=int, help="kidnappings per evaluation (default 10)")
    p.add_argument(
        "--save-freq",
        type=int,
        help="decisions between checkpoints in DIR/checkpoints (default 0: none)",
    )
    p.add_argument(
        "--demo-episodes",
        type=int,
        metavar="N",
        help="warm start (ppo): clone the scripted expert's decisions in N homing episodes "
        "before PPO starts (DIR/warm_start.json; the clone is evaluated first); 0: from "
        "scratch, as with --algo sac (default 60)",
    )
    p.add_argument(
        "--expert-speed",
        type=float,
        metavar="M_S",
        help="fastest walk of the expert the warm start clones, m/s, at most the full walk "
        "(default 0.25, the scripted agent's)",
    )
    p.add_argument(
        "--closeness-bonus",
        type=float,
        metavar="R",
        help="reward of a successful stop for its closeness to home: R x (1 - distance / "
        "success radius), on top of the success bonus (default 0: the task's rewards)",
    )
    p.add_argument(
        "--min-walk",
        type=float,
        metavar="M",
        help="stop requests are ignored until the robot has walked M metres by its own "
        "forward commands (default 0)",
    )
    p.add_argument(
        "--previous-action",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the policy also sees its last action, and the expert it is warm-started from "
        "keeps a turn going while home is behind it (against turning on the spot with "
        "home behind; default on)",
    )
    p.add_argument(
        "--home-offset-episodes",
        type=int,
        metavar="N",
        help="before the warm start the scripted expert homes N times in each training "
        "place and --home-offset-places more; the median of (tracker's position - true "
        "position) at its stops becomes the policy's goal, so that it stops at the true "
        "home, not where the tracker puts home (DIR/home_offset.json; default 10 with "
        "--mode paper, whose spots are normalised where the walk back ends, else 0; 0: "
        "the tracker's home, with --no-home-offset-centre)",
    )
    p.add_argument(
        "--home-offset-places",
        type=int,
        metavar="K",
        help="places learned only for that measurement (default 3): part of the tracker's "
        "offset belongs to the place",
    )
    p.add_argument(
        "--home-offset-centre",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="then let the expert home again on the same kidnappings going to the measured "
        "goal, and move the goal so that its median stop lies at the true home (a secant "
        "step per axis; the stops can move further than the goal did; default on when the "
        "offset is measured; needs --home-offset-episodes of 1 or more)",
    )
    p.add_argument("--tensorboard-log", metavar="DIR", help="also write TensorBoard logs to DIR")
    p.add_argument(
        "--resume",
        metavar="DIR",
        help="continue the run in DIR from its latest checkpoint (its config.json; "
        "--timesteps may extend it)",
    )
    p.add_argument(
        "--seeds",
        type=argument_type(parse_int_list, "seeds"),
        metavar="S,S,...",
        help="a sweep: one full training run per seed in DIR/seed-<s>, as jobs of the "
        "experiment runner, and DIR/results.json with every run's figures and their mean "
        "± std (rerun to resume)",
    )
    p.add_argument(
        "--backend", choices=["local", "ray"], default="local", help="--seeds: who runs the runs"
    )
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help="--seeds: runs at a time (local, default 1: each run has --n-envs workers of "
        "its own) or CPUs of the local Ray instance",
    )
    p.add_argument("--address", metavar="ADDR", help="--seeds with ray: join this cluster")
    p.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    p.set_defaults(func=run, hint=resume_hint)


def _train_sweep(args: argparse.Namespace, config, out: Path) -> int:
    from vc_gym.jobs.backends import make_backend
    from vc_gym.training.sweep import FIGURES, run_train_sweep

    with make_backend(args.backend, args.workers, args.address) as backend:
        r = run_train_sweep(out, config, args.seeds, backend, progress=not args.json)
    if args.json:
        print(json.dumps(r))
        return 1 if r["failed_jobs"] else 0
    for name in FIGURES:
        m = r["over_seeds"][name]
        if m["n"]:
            print(f"{name:26s} {m['mean']:.3f} ± {m['std']:.3f} over {m['n']} seeds")
    for f in r["failed_jobs"]:
        print(f"FAILED {f['key']}: {f['error']}")
    print(f"wrote {out / 'results.json'} and one run folder per seed")
    return 1 if r["failed_jobs"] else 0


def run(args: argparse.Namespace) -> int:
    from vc_gym.training.config import TrainConfig, check_names, read_train_config
    from vc_gym.training.train import train

    given = {
        field: getattr(args, opt)
        for opt, field in _TRAIN_FIELDS.items()
        if getattr(args, opt) is not None
    }
    if "n_envs" in given:
        given["vec_env"] = "dummy" if given["n_envs"] == 1 else "subproc"
        if given["n_envs"] == 1:  # one env runs in-process: nothing to collect from
            given.setdefault("collector", "lockstep")
    if args.seeds is not None and (args.resume or "seed" in given or args.tensorboard_log):
        raise ValueError("--seeds runs a sweep: no --seed, --resume or --tensorboard-log with it")
    if args.resume:
        if args.config or args.out:
            raise ValueError("--resume DIR continues that run: no --config or --out with it")
        unchanged = set(given) - {"timesteps"}
        if unchanged:
            raise ValueError(
                f"--resume keeps the run's settings; only --timesteps may change, "
                f"got {sorted(unchanged)}"
            )
        out = Path(args.resume)
        config = read_train_config(out / "config.json", args.allow_imports, **given)
    else:
        if args.config:
            config = read_train_config(args.config, args.allow_imports, **given)
        else:
            config = TrainConfig(**given)
        check_names(config)  # a bad scene or tracker fails before the folder is made
        out = Path(args.out or "vc_gym_agent")  # train and the sweep's run check it first
    if args.seeds is not None:
        return _train_sweep(args, config, out)
    s = train(
        config,
        out,
        progress=not args.json,
        tensorboard_log=args.tensorboard_log,
        resume=bool(args.resume),
    )
    if args.json:
        print(json.dumps(s))
    else:
        rate = s["recent_success_rate"]
        print(
            f"trained {config.algo} for {config.timesteps} decisions in {s['duration_s']:.0f} s "
            f"({s['episodes']} episodes"
            + (
                f"; last 50: success {rate:.0%}, mean stop error "
                f"{s['recent_mean_stop_error_m'] * 100:.0f} cm)"
                if rate is not None
                else ")"
            )
        )
        print(f"wrote {s['model']} (evaluate it: vc-gym evaluate --agent {s['model']})")
    return 0


def resume_hint(args: argparse.Namespace) -> str:
    """How to go on after Ctrl-C, where a command can: ``"; ..."`` or ``""``."""
    command = args.command
    if command in ("experiment", "evaluate"):
        name = getattr(args, "name", "homing")
        if name in ("synthetic-compass", "real-rotation"):
            return ""  # no jobs: it starts over
        out = args.out or f"vc_gym_{name.replace('-', '_')}"
        return f"; rerun the same command to resume from the jobs saved in {out}"
    if command == "train":
        if getattr(args, "seeds", None) is not None:
            out = args.out or "vc_gym_agent"
            return f"; rerun the same command to resume the sweep from the runs saved in {out}"
        out = args.resume or args.out or "vc_gym_agent"
        try:
            from vc_gym.training.run_folder import latest_checkpoint

            saved = latest_checkpoint(out) is not None
        except Exception:  # noqa: BLE001 - only a hint; the run is over either way
            saved = False
        if saved:
            return f"; 'vc-gym train --resume {out}' continues from its last checkpoint"
        return "; no checkpoint was saved to resume from (--save-freq N saves them)"
    return ""
