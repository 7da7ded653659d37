"""``vc-gym soak``: long-run health (speed over time, memory growth)."""

from __future__ import annotations

import argparse
import json

from vc_gym.jobs.output import write_json

__all__ = ["add_parser", "run"]


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add ``soak`` to the ``vc-gym`` commands."""
    p = commands.add_parser(
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
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
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
