"""``studyapp bench device --loop device``: the device-loop benchmark end to end on the emulator (figures
measured, never asserted as speed: only that every row was shadowed and the figures are there), and its bad
input."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ENV = {"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}


@pytest.mark.alone
def test_bench_device_loop_reports_its_figures_and_shadows_every_row():
    proc = subprocess.run([sys.executable, "-m", "studyapp", "bench", "device", "--loop", "device", "--seconds", "2",
                           "--json"], capture_output=True, text=True, timeout=600, cwd=ROOT, env=ENV)
    assert proc.returncode == 0, proc.stderr[-2000:]
    result = json.loads(proc.stdout)
    run = result["each"][0]
    assert result["loop"] == "device" and result["packet"] == 10 and run["samples"] > 1000
    assert run["shadow_faults"] == 0 and run["telemetry"]["unchecked"] == 0
    assert run["control"]["sent"] >= 1 and run["control"]["device_ms"]["p50"] > 0
    for key in ("watchdog", "force_gaps", "missing", "gaps", "longest_block_ms", "control_device_ms",
                "control_host_ms"):
        assert key in result["median"]


def test_bench_device_refuses_another_loop_in_one_line():
    proc = subprocess.run([sys.executable, "-m", "studyapp", "bench", "device", "--loop", "sideways"],
                          capture_output=True, text=True, timeout=300, cwd=ROOT, env=ENV)
    assert proc.returncode == 2 and proc.stderr.strip().splitlines()[-1].endswith(
        "--loop sideways: allowed is host or device")
