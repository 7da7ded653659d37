"""The README as a newcomer meets it: short, its quick start intact, its links live, and
its headline figures the ones the results pages (written by the commands) hold."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")
QUICK_START = [
    "pip install -e . && vc-gym demo",
    'pip install -e ".[dev]" && pytest',
]
_LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")
_NUMBER = re.compile(r"[-−+]?\d+(?:[.,]\d+)*")


def test_readme_is_short() -> None:
    assert len(README.splitlines()) <= 250


def test_quick_start_is_the_first_bash_block() -> None:
    first = README.split("```bash\n", 1)[1].split("```", 1)[0].splitlines()
    assert first == QUICK_START


@pytest.mark.parametrize("target", sorted(set(_LINK.findall(README))))
def test_every_relative_link_resolves(target: str) -> None:
    if target.startswith(("http://", "https://")):
        pytest.skip("external link")
    assert (ROOT / target).exists(), target


def _headline_rows() -> list:
    """(label, figures, page) of every row of the README's headline table and of the
    results index, the page resolved from the row's link."""
    rows = []
    section = README.split("## Results", 1)[1].split("\n## ", 1)[0]
    index = ROOT / "docs" / "results" / "index.md"
    for text, base, figures_at, link_at in (
        (section, ROOT, 1, 2),
        (index.read_text(encoding="utf-8"), index.parent, 1, 2),
    ):
        for line in text.splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) < 3 or not _LINK.search(cells[link_at]):
                continue
            page = base / _LINK.search(cells[link_at]).group(1)
            rows.append(pytest.param(cells[figures_at], page, id=f"{page.name}:{cells[0][:30]}"))
    return rows


def test_the_headline_tables_have_rows() -> None:
    assert len(_headline_rows()) >= 10


@pytest.mark.parametrize(("figures", "page"), _headline_rows())
def test_headline_figures_are_on_their_page(figures: str, page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    on_page = set(_NUMBER.findall(text.replace("−", "-")))
    missing = [n for n in _NUMBER.findall(figures.replace("−", "-")) if n not in on_page]
    assert not missing, f"{page.name} does not hold {missing}"
