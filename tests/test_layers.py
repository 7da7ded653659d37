"""Layers point one way: every import in the package, lazy ones included, is checked.

The order (docs/design.md): the base helpers, then ``compass``, ``filters``,
``localization``, ``heading_sensors`` (and its deprecated alias ``baselines``), ``worlds``,
``sim`` (the PyBullet world), ``envs`` (the tasks), ``jobs`` (the job runner), ``training``,
``agents``, ``experiments``, ``hyperparams`` (the RL Zoo's settings), ``cli``. A module may
import only its own layer and the layers before it; ``compass`` and ``filters`` never
import each other (``localization`` joins them).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import vc_gym

PACKAGE = Path(vc_gym.__file__).parent
BASE = {
    "angles",
    "images",
    "validation",
    "persistence",
    "config_files",
    "deprecation",
    "errors",
    "exposure",
    "plugins",
    "poses",
}
ORDER = [
    "base",
    "compass",
    "filters",
    "localization",
    "heading_sensors",
    "baselines",
    "worlds",
    "sim",
    "envs",
    "jobs",
    "training",
    "agents",
    "experiments",
    "hyperparams",
    "cli",
]
#: pairs (importer, imported) that are forbidden even though the order allows them
APART = {("filters", "compass")}


def layer_of(module: str) -> str | None:
    """Layer of a dotted ``vc_gym...`` module name (``None`` for the package root)."""
    parts = module.split(".")
    if parts[0] != "vc_gym":
        raise ValueError(module)
    if len(parts) == 1:
        return None
    return "base" if parts[1] in BASE else parts[1]


def imports_of(path: Path, root: Path) -> list[tuple[int, str]]:
    """Every ``vc_gym`` module imported anywhere in ``path`` (with its line).

    ``root`` is the folder that holds the ``vc_gym`` package (relative imports are
    resolved against the module's place under it).
    """
    parts = path.relative_to(root).with_suffix("").parts
    package = parts[:-1]
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = list(package[: len(package) - node.level + 1])
                names = [".".join(base + ([node.module] if node.module else []))]
            else:
                names = [node.module or ""]
        else:
            continue
        found += [(node.lineno, n) for n in names if n.split(".")[0] == "vc_gym"]
    return found


MODULES = sorted(PACKAGE.rglob("*.py"))


def violations(path: Path, root: Path = PACKAGE.parent) -> list[str]:
    """The imports of ``path`` that point the wrong way, as readable lines."""
    rel = path.relative_to(root).with_suffix("")
    me = layer_of(".".join(rel.parts if rel.name != "__init__" else rel.parts[:-1]))
    if me is None:
        return []
    out = []
    for line, name in imports_of(path, root):
        other = layer_of(name)
        if other is None or other == me:
            continue
        if other not in ORDER or me not in ORDER:
            out.append(f"{rel}:{line} {name}: unknown layer ({me} -> {other})")
        elif ORDER.index(other) > ORDER.index(me) or (me, other) in APART:
            out.append(f"{rel}:{line} imports {name} ({me} -> {other})")
    return out


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_imports_point_one_way(path):
    assert violations(path) == []


def test_the_checker_catches_wrong_imports(tmp_path):
    compass = tmp_path / "vc_gym" / "compass"
    compass.mkdir(parents=True)
    lazy = compass / "probe.py"
    lazy.write_text("def f():\n    from vc_gym.localization import GridTracker\n")
    assert violations(lazy, tmp_path) == [
        "vc_gym/compass/probe:2 imports vc_gym.localization (compass -> localization)"
    ]
    filters = tmp_path / "vc_gym" / "filters"
    filters.mkdir()
    relative = filters / "probe.py"
    relative.write_text("import numpy\nfrom ..compass import atlas\n")
    assert violations(relative, tmp_path) == [
        "vc_gym/filters/probe:2 imports vc_gym.compass (filters -> compass)"
    ]
    fine = filters / "ok.py"
    fine.write_text("from vc_gym.angles import wrap180\nfrom . import grid\n")
    assert violations(fine, tmp_path) == []
    assert layer_of("vc_gym.angles") == "base"
    assert layer_of("vc_gym.filters.heading_grid") == "filters"


def test_every_subpackage_has_a_layer():
    packages = {p.parent.name for p in PACKAGE.glob("*/__init__.py")} - {"__pycache__"}
    assert packages <= set(ORDER), packages - set(ORDER)
