"""scripts/sensitivity.py and scripts/quoted_figures.py: the moves they report and the spreads they allow (issue 39)."""

import math
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
import quoted_figures as qf  # noqa: E402
import sensitivity  # noqa: E402


def test_a_move_is_relative_and_equal_values_do_not_move():
    assert sensitivity.move(2.0, 2.1) == pytest.approx(0.05)
    assert sensitivity.move(math.inf, math.inf) == 0.0 and sensitivity.move(0.05, 0.05) == 0.0
    assert sensitivity.move(200.0, math.inf) == math.inf


@pytest.mark.parametrize("args, says", [(["--parts", "nope"], "--parts 'nope': allowed are"),
                                        (["--tables", "strokes-96k"], "--tables 'strokes-96k': allowed are")])
def test_bad_input_is_one_line_and_exit_2(tmp_path, args, says):
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "sensitivity.py"), "-o", str(tmp_path / "o"), *args],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 2 and says in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "o").exists()


def test_within_allows_the_spread_plus_the_rounding():
    assert qf.within(104.0, 100.0, 0.04) and not qf.within(104.1, 100.0, 0.04)
    assert qf.within(104.5, 100.0, 0.04, 0.5) and qf.within(math.inf, math.inf, 0.0)
    assert not qf.within(math.inf, 200.0, 1.0)
    assert qf.half_unit("131") == 0.5 and qf.half_unit("4.84") == 0.005


def test_a_regenerated_breakdown_table_holds_seed_by_seed():
    tol = qf.breakdown_tolerance("strokes", 5000.0)
    quoted = [{"source": "LVT", "seeds_used": "0; 1", "fmax_per_seed": "8.16; > 200"}]
    near = [{"source": "LVT", "seeds_used": "0; 1", "fmax_per_seed": f"{8.16 * (1 + 0.9 * tol):.3g}; > 200"}]
    far = [{"source": "LVT", "seeds_used": "0; 1", "fmax_per_seed": f"{8.16 * (1 + 1.5 * tol):.3g}; 22.6"}]
    assert qf.compare_breakdown(quoted, near, "strokes", 5000.0) == []
    problems = qf.compare_breakdown(quoted, far, "strokes", 5000.0)
    assert [p.split(":")[0] for p in problems] == ["LVT seed 0", "LVT seed 1"]
    assert qf.compare_breakdown(quoted, [], "strokes", 5000.0) == ["LVT: not regenerated"]


def test_every_spread_is_measured():
    relative = [*qf.BREAKDOWN_ROUNDING.values(), *qf.SIGNAL_ROUNDING.values(), qf.PILOT_ROUNDING["median"],
                *qf.RESPONSE_ROUNDING.values(), qf.OBJECTIVE_ROUNDING]
    assert all(isinstance(s, float) and 0.0 <= s < 1.0 for s in relative), relative
    assert 0.0 <= qf.PILOT_ROUNDING["rho"] <= 2.0 and 0.0 <= qf.PILOT_ROUNDING["share"] <= 100.0


def test_the_pilot_table_holds_within_its_spread():
    _, _, quoted = qf.pilot_table((ROOT / "docs" / "experiment.md").read_text())
    assert qf.compare_pilot(quoted, quoted) == []
    moved = {label: list(cells) for label, cells in quoted.items()}
    moved["LVT median (N)"][0] = f"{float(quoted['LVT median (N)'][0]) * 1.015:.3g}"
    assert qf.compare_pilot(quoted, moved) == []
    moved["LVT median (N)"][0] = f"{float(quoted['LVT median (N)'][0]) * 1.05:.3g}"
    moved["rho against the paper's Fig. 7 order"][1] = "0.78"
    assert [p.split(":")[0] for p in qf.compare_pilot(quoted, moved)] == [
        "LVT median (N), set 1", "rho against the paper's Fig. 7 order, set 2"]
