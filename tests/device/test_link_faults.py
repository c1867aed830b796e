"""Issue 29's fault targets, host and emulator as separate processes over a pty (real time, not lock-step).

- the host worker stopped (SIGSTOP) or killed: the emulator's force reaches 0 within its watchdog bound, at
  most the latency + 2 ms after the host's last force frame arrived (the device's FAULT WATCHDOG says where the
  force reached 0 and when the last frame came, on its own sample clock);
- the emulator killed, or its link closed: the host latches a device fault and commands 0 within 20 ms;
- corrupted and dropped frames are counted and never applied;
- a device at another rate is refused with one line naming it (the fake device covers version and limits).

Each case runs ``TRIES`` times (``STUDYAPP_FAULT_TRIES``, default 2: the machine is shared; the 10 tries of
the issue were run once, docs/devices.md).
"""

import json
import os
import select
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from studyapp.device import messages
from studyapp.device.emulator_process import EmulatorProcess
from studyapp.device.link_device import SILENCE, LinkDevice
from studyapp.errors import ParameterError
from studyapp.model.loop import ClosedLoop, LoopConfig

REPO = Path(__file__).resolve().parents[2]
TRIES = int(os.environ.get("STUDYAPP_FAULT_TRIES", "2"))
RATE = 5000.0
LATENCY = 5  # samples: 1 ms

# real-time fault handling at 5 kHz (host, emulator and watchdog on their own clocks): on a loaded machine the
# Python host falls behind the emulator, so the device's watchdog fires before the link fault under test, or the
# emulator stalls past the kill; make test runs these after the parallel suite, with the machine to themselves
pytestmark = pytest.mark.alone


def _line(proc, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if select.select([proc.stdout], [], [], 0.1)[0]:
            return proc.stdout.readline().strip()
    return ""


def _host(path, silence=SILENCE):
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.Popen([sys.executable, "-m", "tests.device.host_worker", str(path), str(LATENCY), str(silence)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=REPO)
    assert _line(proc, 300) == "running", proc.stderr.read() if proc.poll() is not None else "no ready line"
    return proc


@pytest.mark.parametrize("try_", range(TRIES))
def test_a_stopped_host_lets_the_device_force_fall_to_zero_within_its_bound(tmp_path, try_):
    path = tmp_path / "device"
    with EmulatorProcess(path, "--seed", try_, "--watchdog-ms", 1) as emulator:
        # what is measured is the device's watchdog, on its own sample clock; the host waits long enough for the
        # device's FAULT frame that a loaded machine's scheduling (the emulator descheduled 20 ms) cannot latch
        # the host's own silence fault first (that bound has its own test, the killed emulator's)
        host = _host(path, silence=1.0)
        try:
            time.sleep(0.2)
            host.send_signal(signal.SIGSTOP)
            time.sleep(0.05)
            host.send_signal(signal.SIGCONT)
            report = json.loads(_line(host, 30))
        finally:
            host.kill()
            host.communicate()
    assert "WATCHDOG" in report["fault"]
    code, zero_at, last_frame = next(f for f in report["device_faults"] if f[0] == messages.WATCHDOG)
    took_ms = 1e3 * (zero_at - last_frame) / RATE
    print(f"figure: watchdog force 0 after {took_ms:.2f} ms")  # docs/devices.md quotes these (pytest -s)
    assert took_ms <= 1e3 * LATENCY / RATE + 2.0
    assert emulator.stats is None or emulator.stats.get("armed", 0) == 0


@pytest.mark.parametrize("try_", range(TRIES))
def test_a_killed_host_leaves_the_device_disarmed_by_its_watchdog(tmp_path, try_):
    path = tmp_path / "device"
    emulator = EmulatorProcess(path, "--seed", try_, "--watchdog-ms", 1).start()
    try:
        host = _host(path)
        time.sleep(0.2)
        host.kill()
        host.communicate()
        time.sleep(0.05)
    finally:
        stats = emulator.stop()
    assert stats["fault"] == messages.WATCHDOG and stats["armed"] == 0


def _watch_hangup(fd, gone):
    try:
        poller = select.poll()
        poller.register(fd, select.POLLHUP | select.POLLERR)
        while not poller.poll(1000):
            pass
        gone.append(time.monotonic())
    finally:
        os.close(fd)


def _loop(device):
    return ClosedLoop(LoopConfig(rate=RATE, estimators={}, source="LVT", fmax=2.0, gesture="strokes"), device=device)


def _run_until_fault(device, loop, seconds=30.0):
    forces = []
    end = time.monotonic() + seconds
    while device.fault is None and time.monotonic() < end:
        forces.append(loop.run(10)["force"])
    after = [loop.run(10)["force"] for _ in range(3)]
    return forces, after


@pytest.fixture(scope="module", autouse=True)
def warm_loop():
    """The host loop's kernels loaded before any emulator arms its watchdog: the first ``run`` of a process loads
    them from numba's cache, time the device's clock would count against the host."""
    _loop(None).run(10)


@pytest.fixture
def prompt_threads():
    """The hang-up watcher thread gets the interpreter promptly while the loop runs, and the host loop (this
    thread) runs at the engine worker's real-time priority where the system allows it, as a live session's does:
    at normal priority beside two busy processes it fell over 1 s behind the device's clock and the device's own
    watchdog fired before the hang-up the test is about (a clean-clone run at a load of 4, 2026-11-27)."""
    from studyapp.engine.worker import REALTIME_PRIORITY

    before = sys.getswitchinterval()
    sys.setswitchinterval(0.0005)
    policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(REALTIME_PRIORITY))
    except OSError:
        pass
    yield
    os.sched_setscheduler(0, policy, param)
    sys.setswitchinterval(before)


@pytest.mark.usefixtures("prompt_threads")
@pytest.mark.parametrize("how", ["killed", "closed"])
@pytest.mark.parametrize("try_", range(TRIES))
def test_a_lost_emulator_is_a_host_fault_with_force_zero_within_20ms(tmp_path, how, try_):
    path = tmp_path / "device"
    options = ("--disconnect-after", 5.0) if how == "closed" else ()
    emulator = EmulatorProcess(path, "--seed", try_, "--watchdog-ms", 1000, *options).start()
    try:
        # when the link ended: a second descriptor on the pty sees the hang-up as the host's does (the kill's
        # own time would count the kernel's delay in ending a process on a loaded machine)
        gone = []
        watcher = threading.Thread(target=_watch_hangup, args=(os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK),
                                                               gone), daemon=True)
        watcher.start()
        # a silence bound of 1 s: on a loaded machine the emulator may stall for more than 20 ms, and the test is
        # of the hang-up (the 20 ms silence bound itself is tested with the scripted device)
        device = LinkDevice(path, RATE, latency=LATENCY, ramp_ms=0, silence=1.0)
        loop = _loop(device)
        device.arm(0)
        if how == "killed":
            threading.Timer(0.5, emulator.process.kill).start()
        _, after = _run_until_fault(device, loop)
        device.close()
        watcher.join(10.0)
    finally:
        emulator.kill()
    assert device.fault is not None and "the link failed" in device.fault
    assert all(np.all(f == 0.0) for f in after)
    print(f"figure: {how}: host fault {1e3 * (device.fault_time - gone[0]):.2f} ms after the hang-up")
    assert -0.005 <= device.fault_time - gone[0] <= 0.020  # (the watcher thread may see it a little later)


