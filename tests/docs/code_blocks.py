"""The fenced code blocks of the README and the docs pages, as the tests run them.

A page's ```python and ```bash blocks run in page order, in one fresh folder, the
Python ones in one namespace (a later block may use what an earlier one made). A bash
block preceded by the line ``<!-- test-with: COMMAND -->`` runs ``COMMAND`` instead: a
small stand-in for a command that takes minutes or installs the package; a block
preceded by ``<!-- test-setup: COMMAND -->`` runs ``COMMAND`` (bash) first, to make
the input files a reader would bring (e.g. a video). A bash block preceded by
``<!-- test: parse -->`` is not run: each of its ``vc-gym`` command lines is parsed by
vc-gym's own parser (parse_commands.py), so every flag it shows is checked in one
process. A page with
the line ``<!-- test: slow -->`` is left out of ``pytest -m "not slow"``. Other blocks
(``text``, ``json``, ``yaml``) show output or file contents and are not run.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RUN_LANGS = ("python", "bash")
_FENCE = re.compile(r"^(?P<indent> *)```(?P<lang>[\w-]*)[^\n]*$")
_DIRECTIVE = re.compile(r"^\s*<!--\s*test-(?P<kind>with|setup):\s*(?P<cmd>.+?)\s*-->\s*$")
_PARSE = re.compile(r"^\s*<!--\s*test:\s*parse\s*-->\s*$")
SLOW_MARK = "<!-- test: slow -->"


@dataclass(frozen=True)
class Block:
    """One fenced block: its language, its code and the line it starts on."""

    lang: str
    code: str
    line: int


def pages() -> list[Path]:
    """README.md and every Markdown page under docs/, sorted."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def code_blocks(text: str) -> list[Block]:
    """The runnable blocks of a Markdown text, a bash block replaced by its stand-in."""
    lines = text.splitlines()
    blocks: list[Block] = []
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, lang, start = m["indent"], m["lang"], i
        end = next(
            (j for j in range(i + 1, len(lines)) if lines[j].strip() == "```"
             and lines[j].startswith(indent)),
            None,
        )
        if end is None:
            raise ValueError(f"unclosed code block at line {start + 1}")
        body = "\n".join(ln[len(indent):] for ln in lines[start + 1 : end]) + "\n"
        if lang in RUN_LANGS:
            directives = _directives(lines, start)
            if directives and lang != "bash":
                raise ValueError(f"test directive before a {lang} block at line {start + 1}")
            if "parse" in directives:  # the block's commands parsed, in this process
                if set(directives) != {"parse"}:
                    raise ValueError(f"test: parse takes no other directive (line {start + 1})")
                lang, body = "python", f"import parse_commands\nparse_commands.check({body!r})\n"
            if "with" in directives:
                body = directives["with"] + "\n"
            if "setup" in directives:
                body = directives["setup"] + "\n" + body
            blocks.append(Block(lang, body, start + 1))
        i = end + 1
    return blocks


def _directives(lines: list[str], fence: int) -> dict[str, str]:
    """The ``test-with``/``test-setup``/``test: parse`` comments on the lines right
    above a fence."""
    found: dict[str, str] = {}
    i = fence - 1
    while i >= 0:
        if m := _DIRECTIVE.match(lines[i]):
            found[m["kind"]] = m["cmd"]
        elif _PARSE.match(lines[i]):
            found["parse"] = ""
        else:
            break
        i -= 1
    return found


def is_slow(text: str) -> bool:
    """Whether the page marks itself slow."""
    return SLOW_MARK in text
