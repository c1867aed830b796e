"""The layer contracts (.importlinter), checked with import-linter on this tree and shown to catch violations.

DESIGN.md: dependencies point down only, and only studyapp.gui imports Qt. The
contracts live in .importlinter at the repository root:

- ``layers``: cli > gui > analysis > session > engine | evaluation | experiment > device > model > estimators
  > io | stats, indirect imports included (import-linter's default), so no module reaches a
  higher layer through any chain; engine, evaluation and experiment are
  independent; experiment, below analysis, never imports it; io and stats use no other layer;
- ``qt``: PySide6 and pyqtgraph are imported only by studyapp.gui;
- ``knob-law``: only studyapp.model.controls imports the knob law (model.fmax_knob): tasks name
  typed actions, the engine applies them, and that module is where the two meet;
- ``limits``: model.limits and model.fmax_knob, which every layer reads, import neither
  numba nor scipy nor the loop or the estimators.

import-linter resolves ``from studyapp import gui`` to the module studyapp.gui
(a case the ast-based test this replaces missed), so no hand-written check is left.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / ".importlinter"
LINT = "import sys; from importlinter.cli import lint_imports_command; sys.exit(lint_imports_command())"


def lint(root):
    """(exit code, output) of lint-imports on the studyapp package under ``root``."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    run = subprocess.run([sys.executable, "-c", LINT, "--config", str(root / ".importlinter"), "--no-cache"],
                         cwd=root, env=env, capture_output=True, text=True, timeout=120)
    return run.returncode, run.stdout + run.stderr


def test_this_tree_keeps_every_contract():
    code, output = lint(ROOT)
    assert code == 0, output
    assert "Contracts: 4 kept, 0 broken." in output


@pytest.fixture
def copy(tmp_path):
    """A copy of the package's sources and the contracts, to break."""
    shutil.copytree(ROOT / "studyapp", tmp_path / "studyapp", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(CONFIG, tmp_path / ".importlinter")
    return tmp_path


LAYERS = "Layers: dependencies point down"
LIMITS = "Limits and the knob law load no simulation"
VIOLATIONS = {
    "core imports gui by from-import": ({"model/_bad.py": "from studyapp import gui\n"},
                                        LAYERS, "studyapp.model is not allowed to import studyapp.gui"),
    "experiment imports analysis": ({"experiment/_bad.py": "import studyapp.analysis.summary\n"},
                                    LAYERS, "studyapp.experiment is not allowed to import studyapp.analysis"),
    "siblings import each other": ({"engine/_bad.py": "from studyapp.evaluation import pareto\n"},
                                   LAYERS, "studyapp.engine is not allowed to import studyapp.evaluation"),
    "indirect, through an unlayered module": ({"estimators/_bad.py": "import studyapp._bridge\n",
                                               "_bridge.py": "import studyapp.engine.ring\n"},
                                              LAYERS, "studyapp.estimators is not allowed to import studyapp.engine"),
    "live imports gui": ({"live/_bad.py": "import studyapp.gui.app\n"},
                         LAYERS, "studyapp.live is not allowed to import studyapp.gui"),
    "core imports Qt": ({"engine/_bad.py": "import PySide6.QtCore\n"},
                        "Qt only in studyapp.gui", "studyapp.engine._bad -> PySide6"),
    "a task applies the knob law itself": ({"experiment/_bad.py": "from studyapp.model.fmax_knob import fmax_from_knob\n"},
                                           "The knob law is applied in model.controls only",
                                           "studyapp.experiment._bad -> studyapp.model.fmax_knob"),
    "stats imports analysis": ({"stats/_bad.py": "import studyapp.analysis.summary\n"},
                               LAYERS, "studyapp.stats is not allowed to import studyapp.analysis"),
    "io imports model": ({"io/_bad.py": "from studyapp.model import sources\n"},
                         LAYERS, "studyapp.io is not allowed to import studyapp.model"),
    "io and stats import each other": ({"io/_bad.py": "import studyapp.stats.holm\n"},
                                       LAYERS, "studyapp.io is not allowed to import studyapp.stats"),
    "limits imports numba": ({"model/limits.py": "import numba\n"}, LIMITS, "studyapp.model.limits -> numba"),
    "the knob law reaches the loop": ({"model/fmax_knob.py": "from studyapp.model import loop\n"},
                                      LIMITS, "studyapp.model.fmax_knob -> studyapp.model.loop"),
}


@pytest.mark.parametrize("case", VIOLATIONS, ids=list(VIOLATIONS))
def test_a_violation_breaks_its_contract(copy, case):
    files, contract, finding = VIOLATIONS[case]
    for name, text in files.items():
        path = copy / "studyapp" / name
        path.parent.mkdir(exist_ok=True)
        path.write_text(text)
    code, output = lint(copy)
    assert code == 1, output
    broken = output[output.index("Broken contracts"):]
    assert contract in broken and finding in broken, output
    assert "Contracts: 3 kept, 1 broken." in output
