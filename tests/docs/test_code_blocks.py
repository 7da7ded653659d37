"""Every ```python and ```bash block of README.md and docs/ runs (see code_blocks.py)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from code_blocks import ROOT, code_blocks, is_slow, pages

HERE = Path(__file__).parent


def _params() -> list:
    params = []
    for page in pages():
        text = page.read_text(encoding="utf-8")
        if not code_blocks(text):
            continue
        marks = [pytest.mark.slow] if is_slow(text) else []
        params.append(pytest.param(page, id=str(page.relative_to(ROOT)), marks=marks))
    return params


@pytest.mark.parametrize("page", _params())
def test_page_code_runs(page: Path, tmp_path: Path) -> None:
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(ROOT), DOCS_TOOLS=str(HERE))
    env.setdefault("VC_GYM_REAL_DATA", str(ROOT.parent / "shared" / "data" / "real"))
    done = subprocess.run(
        [sys.executable, str(HERE / "run_blocks.py"), str(page)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]


def test_blocks_are_parsed_with_their_stand_ins() -> None:
    text = (
        "intro\n<!-- test-with: echo small -->\n```bash\nvc-gym experiment paper\n```\n"
        "<!-- test-setup: touch in.mp4 -->\n```bash\nls in.mp4\n```\n"
        "```python\nx = 1\n```\n```text\nnot run\n```\n  ```python\n  y = x\n  ```\n"
    )
    blocks = code_blocks(text)
    assert [(b.lang, b.code) for b in blocks] == [
        ("bash", "echo small\n"),
        ("bash", "touch in.mp4\nls in.mp4\n"),
        ("python", "x = 1\n"),
        ("python", "y = x\n"),
    ]
    with pytest.raises(ValueError, match="test directive before a python block"):
        code_blocks("<!-- test-with: echo -->\n```python\nx = 1\n```\n")
    with pytest.raises(ValueError, match="unclosed"):
        code_blocks("```python\nx = 1\n")


def test_a_parsed_block_checks_every_flag_it_shows() -> None:
    from parse_commands import check

    blocks = code_blocks("<!-- test: parse -->\n```bash\nvc-gym demo --seed 3  # one\n```\n")
    assert blocks[0].lang == "python" and "parse_commands" in blocks[0].code
    shown = "vc-gym experiment homing --out r --seeds 0,1 \\\n    --mode check-home\nvc-gym demo\n"
    assert check(shown) == 2
    with pytest.raises(AssertionError, match="--no-such-flag"):
        check("vc-gym demo --no-such-flag 1\n")
    with pytest.raises(AssertionError, match="invalid choice"):
        check("vc-gym experiment nosuch --out r\n")
    with pytest.raises(AssertionError, match="not a vc-gym command"):
        check("python -c pass\n")
    with pytest.raises(ValueError, match="no other directive"):
        code_blocks("<!-- test-setup: touch x -->\n<!-- test: parse -->\n```bash\nvc-gym\n```\n")


def test_a_failing_block_fails_the_page(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("```python\nx = 1\n```\n```bash\ntest -f missing\n```\n")
    done = subprocess.run(
        [sys.executable, str(HERE / "run_blocks.py"), str(page)],
        cwd=tmp_path, capture_output=True, text=True,
    )
    assert done.returncode == 1 and "page.md:4 (bash)" in done.stderr
