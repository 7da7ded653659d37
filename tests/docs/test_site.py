"""The documentation site builds with ``mkdocs build --strict``: every page in the nav,
every link resolving, every API page rendered from the docstrings."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_site_builds_strict(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path)],
        cwd=ROOT,
        env=dict(os.environ, NO_MKDOCS_2_WARNING="1"),
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr[-6000:]
    assert (tmp_path / "api" / "compass" / "index.html").is_file()
    assert "VisualCompass" in (tmp_path / "api" / "compass" / "index.html").read_text()
