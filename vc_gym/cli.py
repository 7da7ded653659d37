"""The ``vc-gym`` command."""

from __future__ import annotations

import argparse
import json
import sys
import textwrap
from collections.abc import Iterator, Sequence
from pathlib import Path

from vc_gym.jobs.output import write_json
from vc_gym.validation import (
    MAX_EPISODES,
    MAX_HOMING_S,
    MAX_LEARN_TIME_S,
    MAX_SEEDS,
    check_seed,
    int_in_range,
    positive_float_at_most,
)

__all__ = ["EXIT_INTERRUPTED", "MAX_BENCH_REPEATS", "MAX_VIDEOS", "main"]

#: Exit status after Ctrl-C (128 + SIGINT, as a shell reports it).
EXIT_INTERRUPTED = 130
#: Most timed rounds of ``vc-gym bench`` (``--repeats``).
MAX_BENCH_REPEATS = 1_000
#: Most homing episodes written as MP4 (``--video``).
MAX_VIDEOS = 1_000


def _cmd_demo(args: argparse.Namespace) -> int:
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


def _cmd_evaluate(args: argparse.Namespace) -> int:
    """``vc-gym evaluate``: the homing experiment without the likelihood field."""
    args.name = "homing"
    args.field = False
    args.seeds = None
    args.tracker = [args.tracker]
    args.atlas = args.video = args.address = args.size = None
    args.quick = False
    args.backend = "local"
    return _cmd_experiment(args)


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
}


def _train_sweep(args: argparse.Namespace, config, out: Path) -> int:
    from vc_gym.jobs.runner import make_backend
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


def _cmd_train(args: argparse.Namespace) -> int:
    from vc_gym.training.train import TrainConfig, check_names, read_train_config, train

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


def _check_bench_args(args: argparse.Namespace) -> None:
    """Every ``vc-gym bench`` argument its benchmark uses, then ``--out`` and ``--plot``,
    before any work (a bad file name fails now, not after the benchmark)."""
    from vc_gym.jobs.output import check_out_file

    int_in_range("--repeats", args.repeats, 1, MAX_BENCH_REPEATS)
    check_seed("--seed", args.seed)
    if args.what == "compass":
        from vc_gym.experiments.benchmarks.compass import MAX_FRAMES

        int_in_range("--frames", args.frames, 1, MAX_FRAMES)
    elif args.what == "backends":
        from vc_gym.jobs.runner import check_workers

        int_in_range("--episodes", args.episodes, 1, MAX_EPISODES)
        check_workers(args.workers, "--workers", minimum=2)
    elif args.what == "train":
        from vc_gym.experiments.benchmarks.train import MAX_TIMESTEPS
        from vc_gym.jobs.runner import check_workers

        int_in_range("--timesteps", args.timesteps, 1, MAX_TIMESTEPS)
        check_workers(args.n_envs, "--n-envs")
    if args.plot is not None and args.what != "filters":
        raise ValueError(f"--plot is for 'bench filters', not 'bench {args.what}'")
    if args.out:
        check_out_file(args.out)
    if args.plot is not None:
        check_out_file(args.plot, "--plot")


