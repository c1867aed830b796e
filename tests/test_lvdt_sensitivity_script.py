"""scripts/lvdt_sensitivity.py (issue 42): its grid, bad input, and a one-point run's CSV and PNG."""

import csv
import math
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
import lvdt_sensitivity as ls  # noqa: E402


def test_the_two_sweeps_meet_once_at_the_documented_sensor():
    grid = ls.points([100.0, 250.0, math.inf], [5.0, 15.0])
    assert grid == [("band", 100.0, 15.0), ("band", 250.0, 15.0), ("band", math.inf, 15.0), ("noise", 250.0, 5.0)]
    assert ls.environment(math.inf, 5.0) == {"STUDYAPP_LVDT_BAND": "inf", "STUDYAPP_LVDT_NOISE": "5e-6"}


@pytest.mark.parametrize("args, says", [(["--bands", "250,wide"], "--bands '250,wide': 'wide' is not allowed"),
                                        (["--noises", "inf"], "--noises 'inf': 'inf' is not allowed"),
                                        (["--seeds", "41-40"], "--seeds '41-40': allowed is A-B")])
def test_bad_input_is_one_line_and_exit_2(tmp_path, args, says):
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "lvdt_sensitivity.py"), "-o", str(tmp_path / "o"),
                           *args], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert done.returncode == 2 and says in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "o").exists()


@pytest.mark.slow
def test_one_point_gives_the_nine_conditions_rho_and_a_picture(tmp_path):
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "lvdt_sensitivity.py"), "-o", str(tmp_path / "o"),
                           "--seeds", "40", "--bands", "250", "--noises", "15", "--no-pilot", "--workers", "1"],
                          capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    with open(tmp_path / "o" / "lvdt_sensitivity.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0]) == ls.FIELDS
    fmax = {r["condition"]: float(r["value"]) for r in rows if r["quantity"] == "fmax_median"}
    assert set(fmax) == set(ls.CONDITIONS) and all(0.05 <= v for v in fmax.values())
    (rho,) = [float(r["value"]) for r in rows if r["quantity"] == "breakdown_rho"]
    assert -1.0 <= rho <= 1.0
    assert (tmp_path / "o" / "lvdt_sensitivity.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "| 250 | 15 |" in done.stdout
