"""Studies share helpers through the shared modules only, never through each other.

A study module (``vc_gym/experiments/studies/<name>.py``, or any module of a study
package ``vc_gym/experiments/studies/<name>/``) may import from the shared
helper modules (:data:`SHARED`) and from the registry (the package itself, e.g.
``get_experiment`` to run another experiment by name), not from a sibling study. The
``paper`` study, which runs all the others, may import their ``run_*`` and
``summary_lines`` functions. Every import is checked, lazy ones included.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import vc_gym.experiments.studies as studies

FOLDER = Path(studies.__file__).parent
PACKAGE = "vc_gym.experiments.studies"
#: The modules that hold what more than one study uses.
SHARED = {"common", "kidnapping", "orientation_grid"}
#: Studies that may import the runners and summaries of the others.
RUNS_OTHERS = {"paper"}
#: Every study's source files: the study modules and the modules of study packages.
MODULES = sorted(p for p in FOLDER.glob("*.py") if p.stem != "__init__") + sorted(
    FOLDER.glob("*/*.py")
)


def study_of(path: Path) -> str:
    """The study a source file belongs to (its package's name inside a study package)."""
    return path.stem if path.parent == FOLDER else path.parent.name


def sibling_imports(source: str, known: set[str]) -> list[tuple[int, str, str]]:
    """``(line, module, name)`` of every import of a module in ``known`` from ``source``
    (``name`` is the imported name, ``"*"`` for the whole module)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if alias.name.startswith(PACKAGE + ".") and parts[3] in known:
                    found.append((node.lineno, parts[3], "*"))
        elif isinstance(node, ast.ImportFrom) and node.module:
            if node.module == PACKAGE:  # the registry, or a module of the package
                found += [(node.lineno, a.name, "*") for a in node.names if a.name in known]
            elif node.module.startswith(PACKAGE + "."):
                module = node.module.split(".")[3]
                if module in known:
                    found += [(node.lineno, module, a.name) for a in node.names]
    return found


def violations(name: str, source: str, known: set[str]) -> list[str]:
    """The imports of study ``name`` that reach into a sibling study."""
    out = []
    for line, module, imported in sibling_imports(source, known):
        if module in SHARED or module == name:
            continue
        if name in RUNS_OTHERS and (imported.startswith("run_") or imported == "summary_lines"):
            continue
        out.append(f"{name}.py:{line} imports {imported} from the study {module}")
    return out


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(FOLDER)))
def test_no_study_imports_from_a_sibling_study(path):
    known = {study_of(p) for p in MODULES}
    assert violations(study_of(path), path.read_text(), known) == []


def test_the_shared_modules_exist():
    assert SHARED <= {study_of(p) for p in MODULES}


def test_the_checker_catches_every_form_of_sibling_import():
    known = {"common", "homing", "orientation", "paper"}
    source = (
        "from vc_gym.experiments.studies.homing import summarise_stops\n"
        "from vc_gym.experiments.studies import orientation, get_experiment\n"
        "import vc_gym.experiments.studies.homing\n"
        "from vc_gym.experiments.studies.common import open_run\n"
        "def f():\n"
        "    from vc_gym.experiments.studies.orientation import run_orientation\n"
    )
    assert violations("trackers", source, known) == [
        "trackers.py:1 imports summarise_stops from the study homing",
        "trackers.py:2 imports * from the study orientation",
        "trackers.py:3 imports * from the study homing",
        "trackers.py:6 imports run_orientation from the study orientation",
    ]
    # the paper study runs the others: their runners and summaries only
    assert violations("paper", source, known) == [
        "paper.py:1 imports summarise_stops from the study homing",
        "paper.py:2 imports * from the study orientation",
        "paper.py:3 imports * from the study homing",
    ]
