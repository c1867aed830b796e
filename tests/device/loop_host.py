"""A minimal version 2 host on the pty, for the tests of a device loop (not a driver: that is
studyapp/device/loop_link.py): frames out, messages of either version in (loop_messages.parse)."""

from studyapp.device import frames, loop_messages, messages
from studyapp.device.errors import ProtocolError
from tests.device.pty_host import PtyHost


class LoopHost(PtyHost):
    WAIT_S = 10.0

    def __init__(self, path):
        super().__init__(path)
        self.reader = frames.FrameReader()
        self.channels = None
        self.corrupt = 0

    def _decode(self, data):
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
        return got
