"""Argument helpers shared by the ``vc-gym`` commands."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Iterator
from typing import Any

from vc_gym.experiments.options import Option, parse_tracker_spec

__all__ = [
    "DefaultsFormatter",
    "RawDescriptionDefaultsFormatter",
    "SceneChoices",
    "add_allow_imports_option",
    "add_json_option",
    "add_option",
    "add_tracker_option",
    "argument_type",
]


def argument_type(parse: Callable[[str], Any], name: str) -> Callable[[str], Any]:
    """``parse`` as an argparse ``type``: its ``ValueError`` message becomes the usage
    error (``argparse`` would otherwise print only ``invalid <name> value``)."""

    def convert(text: str) -> Any:
        try:
            return parse(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    convert.__name__ = name
    return convert


def add_option(parser: argparse.ArgumentParser, option: Option) -> None:
    """Add an experiment's :class:`~vc_gym.experiments.options.Option` to ``parser``
    (default ``None``: an option not given leaves the experiment's own default)."""
    kwargs: dict[str, Any] = {"dest": option.parameter, "default": None, "help": option.help}
    if option.switch:
        kwargs.update(action="store_const", const=True)
    else:
        if option.parse is not None:
            kwargs["type"] = argument_type(option.parse, option.flag.lstrip("-"))
        if option.choices is not None:
            kwargs["choices"] = option.choices
        if option.metavar is not None:
            kwargs["metavar"] = option.metavar
        if option.repeat:
            kwargs["action"] = "append"
    parser.add_argument(option.flag, **kwargs)


def add_tracker_option(parser: argparse.ArgumentParser) -> None:
    """``--tracker SPEC``; default the homing mode's (``grid``; ``pose-grid`` for
    ``pose-home``)."""
    parser.add_argument(
        "--tracker",
        default=None,
        type=argument_type(parse_tracker_spec, "tracker"),
        metavar="SPEC",
        help=(
            "what turns frames and odometry into the pose estimate: grid (the paper's heading "
            "grid + translational filter; the default, pose-grid with --mode pose-home), "
            "particle, kalman, pose, pose-grid, "
            "'package.module:factory' (your own tracker class or factory), or a JSON "
            'object such as \'{"type": "particle", "n_particles": 2000}\''
        ),
    )


def add_allow_imports_option(parser: argparse.ArgumentParser, what: str) -> None:
    """``--allow-imports``: let ``what`` name plug-ins by import path."""
    parser.add_argument(
        "--allow-imports",
        action="store_true",
        help=(
            f"let {what} name plug-ins by import path ('package.module:factory'), which "
            "imports and runs that code; without it a file may name only registered "
            "plug-ins. Only for files you trust"
        ),
    )


def add_json_option(parser: argparse.ArgumentParser, text: str = "") -> None:
    """``--json``: print one JSON object (as the last line)."""
    parser.add_argument(
        "--json", action="store_true", help=text or "print one JSON object as the last line"
    )


class SceneChoices:
    """``choices`` for a ``--scene`` option: ``extra`` and the registered scene names.

    Read from the scene registry only when argparse checks or lists them, so that
    ``vc-gym --help`` and commands without ``--scene`` do not import PyBullet. A scene
    registered in this process before :func:`vc_gym.cli.main` runs is accepted too.
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


class DefaultsFormatter(argparse.HelpFormatter):
    """Help that shows each option's default where it has a value of its own and its
    text does not already say it (``None``, ``False`` and ``--help`` add nothing)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        default = action.default
        if (
            action.option_strings
            and not any(default is v for v in (None, False, argparse.SUPPRESS))
            and "default" not in text.lower()
            and "%(default)" not in text
        ):
            text += " (default: %(default)s)"
        return text


class RawDescriptionDefaultsFormatter(argparse.RawDescriptionHelpFormatter, DefaultsFormatter):
    """:class:`DefaultsFormatter` keeping the description's own line breaks."""
