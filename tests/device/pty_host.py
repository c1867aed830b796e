"""The tests' minimal hosts on a pty (not drivers: those are studyapp/device/link_device.py and loop_link.py):
frames out; messages in, kept in ``inbox``. A subclass decodes what it reads (``_decode``).

Nothing a device sent is lost between calls: what a ``wait`` read after the message it waited for comes out of
the next ``poll`` (a lock-step device sends a row and waits for its answer, so a row dropped there hung the
suite), and ``next`` fails after ``timeout`` s of silence instead of waiting for good."""

import os
import select
import time
import tty

from studyapp.device.streams import Sender


class PtyHost:
    WAIT_S = 5.0

    def __init__(self, path):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(self.fd)
        self.sender = Sender()
        self.inbox = []
        self.after_wait = []

    def close(self):
        os.close(self.fd)

    def send(self, *items):
        data = b"".join(self.sender.frame(m) for m in items)
        while data:
            select.select([], [self.fd], [], 1.0)
            try:
                data = data[os.write(self.fd, data):]
            except BlockingIOError:
                continue

    def send_raw(self, data):
        os.write(self.fd, data)

    def poll(self, timeout=0.0):
        """What a wait left, then what arrives within ``timeout`` s (also appended to ``inbox``)."""
        got, self.after_wait = self.after_wait, []
        if select.select([self.fd], [], [], timeout)[0]:
            try:
                new = self._decode(os.read(self.fd, 1 << 16))
            except BlockingIOError:
                new = []
            self.inbox += new
            got = got + new
        return got

    def clear(self):
        self.inbox.clear()
        self.after_wait = []

    def next(self, timeout=10.0):
        """What arrives next (``poll``), waiting at most ``timeout`` s for something."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            got = self.poll(min(0.5, max(0.0, end - time.monotonic())))
            if got:
                return got
        raise AssertionError(f"nothing from the device within {timeout} s")

    def wait(self, kind, timeout=None, where=lambda m: True):
        """The first message of ``kind`` (and ``where``) in ``inbox`` or arriving within ``timeout`` s; what came
        before it is dropped, what came after it is the next ``poll``'s."""
        timeout = self.WAIT_S if timeout is None else timeout
        end = time.monotonic() + timeout
        while True:
            for i, m in enumerate(self.inbox):
                if isinstance(m, kind) and where(m):
                    self.after_wait = self.inbox[i + 1:]
                    del self.inbox[:i + 1]
                    return m
            self.clear()
            left = end - time.monotonic()
            if left <= 0:
                raise AssertionError(f"no {kind.__name__} within {timeout} s")
            self.poll(min(left, 0.05))

    def _decode(self, data):
        raise NotImplementedError