def test_corrupt_and_lost_frames_are_counted_never_applied(tmp_path):
    path = tmp_path / "device"
    with EmulatorProcess(path, "--corrupt", 0.01, "--loss", 0.01, "--watchdog-ms", 1000) as emulator:
        device = LinkDevice(path, RATE, latency=50, ramp_ms=0)
        loop = _loop(device)
        device.arm(0)
        seen = []
        original = device._sensors

        def record(frame):
            seen.append(frame.sample)
            original(frame)

        device._sensors = record
        blocks = [loop.run(10) for _ in range(1000)]
        health = dict(device.health)
        device.close()
    stats = emulator.stats
    assert health["corrupt"] > 0 and health["lost"] >= health["corrupt"] and health["missing"] > 0
    assert stats["corrupt"] > 0  # the host's frames the emulator flipped, counted there
    assert all(b > a for a, b in zip(seen, seen[1:]))  # only frames that checked reached the loop, in order
    position = np.concatenate([b["position"] for b in blocks])
    assert np.all(np.isfinite(position)) and np.max(np.abs(position)) <= 0.011


def test_a_device_at_another_rate_is_refused(tmp_path):
    path = tmp_path / "device"
    with EmulatorProcess(path, "--rate", 4000):
        with pytest.raises(ParameterError) as err:
            LinkDevice(path, RATE)
    assert "rate 4000 Hz, the loop runs at 5000 Hz" in str(err.value)


@pytest.mark.parametrize("try_", range(TRIES))
def test_a_killed_host_leaves_a_device_loop_disarmed_by_its_keepalive_watchdog(tmp_path, try_):
    """The loop on the device (protocol 2) runs on without the host; only the keep-alive watchdog stops it. A host
    killed mid-run (SIGKILL: no DISARM, no STOP) leaves the device faulted WATCHDOG and disarmed within the
    keep-alive and the ramp down, 100 ms + 1 ms here; the test waits three times that."""
    path = tmp_path / "device"
    emulator = EmulatorProcess(path, "--seed", try_, "--loop", "device", "--keepalive-ms", 100).start()
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    try:
        host = subprocess.Popen([sys.executable, "-m", "tests.device.host_worker", str(path), "loop"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=REPO)
        assert _line(host, 300) == "running", host.stderr.read() if host.poll() is not None else "no ready line"
        time.sleep(0.2)
        assert host.poll() is None  # no fault before the kill: the device was armed and bowing
        host.kill()
        host.communicate()
        time.sleep(0.3)
    finally:
        stats = emulator.stop()
    assert stats["loop"] == "device"
    assert stats["fault"] == messages.WATCHDOG and stats["armed"] == 0
