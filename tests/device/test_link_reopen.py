"""Issue 41 item 4: ``studyapp live --device`` opens the link three times before it streams (the check before the
engine loads, the driver's choice, the driver), each time with its seq from 0; the device counts no lost frames for
it (a HELLO starts a new count, docs/device-protocol.md "A new conversation"), in the C core and the Python one."""

import pytest

from studyapp.device.device_open import open_link_device
from studyapp.device.emulator_process import EmulatorProcess
from studyapp.device.link_probe import probe

RATE = 5000.0


class Zero:
    def sample(self, k, sensors, truth, out, est_out):
        return 0.0


@pytest.mark.parametrize("core", ["c", "python"])
def test_reopening_the_link_counts_no_lost_frames(tmp_path, core):
    path = tmp_path / "device"
    with EmulatorProcess(path, "--core", core, "--watchdog-ms", "100") as emu:
        for _ in range(2):
            assert probe(path, RATE)["serial"] == "EMU-0000"
        device = open_link_device(str(path), RATE, {"latency": 5, "packet": 1, "calibration": None, "ramp_ms": 0,
                                                    "silence": 5.0})
        for _ in range(100):
            device.exchange(Zero(), 10, None, None)
        health = dict(device.health)
        device.close()
        stats = emu.stop()
    assert health["samples"] == 1000 and health["lost"] == 0
    assert stats["lost"] == 0, stats
