"""``vc-gym experiment NAME``: every registered experiment through one path.

Each experiment of :data:`~vc_gym.experiments.studies.EXPERIMENTS` gets its own
sub-command whose flags are the ones its registry entry declares, so
``vc-gym experiment NAME --help`` shows only what that experiment takes.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import shlex
import sys
import textwrap
from pathlib import Path
from typing import Any

from vc_gym.cli.arguments import add_json_option, add_option
from vc_gym.experiments.results_page import PageInfo, check_page_path, seeds_text, write_page
from vc_gym.experiments.studies import EXPERIMENTS, SIZES, Experiment
from vc_gym.validation import check_seed

__all__ = ["add_parser", "resume_hint", "run", "run_experiment"]

_DESCRIPTION = (
    "Experiments split into independent jobs run by a backend (a local process pool or "
    "Ray) and saved as they finish: rerunning the same command in the same --out resumes "
    "an interrupted run. Each writes DIR/results.json (figures only: the same seed gives "
    "the same bytes on any backend), DIR/run.json (timings, jobs per second, backend, "
    "versions) and its plots. Learned atlases are saved in DIR/atlases and reused by every "
    "job. 'vc-gym experiment NAME --help' lists an experiment's own options."
)


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add ``experiment`` and one sub-command per registered experiment."""
    listing = "\n".join(
        textwrap.fill(f"{name}: {e.help}", 88, subsequent_indent="    ")
        for name, e in EXPERIMENTS.items()
    )
    p = commands.add_parser(
        "experiment",
        help="the paper's experiments, the tracker benchmark, and evaluations on real data",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=textwrap.fill(_DESCRIPTION, 88) + "\n\n" + listing,
    )
    names = p.add_subparsers(
        dest="name", metavar="NAME", required=True, help="which experiment (listed above)"
    )
    for experiment in EXPERIMENTS.values():
        _add_experiment_parser(names, experiment)


def _add_experiment_parser(names: argparse._SubParsersAction, e: Experiment) -> None:
    p = names.add_parser(e.name, description=e.help)
    p.add_argument("--out", metavar="DIR", help=f"output folder (default: {_default_out(e.name)})")
    p.add_argument("--seed", type=int, default=0, help="base seed of every random draw")
    if e.jobs:
        p.add_argument(
            "--quick", action="store_true", help="the small size the tests use (= --size quick)"
        )
        p.add_argument(
            "--size", choices=SIZES, help="quick (tests), paper (the report's size), full (default)"
        )
        p.add_argument(
            "--backend", choices=["local", "ray"], default="local", help="who runs the jobs"
        )
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
    for option in e.options:
        add_option(p, option)
    p.add_argument(
        "--page",
        metavar="FILE.md",
        help="also write the results page of the docs (e.g. docs/results/"
        f"{e.name}.md): command, version and commit, date, machine, seeds, figures, plots",
    )
    add_json_option(p)
    p.set_defaults(func=run, hint=resume_hint)


def _default_out(name: str) -> str:
    return f"vc_gym_{name.replace('-', '_')}"


def run(args: argparse.Namespace) -> int:
    """Run ``vc-gym experiment NAME`` with the options given on the command line."""
    e = EXPERIMENTS[args.name]
    options = {
        o.parameter: getattr(args, o.parameter)
        for o in e.options
        if getattr(args, o.parameter) is not None
    }
    return run_experiment(
        e,
        options,
        command=args.command,
        out=args.out,
        seed=args.seed,
        size="quick" if getattr(args, "quick", False) else (getattr(args, "size", None) or "full"),
        backend=getattr(args, "backend", "local"),
        workers=getattr(args, "workers", None),
        address=getattr(args, "address", None),
        json_output=args.json,
        page=args.page,
        command_line="vc-gym " + shlex.join(getattr(args, "argv", [])),
    )


def run_experiment(
    e: Experiment,
    options: dict[str, Any],
    *,
    command: str,
    out: str | None,
    seed: int,
    size: str = "full",
    backend: str = "local",
    workers: int | None = None,
    address: str | None = None,
    json_output: bool = False,
    page: str | None = None,
    command_line: str = "",
) -> int:
    """Check every argument, run experiment ``e`` in ``out`` and print what it found.

    ``options`` maps the parameters of ``e``'s declared options to their values (those
    marked ``to_options`` go to :class:`ExperimentOptions`, the rest to the runner).
    With ``page``, also writes that results page
    (:func:`~vc_gym.experiments.results_page.write_page`; ``command_line`` is the
    command it names). Returns the exit status: 1 if jobs failed, else 0.
    """
    from vc_gym.experiments.studies import ExperimentOptions
    from vc_gym.jobs.backends import make_backend
    from vc_gym.jobs.output import new_out_dir, read_json
    from vc_gym.jobs.workers import check_workers

    # every flag's bounds before the folder is made and any worker starts; the
    # experiment checks its settings again (and what only it knows) before its first job
    check_seed("--seed", seed)
    if page is not None:
        check_page_path(page)
    if workers is not None:
        check_workers(workers, "--workers")
    declared = {o.parameter: o for o in e.options}
    for name, value in options.items():
        option = declared.get(name)
        if option is not None and option.check is not None:
            option.check(option.flag, value)
    shared = {n: v for n, v in options.items() if n in declared and declared[n].to_options}
    given = {n: v for n, v in options.items() if n not in shared}
    running = make_backend(backend, workers, address) if e.jobs else contextlib.nullcontext()
    with new_out_dir(out or _default_out(e.name)) as folder, running as pool:
        opts = ExperimentOptions(
            seed=seed, size=size, backend=pool, progress=not json_output, **shared
        )
        results = e.runner()(folder, opts, **given)
    if json_output:
        print(json.dumps({k: v for k, v in results.items() if k != "per_episode"}))
    else:
        for line in e.summary_lines(results):
            print(line)
        run_json = folder / "run.json"
        for line in e.cost_lines(read_json(run_json) if run_json.is_file() else {}):
            print(line)
        print(_written(folder))
    failed = results.get("failed_jobs") or []
    if page is not None and not failed:
        written = write_page(
            page,
            PageInfo(
                title=f"`vc-gym {command if command != 'experiment' else 'experiment ' + e.name}`",
                command=command_line or f"vc-gym experiment {e.name} --page {page}",
                description=e.help,
                seeds=seeds_text(results, seed),
            ),
            e.summary_lines(results),
            {k: v for k, v in results.items() if k != "per_episode"},
            sorted(folder.glob("*.png")),
        )
        if not json_output:
            print(f"wrote the results page {written}")
    if failed:
        print(
            f"vc-gym {command}: failed: {len(failed)} job(s) failed twice, e.g. "
            f"{failed[0]['stage']}/{failed[0]['key']}: {failed[0]['error']} (all in "
            f"{folder / 'results.json'}; rerun the same command to retry them)",
            file=sys.stderr,
        )
        return 1
    return 0


def _written(folder: Path) -> str:
    files = [str(folder / "results.json")]
    if (folder / "run.json").is_file():
        files.append(str(folder / "run.json"))
    if any(folder.glob("*.png")):
        return f"wrote {', '.join(files)} and the plots in {folder}"
    return f"wrote {' and '.join(files)}"


def resume_hint(args: argparse.Namespace) -> str:
    """After Ctrl-C: how to resume a job-based experiment (``""`` for the others)."""
    name = getattr(args, "name", "homing")
    if not EXPERIMENTS[name].jobs:
        return ""  # no jobs: it starts over
    out = args.out or _default_out(name)
    return f"; rerun the same command to resume from the jobs saved in {out}"
