"""``vc-gym check``: the end-to-end self-test (hostile files, env misuse, faults, soak)."""

from __future__ import annotations

import argparse
import json

from vc_gym.jobs.output import write_json
from vc_gym.validation import int_in_range

__all__ = ["add_parser", "run"]


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add ``check`` to the ``vc-gym`` commands."""
    p = commands.add_parser(
        "check",
        help="self-test: hostile files, env misuse, faults and a short soak (< 5 min)",
        description=(
            "Run vc_gym's end-to-end robustness cases on this machine: hostile map, model, "
            "job and settings files (zip bombs, pickled payloads, bit flips, deep nesting, "
            "code named in a file), the same misuse of every registered env (bad actions, "
            "resets, seeds, use after close), faults (killed workers, a lost physics server, "
            "a rerun of a finished run), commands asked for more than the machine has, "
            "footage commands that would replace their input or an earlier output, scale "
            "past the pixel limit, read truncated frames or get SIGTERM, then a short soak. "
            "Prints cases tried, passed and failed (0 expected) and the soak "
            "figures; the exit status is 1 if a case failed. The checks of single functions' "
            "arguments are in the unit tests."
        ),
    )
    p.add_argument("--soak-steps", type=int, default=2_000, help="steps of the short soak")
    p.add_argument("--soak-cycles", type=int, default=30, help="make/close cycles of the soak")
    p.add_argument("--out", metavar="FILE", help="also write the report as JSON to FILE")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from vc_gym.cli import main
    from vc_gym.experiments.benchmarks.soak import MAX_SOAK_STEPS, MIN_WINDOW, check_soak_args
    from vc_gym.experiments.check import all_cases, run_check
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
    cases = all_cases(main)  # the footage suite runs its commands in this process
    r = run_check(args.soak_steps, args.soak_cycles, progress=not args.json, cases=cases)
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
