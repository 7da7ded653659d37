"""Parse a docs block's ``vc-gym`` command lines with vc-gym's own parser, without running them.

The stand-in of a block whose commands take minutes (``<!-- test: parse -->`` above it,
see code_blocks.py): every flag and value the reader is shown must be one the command
accepts, checked in this process rather than by starting ``vc-gym`` once per line.
"""

from __future__ import annotations

import contextlib
import io
import shlex

from vc_gym.cli import build_parser


def command_lines(text: str) -> list[list[str]]:
    """The commands of a bash block: continuation lines joined, comments dropped."""
    joined = text.replace("\\\n", " ")
    return [argv for line in joined.splitlines() if (argv := shlex.split(line, comments=True))]


def check(text: str) -> int:
    """Parse every command of ``text``; raise ``AssertionError`` naming the first that is
    not a ``vc-gym`` command or that its parser refuses. Returns how many were parsed."""
    commands = command_lines(text)
    assert commands, "the block holds no command"
    parser = build_parser()
    for argv in commands:
        line = shlex.join(argv)
        assert argv[0] == "vc-gym", f"not a vc-gym command: {line}"
        err = io.StringIO()
        try:
            with contextlib.redirect_stderr(err):
                _, unknown = parser.parse_known_args(argv[1:])
        except SystemExit as exc:
            raise AssertionError(f"{line}: {err.getvalue().strip()}") from exc
        assert not unknown, f"{line}: unrecognized arguments {unknown}"
    return len(commands)
