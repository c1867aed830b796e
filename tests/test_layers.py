"""The layer contract: only studyapp.gui imports Qt; core layers import nothing above them.

DESIGN.md: dependencies point down only (gui -> engine/experiment/analysis/evaluation
-> model -> estimators). napari enforces the same with an import-linter contract;
this test does it with the standard library's ast module.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "studyapp"
QT = ("PySide6", "pyqtgraph", "shiboken6")
# layer -> packages it must not import
FORBIDDEN = {
    "estimators": ("studyapp.model", "studyapp.engine", "studyapp.experiment", "studyapp.analysis",
                   "studyapp.evaluation", "studyapp.gui", "studyapp.cli"),
    "model": ("studyapp.engine", "studyapp.experiment", "studyapp.analysis", "studyapp.evaluation",
              "studyapp.gui", "studyapp.cli"),
    "evaluation": ("studyapp.engine", "studyapp.experiment", "studyapp.analysis", "studyapp.gui", "studyapp.cli"),
    "analysis": ("studyapp.engine", "studyapp.gui", "studyapp.cli"),
    "experiment": ("studyapp.gui", "studyapp.cli"),
    "engine": ("studyapp.gui", "studyapp.cli", "studyapp.experiment", "studyapp.analysis"),
    "session": ("studyapp.gui", "studyapp.cli", "studyapp.analysis"),
}


def imports(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.module


SOURCES = sorted(p for p in ROOT.rglob("*.py") if "gui" not in p.relative_to(ROOT).parts)


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_core_never_imports_qt(path):
    bad = [m for m in imports(path) if m.split(".")[0] in QT]
    assert not bad, f"{path.relative_to(ROOT)} imports {bad}: only studyapp/gui may import Qt"


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_dependencies_point_down(path):
    layer = path.relative_to(ROOT).parts[0]
    forbidden = FORBIDDEN.get(layer, ())
    bad = [m for m in imports(path) if any(m == f or m.startswith(f + ".") for f in forbidden)]
    assert not bad, f"{path.relative_to(ROOT)} (layer {layer}) imports {bad}"
