"""A scripted device on a pty for the host driver's tests: answers HELLO and PING, streams on START.

Not the emulator (studyapp device-emulator): no mechanics, no clock of its own
unless asked. ``FakeDevice(info=..., hello=True)`` opens a pty in this process
and serves it from a thread; ``path`` is the slave's name. After START it sends
the SENSORS frames the test pushes with ``sensors(sample, rows)`` or raw
bytes with ``raw(data)``, and records every host message in ``received``.
``reply``: wire bytes sent for every HELLO instead of INFO (a malicious INFO);
``boot``: seconds after the first host byte during which HELLO goes unanswered
(a board that resets when its port opens), ``noise`` written once then.
"""

import os
import select
import threading
import time
import tty

from studyapp.device import frames, messages
from studyapp.device.streams import Sender

INFO = messages.Info(protocol_version=1, firmware_major=0, firmware_minor=1, rate_hz=5000, max_packet=16,
                     name="fake", serial="FAKE-1", travel_m=0.011, impulsive_n=200.0, sustained_n=60.0,
                     sustained_window_s=1.0, watchdog_ms=2, ramp_ms_min=0)


class Recorder:
    """A stand-in for the loop's controller: records the sensors it is given, answers force = 10 * x."""

    def __init__(self):
        self.seen = []

    def sample(self, k, sensors, truth, out, est_out):
        self.seen.append(tuple(sensors))
        return 10.0 * sensors[0]


class FakeDevice:
    def __init__(self, info=INFO, hello=True, reply=None, boot=0.0, noise=b""):
        self.info = info
        self.hello = hello
        self.reply = reply
        self.boot = boot
        self.noise = noise
        self._woken = None  # time.monotonic() of the first host byte
        self.master, slave = os.openpty()
        tty.setraw(slave)
        self.path = os.ttyname(slave)
        os.close(slave)
        self.sender = Sender(info.channels)
        self.received = []
        self.started = threading.Event()
        self._stop = False
        self._reader = frames.FrameReader()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self):
        while not self._stop:
            if not select.select([self.master], [], [], 0.02)[0]:
                continue
            try:
                data = os.read(self.master, 4096)
            except OSError:
                time.sleep(0.001)  # no slave open yet (EIO)
                continue
            if self._woken is None:
                self._woken = time.monotonic()
                if self.noise:
                    self.raw(self.noise)
            for payload in self._reader.feed(data):
                _, message = messages.parse(payload)
                self.received.append(message)
                if time.monotonic() - self._woken < self.boot:
                    continue
                if isinstance(message, messages.Hello) and self.reply is not None:
                    self.raw(self.reply)
                elif isinstance(message, messages.Hello) and self.hello:
                    self.send(self.info)
                elif isinstance(message, messages.Ping):
                    self.send(messages.Pong(nonce=message.nonce, sample=0))
                elif isinstance(message, messages.Start):
                    self.started.set()

    def send(self, message):
        os.write(self.master, self.sender.frame(message))

    def sensors(self, sample, rows, flags=0):
        self.send(messages.Sensors(sample=sample, flags=flags, values=tuple(rows)))

    def raw(self, data):
        os.write(self.master, data)

    def forces(self):
        """{sample: force} from every FORCE frame received."""
        out = {}
        for m in self.received:
            if isinstance(m, messages.Force):
                for i, f in enumerate(m.forces):
                    out[m.sample + i] = f
        return out

    def close(self):
        if not self._stop:
            self._stop = True
            self._thread.join(1.0)
            os.close(self.master)
