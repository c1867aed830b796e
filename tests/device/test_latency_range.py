"""Issue 41 item 4: the host's latency range, packet .. 1024 samples, measured at both ends on the emulator.

Under the loop order (the device receives, samples, actuates, then sends a frame once its last sample is
actuated) the force for a frame's first sample, tagged k + latency, is late at latency packet - 1 whatever the
host does: the lock-step emulator (no clock: it waits for each force) shows it, every fifth force late at packet 5,
latency 4, and none at latency 5. At the top, the device drops a force tagged 1024 or more samples ahead: at latency
1024 the newest force of an answer is at most 1023 ahead (none dropped), above it the clocked emulator drops some.
The figures print with ``pytest -s``; the latencies outside the range are reached by lifting the host's check.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from studyapp.device import handshake
from studyapp.device.emulator_process import EmulatorProcess
from studyapp.device.link_device import LinkDevice

ROOT = Path(__file__).resolve().parents[2]
RATE = 5000.0
PACKET = 5


class Zero:
    def sample(self, k, sensors, truth, out, est_out):
        return 0.0


def _stream(tmp_path, latency, seconds, *emulator, faults=()):
    path = tmp_path / f"device-{latency}"
    with EmulatorProcess(path, "--seed", "1", "--watchdog-ms", "100", *emulator) as emu:
        device = LinkDevice(path, RATE, latency=latency, packet=PACKET, ramp_ms=0, silence=5.0, pings=2)
        device.arm(0)
        for _ in range(int(seconds * RATE / 10)):
            device.exchange(Zero(), 10, None, None)
        health, fault = dict(device.health), device.fault
        device.close()
        stats = emu.stop()
    assert fault is None or any(word in fault for word in faults), fault
    print(f"\npacket {PACKET}, latency {latency} {' '.join(emulator) or 'clocked'}: {health['samples']} samples, "
          f"host late {health['late']}, device late {stats['late']}, dropped ahead {stats['corrupt']}")
    return health, stats


@pytest.fixture
def unchecked(monkeypatch):
    monkeypatch.setattr(handshake, "check_latency", lambda latency, packet=1: latency)


def test_at_latency_packet_every_force_is_on_time_under_the_loop_order(tmp_path):
    health, stats = _stream(tmp_path, PACKET, 1.0, "--lockstep")
    assert health["samples"] == RATE and health["late"] == stats["late"] == stats["missing"] == 0


def test_at_latency_packet_minus_1_every_frames_first_force_is_late(tmp_path, unchecked):
    health, _ = _stream(tmp_path, PACKET - 1, 1.0, "--lockstep")
    assert health["late"] == health["samples"] // PACKET > 0


def test_at_latency_1024_no_force_is_dropped_above_it_some_are(tmp_path, unchecked):
    assert handshake.MAX_LATENCY == 1024
    _, stats = _stream(tmp_path, 1024, 2.0)
    assert stats["corrupt"] == 0 and stats["samples"] > 1024 + RATE
    # every force dropped starves the device's watchdog (100 ms) when the host keeps up: the drop is the point
    _, stats = _stream(tmp_path, 1040, 2.0, faults=("WATCHDOG",))
    assert stats["corrupt"] > 0


@pytest.mark.parametrize("latency, packet", [(4, 5), (0, 1), (1025, 1), (65535, 1), (2000, 5)])
def test_live_refuses_a_latency_outside_the_range(tmp_path, latency, packet):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "studyapp", "live", "--device", str(tmp_path / "ttyACM0"),
                           "--device-latency", str(latency), "--device-packet", str(packet), "--audio", "null",
                           "--midi", "none", "--seconds", "1"], capture_output=True, text=True, timeout=120, env=env,
                          cwd=ROOT)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert f"device latency = {latency}: allowed is a whole number of samples from the packet ({packet}" in lines[0]
    assert "to 1024" in lines[0]
