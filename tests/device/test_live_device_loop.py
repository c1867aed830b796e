"""``studyapp live --device PATH`` on the emulator running the loop itself (protocol 2, ``--loop device``): the
engine picks the device-loop driver from INFO, its loop runs the device's estimators, the shadow follows every
row, and the JSON's ``device`` says "loop on the device"."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from studyapp.device.emulator_process import EmulatorProcess

REPO = Path(__file__).resolve().parents[2]


# real time: the engine is paced by the emulator's clock; the device's keep-alive watchdog (200 ms) is what a
# stall must stay under, not every sample
@pytest.mark.alone
def test_live_on_a_device_loop_picks_the_driver_from_info_and_shadows_every_row(tmp_path):
    path = tmp_path / "device"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    with EmulatorProcess(path, "--loop", "device") as emulator:
        proc = subprocess.run([sys.executable, "-m", "studyapp", "live", "--device", str(path), "--audio", "null",
                               "--midi", "none", "--seconds", "3", "--json", "--source", "KALPOS"],
                              capture_output=True, text=True, timeout=600, env=env, cwd=REPO)
    assert proc.returncode in (0, 1), proc.stderr
    device = json.loads(proc.stdout)["device"]
    assert device["loop"] == "device" and device["latency_samples"] == 0 and device["protocol"] == 2
    assert device["fault"] is None, device["fault"]
    health = device["health"]
    assert health["samples"] > 5000 and health["unchecked"] == 0 and health["controls"] >= 1
    assert emulator.stats is None or emulator.stats["loop"] == "device"
