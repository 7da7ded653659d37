"""The ``vc-gym`` command: one module per sub-command, each adding its parser.

Every command module has ``add_parser(commands)``, which registers its sub-command
with ``func`` (the function that runs it) and, where an interrupted run can go on,
``hint`` (what to tell the user after Ctrl-C). The command modules are imported by
:func:`build_parser`, inside :func:`main`'s Ctrl-C handling: importing them takes a
few seconds, and Ctrl-C then still ends in one line, not a traceback.

SIGTERM (what ``timeout``, ``docker stop`` and systemd send) is heard like Ctrl-C: while
:func:`main` runs it raises :class:`Terminated`, a ``KeyboardInterrupt``, so every
command's Ctrl-C cleanup runs (temporary files removed, folders a refused or unfinished
run created removed again) and the command ends with one line and status 143.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import signal
import sys
from collections.abc import Iterator, Sequence
from types import FrameType

from vc_gym.cli.arguments import DefaultsFormatter, RawDescriptionDefaultsFormatter
from vc_gym.deprecation import moved_names

__all__ = ["COMMANDS", "EXIT_INTERRUPTED", "EXIT_TERMINATED", "Terminated", "build_parser", "main"]

#: Exit status after Ctrl-C (128 + SIGINT, as a shell reports it).
EXIT_INTERRUPTED = 130
#: Exit status after SIGTERM (128 + SIGTERM).
EXIT_TERMINATED = 143


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived while a command ran: raised where Ctrl-C's ``KeyboardInterrupt``
    would be, so that the same cleanup runs."""


#: The command modules of :mod:`vc_gym.cli`, in the order ``vc-gym --help`` lists them.
COMMANDS = (
    "demo",
    "bench",
    "evaluate",
    "train",
    "render",
    "soak",
    "check",
    "experiment",
    "compass",
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
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        importlib.import_module(f"{__name__}.{name}").add_parser(commands)
    _remember_parsers(parser)
    return parser


def _remember_parsers(parser: argparse.ArgumentParser) -> None:
    """Let every (sub-)command's namespace know its own parser, so that an unknown flag
    is reported with that command's usage, not the top level's; and let each show its
    options' defaults in ``--help``."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                sub.set_defaults(parser=sub)
                raw = issubclass(sub.formatter_class, argparse.RawDescriptionHelpFormatter)
                sub.formatter_class = RawDescriptionDefaultsFormatter if raw else DefaultsFormatter
                _remember_parsers(sub)


@contextlib.contextmanager
def _sigterm_as_interrupt() -> Iterator[None]:
    """Raise :class:`Terminated` on SIGTERM in this process while the block runs.

    Only in the main thread (where Python delivers signals). A process forked from this
    one (a worker) that gets SIGTERM dies of it as before: the handler re-sends the
    signal with its default action there.
    """
    owner = os.getpid()

    def handler(signum: int, frame: FrameType | None) -> None:
        if os.getpid() != owner:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
            return
        raise Terminated()

    try:
        previous = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread: signals cannot be handled here
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``vc-gym``; returns the exit status."""
    args = argparse.Namespace(command=None)
    try:
        with _sigterm_as_interrupt():
            parser = build_parser()
            args, unknown = parser.parse_known_args(argv)
            if unknown:
                getattr(args, "parser", parser).error(
                    f"unrecognized arguments: {' '.join(unknown)}"
                )
            # the command line as typed, for the pages that say how their figures were made
            args.argv = list(sys.argv[1:] if argv is None else argv)
            return int(args.func(args))
    except Terminated:  # SIGTERM: the same cleanup as Ctrl-C, then one line
        hint = args.hint(args) if getattr(args, "hint", None) else ""
        print(f"{_prog(args)}: terminated (SIGTERM){hint}", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:  # Ctrl-C: one line, not a traceback
        hint = args.hint(args) if getattr(args, "hint", None) else ""
        print(f"{_prog(args)}: interrupted{hint}", file=sys.stderr)
        return EXIT_INTERRUPTED
    except (ValueError, FileNotFoundError) as e:
        print(f"{_prog(args)}: error: {e}", file=sys.stderr)
        return 2
    except RuntimeError as e:  # a failure during the work (a dead worker, a fall, ...)
        print(f"{_prog(args)}: failed: {e}", file=sys.stderr)
        return 1


def _prog(args: argparse.Namespace) -> str:
    return f"vc-gym {args.command}" if getattr(args, "command", None) else "vc-gym"


#: Constants this package exported, now in the module of what they bound.
_MOVED = {"MAX_BENCH_REPEATS": "vc_gym.cli.bench", "MAX_VIDEOS": "vc_gym.experiments.options"}


def __getattr__(name: str) -> object:
    # imported on first use: the command modules stay out of ``import vc_gym.cli``
    if name not in _MOVED:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return moved_names(__name__, {name: importlib.import_module(_MOVED[name])})(name)
