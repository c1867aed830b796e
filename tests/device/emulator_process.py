"""The emulator as its own process and a minimal host on the pty, for the tests (not a driver: that is
studyapp/device/link_device.py)."""

import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

from studyapp.device.streams import host_receiver
from tests.device.pty_host import PtyHost

ROOT = Path(__file__).resolve().parents[2]
START_TIMEOUT = 120.0  # s: numba's cache loads slowly on a loaded machine


def start_emulator(link, *options):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "studyapp", "device-emulator", "--link", str(link), *options],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, cwd=ROOT)
    line = _readline(proc, START_TIMEOUT)
    if line != f"ready: {link}":
        proc.kill()
        raise AssertionError(f"no ready line: {line!r} {proc.stderr.read().decode()[-2000:]}")
    return proc


def _readline(proc, timeout):
    end = time.monotonic() + timeout
    buf = b""
    fd = proc.stdout.fileno()
    while not buf.endswith(b"\n"):
        left = end - time.monotonic()
        if left <= 0 or not select.select([fd], [], [], left)[0]:
            return buf.decode()
        chunk = os.read(fd, 1)
        if not chunk:
            return buf.decode()
        buf += chunk
    return buf.decode().strip()


def stop_emulator(proc, sig=signal.SIGTERM):
    """Signal it; its stdout's last line, ``stats: {...}``, parsed."""
    import json
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=30)
    lines = [x for x in out.decode().splitlines() if x.startswith("stats: ")]
    assert lines, err.decode()[-2000:]
    return json.loads(lines[-1][len("stats: "):])


class Host(PtyHost):
    """Protocol 1's messages in (streams.host_receiver); ``wait`` returns the first message of a type."""

    def __init__(self, path):
        super().__init__(path)
        self.receiver = host_receiver()

    def _decode(self, data):
        return self.receiver.feed(data)
