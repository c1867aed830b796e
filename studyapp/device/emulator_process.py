"""``studyapp device-emulator`` as a child process: started, waited for, stopped, its stats read.

The benchmark (``studyapp bench device``) and the tests run host and device
as separate processes, as a rig has them: ``EmulatorProcess(link, *options)``
starts ``python -m studyapp device-emulator --link LINK OPTIONS`` in its own
session (so a signal to it reaches no one else), waits for its ``ready: PATH``
line (``start``), and on ``stop`` sends SIGTERM and reads its last line,
``stats: {json}``.
"""

import json
import os
import select
import signal
import subprocess
import sys
import time

from studyapp.errors import EngineError

READY_TIMEOUT = 300.0  # s: the emulator loads the simulated device (compiled on a fresh cache) before it is ready


class EmulatorProcess:
    def __init__(self, link, *options):
        self.link = str(link)
        self.argv = [sys.executable, "-m", "studyapp", "device-emulator", "--link", self.link, *map(str, options)]
        self.process = None
        self.stats = None

    def start(self, timeout=READY_TIMEOUT):
        """Start it; returns once its link exists (``EngineError`` if it never says ready)."""
        self.process = subprocess.Popen(self.argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                        start_new_session=True)
        end = time.monotonic() + timeout
        out = self.process.stdout
        while time.monotonic() < end:
            if select.select([out], [], [], 0.1)[0]:
                line = out.readline()
                if line.startswith("ready: "):
                    return self
                if not line and self.process.poll() is not None:
                    break
        error = self.process.stderr.read() if self.process.poll() is not None else ""
        self.kill()
        raise EngineError(f"device-emulator did not become ready: {error.strip().splitlines()[-1:] or 'timeout'}")

    @property
    def pid(self):
        return self.process.pid

    def signal(self, signum):
        os.kill(self.process.pid, signum)

    def stop(self, timeout=10.0):
        """SIGTERM, wait, and its ``stats`` (a dict; None if it printed none)."""
        if self.process is None:
            return self.stats
        if self.process.poll() is None:
            self.signal(signal.SIGTERM)
        try:
            out, _ = self.process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            return self.stats
        for line in out.splitlines():
            if line.startswith("stats: "):
                self.stats = json.loads(line[len("stats: "):])
        self.process = None
        return self.stats

    def kill(self):
        if self.process is not None:
            if self.process.poll() is None:
                self.process.kill()
            self.process.communicate()
            self.process = None

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
