"""A results page of the documentation, written by the command that measured it.

``vc-gym experiment NAME --page docs/results/NAME.md`` (and ``vc-gym bench NAME --page``)
write a Markdown page holding everything a reader needs to trust and repeat the figures:
the command, the package version and commit, the date, the machine, the seeds, the
figures as the command printed them, and the plots. The plots and ``results.json`` are
copied into a folder beside the page (``docs/results/NAME/``), so the page is whole
without the run folder. No figure on such a page is typed by hand. A page may end with a
hand-written ``## Discussion`` section (what the figures mean, why); rewriting the page
keeps it.
"""

from __future__ import annotations

import os
import platform
import shutil
import subprocess
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import vc_gym
from vc_gym.jobs.output import check_out_file, write_json, write_text

__all__ = [
    "DISCUSSION",
    "WRITTEN_BY",
    "PageInfo",
    "check_page_path",
    "machine_description",
    "seeds_text",
    "source_commit",
    "write_page",
]

#: The line every written page starts its provenance table with (tests look for it).
WRITTEN_BY = "Written by the command below; regenerate it by running that command again."
#: The heading of the hand-written part of a page, kept when the page is rewritten.
DISCUSSION = "## Discussion"


@dataclass(frozen=True)
class PageInfo:
    """What a results page says about where its figures come from.

    Attributes
    ----------
    title : str
        The page's heading.
    command : str
        The command line that made the figures (as typed, ``--page`` included).
    description : str
        One paragraph: what the command measures.
    seeds : str
        The seeds the figures are over, in words (e.g. ``"learning seeds 0, 1, 2"``).
    """

    title: str
    command: str
    description: str
    seeds: str


def check_page_path(path: str | os.PathLike, flag: str = "--page") -> Path:
    """Check a page's path before any work: a ``.md`` file whose folder can be written."""
    page = Path(path)
    if page.suffix != ".md":
        raise ValueError(f"{flag} must name a Markdown file (.md), got {str(path)!r}")
    return check_out_file(page, flag)


def source_commit(package_dir: Path | None = None) -> str:
    """The git commit the package runs from (``"abc1234"``, ``"abc1234+changes"`` when
    the tree has uncommitted changes), or ``"not a git checkout"``."""
    folder = package_dir or Path(vc_gym.__file__).resolve().parent

    def git(*args: str) -> str | None:
        try:
            done = subprocess.run(
                ["git", "-C", str(folder), *args], capture_output=True, text=True, timeout=10
            )
        except (OSError, subprocess.TimeoutExpired):
            return None
        return done.stdout.strip() if done.returncode == 0 else None

    commit = git("rev-parse", "--short=10", "HEAD")
    if not commit:
        return "not a git checkout"
    changed = git("status", "--porcelain", "--untracked-files=no", "--", ".")
    return f"{commit}+changes" if changed else commit


def machine_description() -> str:
    """The machine in one line: CPU model, cores, OS, Python."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return (
        f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}, "
        f"Python {platform.python_version()}"
    )


def write_page(
    page: str | os.PathLike,
    info: PageInfo,
    summary: Sequence[str],
    results: Mapping[str, Any],
    plots: Iterable[str | os.PathLike] = (),
) -> Path:
    """Write the results page ``page`` and its folder of plots and ``results.json``.

    Parameters
    ----------
    page : path-like
        The page to write (``docs/results/NAME.md``); its assets go to ``NAME/`` beside
        it (emptied first, so no plot of an earlier run stays). The ``## Discussion``
        section of an existing page is kept.
    info : PageInfo
        Title, command, description and seeds.
    summary : sequence of str
        The figures as the command prints them (shown as a text block).
    results : mapping
        The command's ``results.json`` content (copied beside the page and linked).
    plots : iterable of path-like
        PNG files to copy beside the page and show on it, in order.

    Returns
    -------
    pathlib.Path
        The page written.
    """
    page = check_page_path(page)
    discussion = _discussion(page)
    assets = page.with_suffix("")
    if assets.exists():
        shutil.rmtree(assets)
    assets.mkdir(parents=True)
    write_json(assets / "results.json", dict(results))
    shown = []
    for plot in plots:
        plot = Path(plot)
        shutil.copyfile(plot, assets / plot.name)
        shown.append(plot.name)
    rel = assets.name
    lines = [
        f"# {info.title}",
        "",
        info.description[:1].upper() + info.description[1:],
        "",
        f"*{WRITTEN_BY}*",
        "",
        "| | |",
        "|---|---|",
        f"| command | `{info.command}` |",
        f"| vc_gym | {vc_gym.__version__}, commit {source_commit()} |",
        f"| date | {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} |",
        f"| machine | {machine_description()} |",
        f"| seeds | {info.seeds} |",
        f"| figures | [`results.json`]({rel}/results.json) |",
        "",
        "## Figures",
        "",
        "```text",
        *summary,
        "```",
    ]
    if shown:
        lines += ["", "## Plots", ""]
        for name in shown:
            lines += [f"![{Path(name).stem}]({rel}/{name})", ""]
    if discussion:
        lines += ["", discussion]
    write_text(page, "\n".join(lines).rstrip() + "\n")
    return page


def _discussion(page: Path) -> str:
    """The hand-written ``## Discussion`` section of an existing page ("" if none)."""
    if not page.is_file():
        return ""
    text = page.read_text(encoding="utf-8")
    at = text.find("\n" + DISCUSSION + "\n")
    return text[at + 1 :].rstrip() if at >= 0 else ""


def seeds_text(results: Mapping[str, Any], base_seed: int) -> str:
    """The seeds a run's figures are over: its ``seeds`` (or ``learning_seeds``) figure
    when it has one, else the base seed every draw derives from."""
    for key in ("learning_seeds", "seeds"):
        seeds = results.get(key)
        if isinstance(seeds, list) and seeds and all(isinstance(s, int) for s in seeds):
            return f"{key.replace('_', ' ')} {', '.join(map(str, seeds))}"
    return f"base seed {base_seed} (every draw derives from it)"

