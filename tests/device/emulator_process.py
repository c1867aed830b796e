"""The emulator as its own process and a minimal host on the pty, for the tests (not a driver: that is
studyapp/device/link_device.py)."""

import os
import select
import signal
import subprocess
import sys
import time
import tty
from pathlib import Path

from studyapp.device.streams import Sender, host_receiver

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


class Host:
    """Frames out, messages in, over the pty; ``wait`` returns the first message of a type."""

    def __init__(self, path):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(self.fd)
        self.sender = Sender()
        self.receiver = host_receiver()
        self.inbox = []
        self.after_wait = []  # what a wait read after the message it waited for: the next poll returns it

    def close(self):
        os.close(self.fd)

    def send(self, *items):
        data = b"".join(self.sender.frame(m) for m in items)
        while data:
            select.select([], [self.fd], [], 1.0)
            try:
                n = os.write(self.fd, data)
            except BlockingIOError:
                continue
            data = data[n:]

    def send_raw(self, data):
        os.write(self.fd, data)

    def poll(self, timeout=0.0):
        if select.select([self.fd], [], [], timeout)[0]:
            try:
                data = os.read(self.fd, 1 << 16)
            except BlockingIOError:
                return []
            got = self.receiver.feed(data)
            self.inbox += got
            return self._with_after_wait(got)
        return self._with_after_wait([])

    def clear(self):
        self.inbox.clear()
        self.after_wait = []

    def _with_after_wait(self, got):
        got, self.after_wait = self.after_wait + got, []
        return got

    def next(self, timeout=10.0):
        """What arrives next (``poll``), waiting at most ``timeout`` s for something: a lock-step device that has
        stopped sending is a failed test, not a hung one."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            got = self.poll(min(0.5, max(0.0, end - time.monotonic())))
            if got:
                return got
        raise AssertionError(f"nothing from the device within {timeout} s")

    def wait(self, kind, timeout=5.0, where=lambda m: True):
        end = time.monotonic() + timeout
        while True:
            for i, m in enumerate(self.inbox):
                if isinstance(m, kind) and where(m):
                    self.after_wait = self.inbox[i + 1:]
                    del self.inbox[:i + 1]
                    return m
            self.inbox.clear()
            self.after_wait = []
            left = end - time.monotonic()
            if left <= 0:
                raise AssertionError(f"no {kind.__name__} within {timeout} s")
            self.poll(min(left, 0.05))