def _cmd_bench(args: argparse.Namespace) -> int:
    _check_bench_args(args)
    if args.what == "compass":
        from vc_gym.experiments.benchmarks.compass import bench_compass

        result = bench_compass(
            frames=args.frames, repeats=args.repeats, seed=args.seed, progress=not args.json
        )
        if not args.json:
            print(
                f"learn {result['learn_ms']:.3f} ms, localize {result['localize_ms']:.3f} ms, "
                f"floor {result['floor_ms']:.4f} ms per {result['frame']} frame "
                f"({result['pixels_per_s'] / 1e6:.1f} Mpixel/s); "
                f"paper (Aibo): learn {result['paper_aibo_learn_ms']} ms, "
                f"localize {result['paper_aibo_localize_ms']} ms"
            )
    elif args.what == "filters":
        from vc_gym.experiments.benchmarks.filters import bench_filters

        result = bench_filters(repeats=args.repeats, seed=args.seed, plot=args.plot)
        if not args.json:
            for key, value in result.items():
                if key.endswith("_update_ms"):
                    print(f"{key[: -len('_update_ms')]:20s} {value:8.3f} ms per update")
            for name, v in result["tracking"].items():
                print(
                    f"{name:20s} mean error {v['mean_error_deg']:6.2f}°, "
                    f"max {v['max_error_deg']:6.1f}°"
                )
    elif args.what == "env":
        from vc_gym.experiments.benchmarks.env import bench_env

        result = bench_env(rounds=max(1, args.repeats // 3), seed=args.seed)
        if not args.json:
            print(
                f"env {result['steps_per_s']:.1f} steps/s, bare PyBullet "
                f"{result['bare_steps_per_s']:.1f} steps/s (ratio {result['env_over_bare']:.2f}); "
                f"2 async envs: x{result['async2_speedup']:.2f}, "
                f"2 sync envs: x{result['sync2_speedup']:.2f}"
            )
    elif args.what == "trackers":
        from vc_gym.experiments.benchmarks.trackers import bench_trackers

        result = bench_trackers(repeats=max(1, args.repeats // 3), seed=args.seed)
        if not args.json:
            print(f"{'atlas alone':12s} {result['atlas_ms']:7.3f} ms per frame (shared by all)")
            for name, v in result["trackers"].items():
                print(
                    f"{name:12s} {v['update_ms']:7.3f} ms per update "
                    f"(+{v['overhead_ms']:.3f} ms over the atlas); final heading error "
                    f"{v['final_heading_error_deg']:.1f}°, position error "
                    f"{v['final_position_error_m'] * 100:.0f} cm"
                )
    elif args.what == "backends":
        from vc_gym.experiments.benchmarks.backends import bench_backends

        result = bench_backends(
            episodes=args.episodes, workers=args.workers, seed=args.seed, progress=not args.json
        )
        if not args.json:
            for name, r in result["runs"].items():
                ratio = result["speedup_vs_one_local_worker"].get(name, 1.0)
                print(
                    f"{name:8s} {r['jobs_per_s']:6.3f} jobs/s ({r['jobs']} homing episodes in "
                    f"{r['wall_s']:.0f} s), x{ratio:.2f} of one local worker"
                )
            print(f"byte-identical results.json on every backend: {result['identical_results']}")
    elif args.what == "train":
        from vc_gym.experiments.benchmarks.train import bench_train

        result = bench_train(
            timesteps=args.timesteps, n_envs=args.n_envs, seed=args.seed, progress=not args.json
        )
        if not args.json:
            n = result["n_envs"]
            print(
                f"one env alone: {result['env_decisions_per_s']:.1f} decisions/s, "
                f"{result['env_task_steps_per_s']:.1f} task-env steps/s "
                f"({result['env_task_steps_per_decision']:.2f} per decision)"
            )
            for name, r in result["collectors"].items():
                print(
                    f"training, {name:8s} collector: {r['train_decisions_per_s']:.1f} "
                    f"decisions/s with {n} workers, efficiency {r['efficiency']:.2f} of {n} x "
                    f"the env's rate (target {result['target_efficiency']}); in task-env "
                    f"steps {r['train_task_steps_per_s']:.1f}/s, efficiency "
                    f"{r['task_step_efficiency']:.2f} (decisions / task-env steps "
                    f"{r['decisions_over_task_steps']:.2f})"
                )
            if "async_over_lockstep" in result:
                print(f"async / lockstep decisions/s: {result['async_over_lockstep']:.2f}")
    else:  # pragma: no cover - argparse restricts the choices
        raise AssertionError(args.what)
    if args.out:
        write_json(args.out, result)
    if args.json:
        print(json.dumps(result))
    return 0


def _cmd_experiment(args: argparse.Namespace) -> int:
    if args.name in ("synthetic-compass", "real-rotation"):
        return _cmd_compass_experiment(args)
    from vc_gym.experiments.studies import ExperimentOptions, get_experiment
    from vc_gym.jobs.output import new_out_dir
    from vc_gym.jobs.runner import make_backend

    experiment = get_experiment(args.name)
    size = "quick" if args.quick else (args.size or "full")
    run = experiment.runner()
    options = _experiment_options(args, run)
    _check_experiment_args(args)  # before the folder is made and any worker starts
    with (
        new_out_dir(args.out or f"vc_gym_{args.name.replace('-', '_')}") as out,
        make_backend(args.backend, args.workers, args.address) as backend,
    ):
        opts = ExperimentOptions(
            seed=args.seed,
            size=size,
            backend=backend,
            atlas_dir=args.atlas,
            video=args.video or 0,
            progress=not args.json,
        )
        results = run(out, opts, **options)
    if args.json:
        print(json.dumps({k: v for k, v in results.items() if k != "per_episode"}))
    else:
        for line in experiment.summary_lines(results):
            print(line)
        from vc_gym.jobs.output import read_json

        run_info = read_json(out / "run.json") if (out / "run.json").is_file() else {}
        for line in experiment.cost_lines(run_info):
            print(line)
        print(f"wrote {out / 'results.json'}, {out / 'run.json'} and the plots in {out}")
    failed = results.get("failed_jobs") or []
    if failed:
        print(
            f"vc-gym {args.command}: failed: {len(failed)} job(s) failed twice, e.g. "
            f"{failed[0]['stage']}/{failed[0]['key']}: {failed[0]['error']} (all in "
            f"{out / 'results.json'}; rerun the same command to retry them)",
            file=sys.stderr,
        )
        return 1
    return 0


def _check_experiment_args(args: argparse.Namespace) -> None:
    """The counts, seeds, times and folders ``vc-gym experiment`` (and ``evaluate``)
    takes, by flag, with their upper bounds: checked before any work. The experiment
    checks its own settings again (and what only it knows) before its first job."""
    import os

    from vc_gym.jobs.runner import check_workers

    check_seed("--seed", args.seed)
    if getattr(args, "workers", None) is not None:
        check_workers(args.workers, "--workers")
    if getattr(args, "episodes", None) is not None:
        int_in_range("--episodes", args.episodes, 1, MAX_EPISODES)
    seeds = getattr(args, "seeds", None)
    if seeds is not None:
        if not 1 <= len(seeds) <= MAX_SEEDS:
            raise ValueError(f"--seeds must name 1..{MAX_SEEDS} seeds, got {len(seeds)}")
        for seed in seeds:
            check_seed("--seeds", seed)
    if getattr(args, "video", None) is not None:
        int_in_range("--video", args.video, 0, MAX_VIDEOS)
    if getattr(args, "learn_time", None) is not None:
        positive_float_at_most("--learn-time", args.learn_time, MAX_LEARN_TIME_S)
    if getattr(args, "max_homing", None) is not None:
        positive_float_at_most("--max-homing", args.max_homing, MAX_HOMING_S)
    for flag, folder in (
        ("--atlas", getattr(args, "atlas", None)),
        ("--data", getattr(args, "data", None)),
    ):
        if folder is not None and not os.path.isdir(folder):
            raise ValueError(f"{flag} {folder}: not a folder")


def _experiment_options(args: argparse.Namespace, run) -> dict:
    """The experiment-specific flags given, checked against what ``run`` accepts."""
    import inspect

    accepted = inspect.signature(run).parameters
    given = {
        "agent": getattr(args, "agent", None),
        "episodes": getattr(args, "episodes", None),
        "seeds": getattr(args, "seeds", None),
        "scenes": getattr(args, "scenes", None),
        "learn_time_s": getattr(args, "learn_time", None),
        "max_homing_s": getattr(args, "max_homing", None),
        "relearn": getattr(args, "relearn", None),
        "field": getattr(args, "field", None),
        "mode": getattr(args, "mode", None),
        "modes": getattr(args, "modes", None),
        "light": getattr(args, "light", None),
        "data_dir": getattr(args, "data", None),
        "sensor": getattr(args, "sensor", None),
        "home_offset_m": getattr(args, "home_offset", None),
        "allow_imports": getattr(args, "allow_imports", False) or None,
    }
    trackers = getattr(args, "tracker", None)
    if trackers:
        if "trackers" in accepted:
            given["trackers"] = trackers
        elif len(trackers) > 1:
            raise ValueError(f"experiment {args.name} takes one --tracker")
        else:
            given["tracker"] = trackers[0]
    options = {}
    for name, value in given.items():
        if value is None:
            continue
        if name not in accepted:
            flag = "--" + {
                "learn_time_s": "learn-time",
                "max_homing_s": "max-homing",
                "data_dir": "data",
                "home_offset_m": "home-offset",
                "allow_imports": "allow-imports",
            }.get(name, name)
            raise ValueError(f"experiment {args.name} does not take {flag}")
        options[name] = value
    return options


def _cmd_compass_experiment(args: argparse.Namespace) -> int:
    """The compass-only experiments (no simulator, no jobs)."""
    from vc_gym.jobs.output import new_out_dir

    check_seed("--seed", args.seed)
    if args.name == "real-rotation":  # the photos are checked before the folder is made
        from vc_gym.experiments.real_data import default_real_data_dir

        data = Path(args.data) if args.data else default_real_data_dir()
        if data is None or not data.is_dir():
            print(
                "real photos not found: pass --data DIR (the folder holding rotation_grail/ "
                "and rotation_parrington/) or set VC_GYM_REAL_DATA",
                file=sys.stderr,
            )
            return 2
    with new_out_dir(args.out or f"vc_gym_{args.name.replace('-', '_')}") as out:
        result = _run_compass_experiment(args, out)
    if args.json:
        print(json.dumps(result))
    return 0


def _run_compass_experiment(args: argparse.Namespace, out: Path) -> dict:
    """Run a compass-only experiment in ``out`` and print its table; its results."""
    if args.name == "synthetic-compass":
        from vc_gym.experiments.synthetic_compass import run_synthetic_compass

        result = run_synthetic_compass(out, seed=args.seed)  # writes results.json
        if not args.json:
            for label, entry in result["results"].items():
                parts = [
                    f"light×{k.split('_')[1]}: median {v['median_error_deg']:.2f}°, "
                    f"{v['within_5deg']:.0%} within 5°"
                    + (f" (session gain {v['session_gain']:.2f})" if "session_gain" in v else "")
                    for k, v in entry.items()
                ]
                print(f"{label:28s} " + " | ".join(parts))
            print(f"wrote {out / 'synthetic_compass.png'}")
    else:
        from vc_gym.experiments.real_data import default_real_data_dir
        from vc_gym.experiments.real_rotation import run_real_rotation

        data = Path(args.data) if args.data else default_real_data_dir()
        result = run_real_rotation(data, progress=not args.json)
        if not args.json:
            print(
                f"{'set':22s} {'light':>5s} {'classes':>7s} {'exposure':>8s} "
                f"{'median':>8s} {'<5°':>5s}"
            )
            for r in result["results"]:
                line = (
                    f"{r['set']:22s} {r['light']:5.2f} {r['n_colors']:7d} {r['exposure']:>8s} "
                    f"{r['median_error_deg']:7.2f}° {r['within_5deg']:5.0%}"
                )
                if "session_gain" in r:
                    line += (
                        f"  (session gain {r['session_gain']:.2f}; per frame "
                        f"{r['per_frame_median_error_deg']:.2f}°, "
                        f"{r['per_frame_within_5deg']:.0%})"
                    )
                print(line)
        write_json(out / "results.json", result)
    return result


class _SceneChoices:
    """``choices`` for a ``--scene`` option: ``extra`` and the registered scene names.

    Read from the scene registry only when argparse checks or lists them, so that
    ``vc-gym --help`` and commands without ``--scene`` do not import PyBullet. A scene
    registered in this process before :func:`main` runs is accepted too.
    """

    def __init__(self, *extra: str) -> None:
        self.extra = extra

    def _names(self) -> tuple[str, ...]:
        from vc_gym.sim.scenes import scene_names

        return (*self.extra, *scene_names())

    def __contains__(self, name: object) -> bool:
        return name in self._names()

    def __iter__(self) -> Iterator[str]:
        return iter(self._names())


def _cmd_render(args: argparse.Namespace) -> int:
    from vc_gym.experiments.render_scenes import render_scene_pictures
    from vc_gym.jobs.output import check_out_dir
    from vc_gym.sim.scenes import scene_names

    check_seed("--seed", args.seed)
    check_out_dir(args.out)
    scenes = scene_names() if args.scene == "all" else (args.scene,)
    for path in render_scene_pictures(args.out, scenes, seed=args.seed, randomize=args.randomize):
        print(f"wrote {path}")
    return 0


def _cmd_soak(args: argparse.Namespace) -> int:
    from vc_gym.experiments.benchmarks.soak import check_soak_args, soak
    from vc_gym.jobs.output import check_out_file

    check_soak_args(
        args.steps,
        args.cycles,
        args.window,
        args.seed,
        ("--steps", "--cycles", "--window", "--seed"),
    )
    if args.out:
        check_out_file(args.out)
    r = soak(args.steps, args.cycles, args.window, seed=args.seed, progress=not args.json)
    if args.out:
        write_json(args.out, r)
    if args.json:
        print(json.dumps(r))
        return 0
    print(
        f"{r['steps']} steps: median {r['median_steps_per_s']} steps/s (last window / first "
        f"{r['last_over_first_window']}), memory {r['rss_mb'][0]} -> {r['rss_mb'][-1]} MB, "
        f"growth {r['rss_growth_kb_per_10k_steps']} KB per 10k steps"
    )
    verdict = "within" if r["cycles_within_target"] else "ABOVE"
    print(
        f"{r['cycles']} make/close cycles: {r['rss_before_cycles_mb']} -> "
        f"{r['rss_after_cycles_mb']} MB, growth {r['rss_growth_kb_per_cycle']} KB per cycle "
        f"({verdict} the {r['growth_target_kb_per_cycle']:g} KB target); C heap in use: "
        f"{r['heap_growth_kb_per_10k_steps']} KB per 10k steps, "
        f"{r['heap_growth_kb_per_cycle']} KB per cycle"
    )
    return 0


def _cmd_check(args: argparse.Namespace) -> int:
    from vc_gym.experiments.benchmarks.soak import MAX_SOAK_STEPS, MIN_WINDOW, check_soak_args
    from vc_gym.experiments.check import run_check
    from vc_gym.jobs.output import check_out_file

    # the soak's arguments before the cases run; its window is the one run_check uses
    steps = int_in_range("--soak-steps", args.soak_steps, 2 * MIN_WINDOW, MAX_SOAK_STEPS)
    window = max(MIN_WINDOW, steps // 4)
    check_soak_args(
        steps,
        args.soak_cycles,
        window,
        0,
        ("--soak-steps", "--soak-cycles", "--soak-steps / 4", "seed"),
    )
    if args.out:
        check_out_file(args.out)
    r = run_check(args.soak_steps, args.soak_cycles, progress=not args.json)
    if args.out:
        write_json(args.out, r)
    if args.json:
        print(json.dumps(r))
    else:
        for suite, s in r["suites"].items():
            print(f"{suite:13s} {s['passed']}/{s['tried']} passed")
        for f in r["failures"]:
            print(f"FAILED {f['suite']}: {f['case']}: {f['error']}")
        k = r["soak"]
        print(
            f"tried {r['tried']}, passed {r['passed']}, failed {r['failed']}; soak: "
            f"{k['median_steps_per_s']} steps/s, {k['rss_growth_kb_per_10k_steps']} KB per 10k "
            f"steps, {k['rss_growth_kb_per_cycle']} KB per make/close cycle"
        )
    return 1 if r["failed"] else 0


def _tracker_spec(text: str) -> object:
    """``--tracker``: a name, ``package.module:factory`` or a JSON ``{"type": ...}``."""
    if text.lstrip().startswith("{"):
        try:
            spec = json.loads(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(f"not a JSON object: {exc}") from None
        if not isinstance(spec, dict):
            raise argparse.ArgumentTypeError("a JSON tracker spec must be an object")
        return spec
    return text


def _int_list(text: str) -> list[int]:
    try:
        return [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected integers separated by commas: {text!r}"
        ) from None


def _float_pair(text: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 2:
        raise argparse.ArgumentTypeError(f"expected two numbers X,Y: {text!r}")
    return values


def _str_list(text: str) -> list[str]:
    return [v.strip() for v in text.split(",") if v.strip()]


def _add_tracker_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--tracker",
        default="grid",
        type=_tracker_spec,
        metavar="SPEC",
        help=(
            "what turns frames and odometry into the pose estimate: grid (the paper's heading "
            "grid + translational filter, default), particle, kalman, "
            "'package.module:factory' (your own tracker class or factory), or a JSON "
            'object such as \'{"type": "particle", "n_particles": 2000}\''
        ),
    )


def _add_allow_imports_option(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument(
        "--allow-imports",
        action="store_true",
        help=(
            f"let {what} name plug-ins by import path ('package.module:factory'), which "
            "imports and runs that code; without it a file may name only registered "
            "plug-ins. Only for files you trust"
        ),
    )


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``vc-gym`` (exposed for documentation and tests)."""
    from vc_gym import __version__

    parser = argparse.ArgumentParser(
        prog="vc-gym",
        description=(
            "vc_gym: the appearance-based visual compass of Sturm & Visser - compass "
            "sensor, filters, simulated quadruped room and homing agents."
        ),
    )
    parser.add_argument("--version", action="version", version=f"vc_gym {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    p = sub.add_parser(
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
        "--learn-time", type=float, default=5.0, help="seconds per learning direction (paper: 5)"
    )
    p.add_argument(
        "--mode",
        choices=["improved", "paper"],
        default="improved",
        help="improved (default): normalise the spots with the first turn's frames at the "
        "true home, and check home with a full turn before stopping; paper: normalise "
        "after walking back home by odometry and stop where the estimate says home",
    )
    _add_tracker_option(p)
    p.set_defaults(func=_cmd_demo)

    p = sub.add_parser(
        "bench",
        help="speed benchmarks (medians measured side by side in one run)",
        description=(
            "compass: learning and localisation time per 208x160 frame at the paper's "
            "defaults, next to the floor (copying the scanned pixels once). filters: cost of "
            "one update of every filter (1 deg grid, 1,000 and 10,000 particles, Kalman) and "
            "their heading errors on one seeded tracking run with the real compass. env: steps per "
            "second of vc_gym/AiboRoom-v0 next to bare PyBullet doing the same physics and "
            "render, and the speed-up of 2 async envs. trackers: cost of one update of every "
            "registered tracker (grid, particle, kalman) on the same walk through a ray-cast "
            "room with a 4-spot atlas, next to the atlas alone. backends: jobs per second of "
            "the homing experiment's episodes with 1 local worker, --workers local workers and "
            "a local Ray instance of --workers CPUs (atlas learned once; the results must be "
            "byte-identical). train: agent decisions per second of PPO training with --n-envs "
            "workers, once with SB3's lockstep collector and once with the asynchronous one, "
            "next to one vc_gym/Homing-v0 stepping alone (timed with the same actions before "
            "the first training and after each, in the same run; each training against the "
            "rounds either side of it), and their ratios (efficiency; target 0.7). The last "
            "line of --json output is one JSON object."
        ),
    )
    p.add_argument(
        "what",
        choices=["compass", "filters", "env", "trackers", "backends", "train"],
        help="what to benchmark",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    p.add_argument("--out", metavar="FILE", help="also save the JSON to FILE")
    p.add_argument("--frames", type=int, default=40, help="compass: distinct test frames")
    p.add_argument("--repeats", type=int, default=15, help="timed rounds (medians are reported)")
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
    p.set_defaults(func=_cmd_bench)

    p = sub.add_parser(
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
    _add_allow_imports_option(p, "the agent's config.json")
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
    p.add_argument("--learn-time", type=float, default=5.0, help="seconds per direction")
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
        choices=["paper", "improved"],
        default="paper",
        help="how the place is learned and the scripted agent homes: paper (default) or "
        "improved (as the demo: normalised at the true home, home checked with a full turn)",
    )
    _add_tracker_option(p)
    p.add_argument(
        "--out", default="vc_gym_homing", metavar="DIR", help="output folder (resumable)"
    )
    p.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    p.set_defaults(func=_cmd_evaluate)

    p = sub.add_parser(
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
        choices=_SceneChoices(),
        metavar="SCENE",
        help="scene to train in (default: robolab): %(choices)s",
    )
    p.add_argument("--learn-time", type=float, help="seconds per learning direction (default 5)")
    p.add_argument(
        "--places",
        type=_int_list,
        metavar="S,S,...",
        help="train over a pool of places: the learning seeds of the places, each learned "
        "once (DIR/atlas-place<s>.npz), every episode in one of them (default: the one "
        "place of --seed)",
    )
    p.add_argument(
        "--tracker",
        type=_tracker_spec,
        metavar="SPEC",
        help="tracker of the agent's env: grid (the paper's filters, default), particle, "
        "kalman, 'package.module:factory', or a JSON object such as "
        '\'{"type": "particle", "n_particles": 500}\'',
    )
    _add_allow_imports_option(p, "--config FILE and a --resume run's config.json")
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
        "home, not where the tracker puts home (DIR/home_offset.json; default 10; 0: the "
        "tracker's home, with --no-home-offset-centre)",
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
        "step per axis; the stops can move further than the goal did; default on; needs "
        "--home-offset-episodes of 1 or more)",
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
        type=_int_list,
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
    p.set_defaults(func=_cmd_train)

    p = sub.add_parser(
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
        choices=_SceneChoices("all"),
        metavar="SCENE",
        help="which scene (default: all, every registered scene): %(choices)s",
    )
    p.add_argument("--out", default="vc_gym_scenes", metavar="DIR", help="output folder")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--randomize", action="store_true", help="domain-randomised scene")
    p.set_defaults(func=_cmd_render)

    p = sub.add_parser(
        "soak",
        help="long-run health: steps/s over time, memory growth per 10k steps and per env",
        description=(
            "Step one vc_gym/AiboRoom-v0 for --steps steps with random actions (windows of "
            "--window steps: steps/s and resident memory), then make, reset, step and close "
            "--cycles envs; print the memory growth per 10,000 steps and per make/close "
            "cycle (target: within noise, <= 5 KB per cycle). Each memory sample is taken "
            "after the C allocator has given its free memory back (glibc malloc_trim), and "
            "the C heap in use (glibc mallinfo2) is printed too. Full run: about 15 min."
        ),
    )
    p.add_argument("--steps", type=int, default=50_000, help="steps of the long run")
    p.add_argument("--cycles", type=int, default=200, help="make/reset/step/close cycles")
    p.add_argument("--window", type=int, default=2_000, help="steps per measurement window")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", metavar="FILE", help="also write the figures as JSON to FILE")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_cmd_soak)

    p = sub.add_parser(
        "check",
        help="self-test: bad input, hostile files, faults and a short soak (< 5 min)",
        description=(
            "Run vc_gym's robustness cases: bad arguments and images, hostile map, model and "
            "settings files (zip bombs, pickled payloads, bit flips, deep nesting), the same "
            "misuse of every registered env (bad actions, resets, seeds, use after close), "
            "faults (killed workers, a lost physics server, a rerun of a finished run), then "
            "a short "
            "soak. Prints cases tried, passed and failed (0 expected) and the soak figures; "
            "the exit status is 1 if a case failed."
        ),
    )
    p.add_argument("--soak-steps", type=int, default=2_000, help="steps of the short soak")
    p.add_argument("--soak-cycles", type=int, default=30, help="make/close cycles of the soak")
    p.add_argument("--out", metavar="FILE", help="also write the report as JSON to FILE")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_cmd_check)

    from vc_gym.experiments.studies import EXPERIMENTS, SIZES

    def entry(name: str, text: str) -> str:
        return textwrap.fill(f"{name}: {text}", 88, subsequent_indent="    ")

    listing = "\n".join(entry(name, e.help) for name, e in EXPERIMENTS.items())
    p = sub.add_parser(
        "experiment",
        help="the paper's experiments, the tracker benchmark, and evaluations on real data",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            textwrap.fill(
                "Experiments split into independent jobs run by a backend (a local process "
                "pool or Ray) and saved as they finish: rerunning the same command in the "
                "same --out resumes an interrupted run. Each writes DIR/results.json (figures "
                "only: the same seed gives the same bytes on any backend), DIR/run.json "
                "(timings, jobs per second, backend, versions) and its plots. Learned atlases "
                "are saved in DIR/atlases and reused by every job.",
                88,
            )
            + "\n\n"
            + listing
            + "\n"
            + entry(
                "real-rotation",
                "learn from 9 alternate photos of a camera turning in place and estimate the "
                "yaw of crops of the other 9 (indoor and outdoor sets, 10 and 3 colour "
                "classes, exposure none/mean/map, crops at full and half light)",
            )
            + "\n"
            + entry(
                "synthetic-compass",
                "synthetic room and outdoor panoramas at normal and half illumination",
            )
        ),
    )
    p.add_argument(
        "name",
        choices=[*EXPERIMENTS, "real-rotation", "synthetic-compass"],
        help="which experiment",
    )
    p.add_argument("--out", metavar="DIR", help="output folder (default: vc_gym_NAME)")
    p.add_argument("--seed", type=int, default=0, help="base seed of every random draw")
    p.add_argument(
        "--quick", action="store_true", help="the small size the tests use (= --size quick)"
    )
    p.add_argument(
        "--size",
        choices=SIZES,
        help="quick (tests), paper (the report's size), full (default)",
    )
    p.add_argument("--backend", choices=["local", "ray"], default="local", help="who runs the jobs")
    p.add_argument(
        "--workers",
        type=int,
        help="local: worker processes (default 2; 1 runs in this process); ray: CPUs of "
        "the local Ray instance",
    )
    p.add_argument(
        "--address",
        metavar="ADDR",
        help="ray: join this running cluster ('auto', 'host:6379' or 'ray://host:10001') "
        "instead of starting a local instance",
    )
    p.add_argument("--atlas", metavar="DIR", help="reuse the saved atlases in DIR")
    p.add_argument(
        "--video", type=int, metavar="N", help="write the first N homing episodes as MP4"
    )
    p.add_argument(
        "--agent",
        metavar="scripted|pretrained|DIR/model.zip",
        help="homing, trackers: the agent (default scripted); agents: the agents to compare, "
        "comma-separated, scripted among them (default scripted,pretrained)",
    )
    _add_allow_imports_option(p, "homing, agents: a learned agent's config.json")
    p.add_argument(
        "--tracker",
        action="append",
        type=_tracker_spec,
        metavar="SPEC",
        help="the tracker (homing) or the trackers to compare (trackers; repeat the flag): "
        "grid, particle, kalman, 'package.module:factory' or a JSON object",
    )
    p.add_argument(
        "--sensor",
        metavar="NAME",
        help="homing: the grid tracker's heading sensor, learned in a turn at home for "
        "every learning seed (position still from the atlas): feature, image_difference, "
        "sector_colour, visual_compass, or magnetic (a magnetometer in the head; see "
        "`vc-gym experiment sensors`)",
    )
    p.add_argument(
        "--home-offset",
        type=_float_pair,
        metavar="X,Y",
        help="homing: the scripted agent's goal relative to the tracker's home, in metres "
        "(world frame), e.g. a learned agent's measured home_offset_m from its config.json; "
        "write --home-offset=-0.07,0.10 when X is negative (default 0,0: the paper's)",
    )
    p.add_argument("--episodes", type=int, help="kidnappings per learning seed (paper: 33)")
    p.add_argument(
        "--seeds", type=_int_list, metavar="S,S,...", help="learning seeds (default: --seed)"
    )
    p.add_argument(
        "--scenes", type=_str_list, metavar="NAME,...", help="scenes (default by experiment)"
    )
    p.add_argument("--learn-time", type=float, help="seconds per learning direction")
    p.add_argument("--max-homing", type=float, metavar="S", help="homing time limit")
    p.add_argument(
        "--mode",
        choices=["paper", "improved"],
        help="homing: paper (the paper's procedure, default) or improved (the spots "
        "normalised with the frames of the first turn at the true home; the scripted agent "
        "checks home with a full turn before it stops)",
    )
    p.add_argument(
        "--modes",
        type=_str_list,
        metavar="MODE,...",
        help="orientation, environments: paper (one spot, default) and/or improved (the same "
        "learning at every spot of a 1.0 m grid with exposure-normalised colours; heading "
        "from the best-fitting map), e.g. --modes paper,improved",
    )
    p.add_argument(
        "--light",
        type=float,
        metavar="L",
        help="orientation, environments: room illumination for the views, in (0, 1] "
        "(maps learned at full light; the paper's 5.3: 0.5)",
    )
    p.add_argument(
        "--data", metavar="DIR", help="real-rotation, sensors: folder of the real photo sets"
    )
    p.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    p.set_defaults(func=_cmd_experiment)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``vc-gym``; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except KeyboardInterrupt:  # Ctrl-C: one line, not a traceback
        print(f"vc-gym {args.command}: interrupted{_resume_hint(args)}", file=sys.stderr)
        return EXIT_INTERRUPTED
    except (ValueError, FileNotFoundError) as e:
        print(f"vc-gym {args.command}: error: {e}", file=sys.stderr)
        return 2
    except RuntimeError as e:  # a failure during the work (a dead worker, a fall, ...)
        print(f"vc-gym {args.command}: failed: {e}", file=sys.stderr)
        return 1


def _resume_hint(args: argparse.Namespace) -> str:
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
            from vc_gym.training.train import latest_checkpoint

            saved = latest_checkpoint(out) is not None
        except Exception:  # noqa: BLE001 - only a hint; the run is over either way
            saved = False
        if saved:
            return f"; 'vc-gym train --resume {out}' continues from its last checkpoint"
        return "; no checkpoint was saved to resume from (--save-freq N saves them)"
    return ""


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
