"""``vc-gym bench``: speed benchmarks, medians measured side by side in one run."""

from __future__ import annotations

import argparse
import json
import shlex

from vc_gym.cli.arguments import add_json_option
from vc_gym.experiments.results_page import PageInfo, check_page_path, write_page
from vc_gym.jobs.output import write_json
from vc_gym.validation import MAX_EPISODES, check_seed, int_in_range

__all__ = ["MAX_BENCH_REPEATS", "add_parser", "run"]

#: Most timed rounds of ``vc-gym bench`` (``--repeats``).
MAX_BENCH_REPEATS = 1_000

#: What each benchmark measures (its ``--help`` and its results page).
_WHAT = {
    "compass": "learning and localisation time per 208x160 frame at the paper's defaults, "
    "next to the floor (copying the scanned pixels once).",
    "filters": "cost of one update of every filter (1 deg grid, 1,000 and 10,000 particles, "
    "Kalman) and their heading errors on one seeded tracking run with the real compass.",
    "env": "steps per second of vc_gym/AiboRoom-v0 next to bare PyBullet doing the same "
    "physics and render, and the speed-up of 2 async envs.",
    "trackers": "cost of one update of every registered tracker (grid, particle, kalman) on "
    "the same walk through a ray-cast room with a 4-spot atlas, next to the atlas alone.",
    "bearings": "cost per frame of reading a frame's colour changes as bearings and of "
    "scoring --poses candidate poses with the landmarks learned from the pose-home mode's "
    "turns (rendered at their true poses in the robot lab), over --frames frames.",
    "backends": "jobs per second of the homing experiment's episodes with 1 local worker, "
    "--workers local workers and a local Ray instance of --workers CPUs (atlas learned "
    "once; the results must be byte-identical).",
    "train": "agent decisions per second of PPO training with --n-envs workers, once with "
    "SB3's lockstep collector and once with the asynchronous one, next to one "
    "vc_gym/Homing-v0 stepping alone (timed with the same actions before the first "
    "training and after each, in the same run; each training against the rounds either "
    "side of it), and their ratios (efficiency; target 0.7).",
}


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add ``bench`` to the ``vc-gym`` commands."""
    p = commands.add_parser(
        "bench",
        help="speed benchmarks (medians measured side by side in one run)",
        description=" ".join(f"{name}: {text}" for name, text in _WHAT.items())
        + " The last line of --json output is one JSON object.",
    )
    p.add_argument(
        "what",
        choices=list(_WHAT),
        help="what to benchmark",
    )
    add_json_option(p)
    p.add_argument("--out", metavar="FILE", help="also save the JSON to FILE")
    p.add_argument("--frames", type=int, default=40, help="compass: distinct test frames")
    p.add_argument("--repeats", type=int, default=15, help="timed rounds (medians are reported)")
    p.add_argument(
        "--poses", type=int, default=500, help="bearings: candidate poses scored per frame"
    )
    p.add_argument("--plot", metavar="PNG", help="filters: save a plot of the tracking run")
    p.add_argument(
        "--episodes", type=int, default=12, help="backends: homing episodes (jobs) per backend"
    )
    p.add_argument(
        "--workers", type=int, default=2, help="backends: workers of the parallel backends"
    )
    p.add_argument("--timesteps", type=int, default=2048, help="train: decisions to train for")
    p.add_argument("--n-envs", type=int, default=2, help="train: worker processes")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--page",
        metavar="FILE.md",
        help="also write the results page of the docs (e.g. docs/results/bench-compass.md)",
    )
    p.set_defaults(func=run)


def _check_bench_args(args: argparse.Namespace) -> None:
    """Every ``vc-gym bench`` argument its benchmark uses, then ``--out`` and ``--plot``,
    before any work (a bad file name fails now, not after the benchmark)."""
    from vc_gym.jobs.output import check_out_file

    int_in_range("--repeats", args.repeats, 1, MAX_BENCH_REPEATS)
    check_seed("--seed", args.seed)
    if args.what == "compass":
        from vc_gym.experiments.benchmarks.compass import MAX_FRAMES

        int_in_range("--frames", args.frames, 1, MAX_FRAMES)
    elif args.what == "bearings":
        from vc_gym.experiments.benchmarks.bearings import MAX_FRAMES, MAX_POSES

        int_in_range("--frames", args.frames, 1, MAX_FRAMES)
        int_in_range("--poses", args.poses, 1, MAX_POSES)
    elif args.what == "backends":
        from vc_gym.jobs.workers import check_workers

        int_in_range("--episodes", args.episodes, 1, MAX_EPISODES)
        check_workers(args.workers, "--workers", minimum=2)
    elif args.what == "train":
        from vc_gym.experiments.benchmarks.train import MAX_TIMESTEPS
        from vc_gym.jobs.workers import check_workers

        int_in_range("--timesteps", args.timesteps, 1, MAX_TIMESTEPS)
        check_workers(args.n_envs, "--n-envs")
    if args.plot is not None and args.what != "filters":
        raise ValueError(f"--plot is for 'bench filters', not 'bench {args.what}'")
    if args.out:
        check_out_file(args.out)
    if args.plot is not None:
        check_out_file(args.plot, "--plot")


def run(args: argparse.Namespace) -> int:
    """Run ``vc-gym bench WHAT``: measure, print the figures, save them where asked."""
    _check_bench_args(args)
    if args.page is not None:
        check_page_path(args.page)
    result = _measure(args)
    lines = _summary_lines(args.what, result)
    if not args.json:
        for line in lines:
            print(line)
    if args.out:
        write_json(args.out, result)
    if args.page is not None:
        info = PageInfo(
            title=f"`vc-gym bench {args.what}`",
            command="vc-gym " + shlex.join(getattr(args, "argv", [])),
            description=_WHAT[args.what],
            seeds=f"base seed {args.seed}",
        )
        plots = [args.plot] if args.what == "filters" and args.plot else []
        written = write_page(args.page, info, lines, result, plots)
        if not args.json:
            print(f"wrote the results page {written}")
    if args.json:
        print(json.dumps(result))
    return 0


def _measure(args: argparse.Namespace) -> dict:
    """Run the benchmark ``args.what`` with its arguments."""
    progress = not args.json
    if args.what == "compass":
        from vc_gym.experiments.benchmarks.compass import bench_compass

        return bench_compass(
            frames=args.frames, repeats=args.repeats, seed=args.seed, progress=progress
        )
    if args.what == "filters":
        from vc_gym.experiments.benchmarks.filters import bench_filters

        return bench_filters(repeats=args.repeats, seed=args.seed, plot=args.plot)
    if args.what == "env":
        from vc_gym.experiments.benchmarks.env import bench_env

        return bench_env(rounds=max(1, args.repeats // 3), seed=args.seed)
    if args.what == "trackers":
        from vc_gym.experiments.benchmarks.trackers import bench_trackers

        return bench_trackers(repeats=max(1, args.repeats // 3), seed=args.seed)
    if args.what == "bearings":
        from vc_gym.experiments.benchmarks.bearings import bench_bearings

        return bench_bearings(
            frames=args.frames, repeats=args.repeats, poses=args.poses, seed=args.seed,
            progress=progress,
        )  # fmt: skip
    if args.what == "backends":
        from vc_gym.experiments.benchmarks.backends import bench_backends

        return bench_backends(
            episodes=args.episodes, workers=args.workers, seed=args.seed, progress=progress
        )
    from vc_gym.experiments.benchmarks.train import bench_train

    return bench_train(
        timesteps=args.timesteps, n_envs=args.n_envs, seed=args.seed, progress=progress
    )


def _summary_lines(what: str, result: dict) -> list[str]:
    """What a benchmark measured, in the lines the command prints."""
    if what == "compass":
        return [
            f"learn {result['learn_ms']:.3f} ms, localize {result['localize_ms']:.3f} ms, "
            f"estimate {result['estimate_ms']:.3f} ms, floor {result['floor_ms']:.4f} ms per "
            f"{result['frame']} frame ({result['pixels_per_s'] / 1e6:.1f} Mpixel/s)",
            f"localize / floor {result['localize_over_floor']:.1f}, learn / floor "
            f"{result['learn_over_floor']:.1f}; median heading error of the timed frames "
            f"{result['median_heading_error_deg']:.2f} deg",
            f"paper (Aibo): learn {result['paper_aibo_learn_ms']} ms, "
            f"localize {result['paper_aibo_localize_ms']} ms",
        ]
    if what == "filters":
        lines = [
            f"{key[: -len('_update_ms')]:20s} {value:8.3f} ms per update"
            for key, value in result.items()
            if key.endswith("_update_ms")
        ]
        return lines + [
            f"{name:20s} mean error {v['mean_error_deg']:6.2f}°, max {v['max_error_deg']:6.1f}°"
            for name, v in result["tracking"].items()
        ]
    if what == "env":
        return [
            f"env {result['steps_per_s']:.1f} steps/s, bare PyBullet "
            f"{result['bare_steps_per_s']:.1f} steps/s (ratio {result['env_over_bare']:.2f}); "
            f"2 async envs: x{result['async2_speedup']:.2f}, "
            f"2 sync envs: x{result['sync2_speedup']:.2f}"
        ]
    if what == "trackers":
        return [f"{'atlas alone':12s} {result['atlas_ms']:7.3f} ms per frame (shared by all)"] + [
            f"{name:12s} {v['update_ms']:7.3f} ms per update "
            f"(+{v['overhead_ms']:.3f} ms over the atlas); final heading error "
            f"{v['final_heading_error_deg']:.1f}°, position error "
            f"{v['final_position_error_m'] * 100:.0f} cm"
            for name, v in result["trackers"].items()
        ]
    if what == "bearings":
        return [
            f"bearings {result['bearings_ms']:.3f} ms per frame ({result['changes_per_frame']:g} "
            f"colour changes a frame), likelihood of {result['poses']} poses "
            f"{result['likelihood_ms']:.3f} ms per frame; {result['landmarks']} landmarks "
            f"from {result['learning_frames']} learning frames ({result['scene']})"
        ]
    if what == "backends":
        lines = []
        for name, r in result["runs"].items():
            ratio = result["speedup_vs_one_local_worker"].get(name, 1.0)
            lines.append(
                f"{name:8s} {r['jobs_per_s']:6.3f} jobs/s ({r['jobs']} homing episodes in "
                f"{r['wall_s']:.0f} s), x{ratio:.2f} of one local worker"
            )
        identical = result["identical_results"]
        return [*lines, f"byte-identical results.json on every backend: {identical}"]
    n = result["n_envs"]
    lines = [
        f"one env alone: {result['env_decisions_per_s']:.1f} decisions/s, "
        f"{result['env_task_steps_per_s']:.1f} task-env steps/s "
        f"({result['env_task_steps_per_decision']:.2f} per decision)"
    ]
    for name, r in result["collectors"].items():
        lines.append(
            f"training, {name:8s} collector: {r['train_decisions_per_s']:.1f} "
            f"decisions/s with {n} workers, efficiency {r['efficiency']:.2f} of {n} x "
            f"the env's rate (target {result['target_efficiency']}); in task-env "
            f"steps {r['train_task_steps_per_s']:.1f}/s, efficiency "
            f"{r['task_step_efficiency']:.2f} (decisions / task-env steps "
            f"{r['decisions_over_task_steps']:.2f})"
        )
    if "async_over_lockstep" in result:
        lines.append(f"async / lockstep decisions/s: {result['async_over_lockstep']:.2f}")
    return lines
