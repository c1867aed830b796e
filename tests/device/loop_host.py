"""A minimal version 2 host on the pty, for the tests of a device loop (not a driver: that is
studyapp/device/loop_link.py): frames out, messages of either version in (loop_messages.parse)."""

import os
import select
import time
import tty

from studyapp.device import frames, loop_messages, messages
from studyapp.device.errors import ProtocolError
from studyapp.device.streams import Sender


class LoopHost:
    def __init__(self, path):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(self.fd)
        self.sender = Sender()
        self.reader = frames.FrameReader()
        self.channels = None
        self.inbox = []
        self.after_wait = []  # what a wait read after the message it waited for: the next poll returns it
        self.corrupt = 0

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

    def poll(self, timeout=0.0):
        got, self.after_wait = self.after_wait, []
        return got + self._read(timeout)

    def _read(self, timeout):
        if not select.select([self.fd], [], [], timeout)[0]:
            return []
        try:
            data = os.read(self.fd, 1 << 16)
        except BlockingIOError:
            return []
        got = []
        for payload in self.reader.feed(data):
            try:
                _, m = loop_messages.parse(payload, self.channels)
            except ProtocolError:
                self.corrupt += 1
                continue
            if isinstance(m, messages.Info):
                self.channels = m.channels
            got.append(m)
        self.inbox += got
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

    def wait(self, kind, timeout=10.0, where=lambda m: True):
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
