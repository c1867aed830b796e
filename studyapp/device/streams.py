"""One direction of a link: a ``Sender`` numbers frames, a ``Receiver`` checks, parses and counts them.

Each side numbers its frames ``seq`` = 0, 1, ... mod 256. The receiver
counts a jump in ``seq`` as frames lost (``lost``: frames that never arrived
intact, so a frame dropped as corrupt leaves a gap too), every run or payload
that breaks the protocol as ``corrupt`` (frames.py: COBS, CRC, length;
messages.py: type, body length, a value out of range), and hands on the
messages that check, in order, never a corrupt one.
"""

from studyapp.device import frames, messages
from studyapp.device.errors import ProtocolError


class Sender:
    """Wire bytes for messages, numbered 0, 1, ... mod 256; SENSORS packed with ``channels``."""

    def __init__(self, channels=messages.SI_CHANNELS):
        self.channels = channels
        self.seq = 0

    def frame(self, message):
        if isinstance(message, messages.Sensors):
            payload = message.pack(self.seq, self.channels)
        else:
            payload = message.pack(self.seq)
        self.seq = (self.seq + 1) & 0xFF
        return frames.encode(payload)


class Receiver:
    """Messages out of a byte stream (any split). ``channels``: the INFO's, for SENSORS (None before INFO;
    an INFO received sets them).

    ``accept``: the message types this side may receive (a host frame at the host is corrupt).
    Counters: ``frames`` (valid messages), ``corrupt``, ``lost``.
    """

    def __init__(self, accept, channels=None):
        self.accept = accept
        self.channels = channels
        self._reader = frames.FrameReader()
        self._corrupt_messages = 0
        self._last_seq = None
        self.frames = 0
        self.lost = 0

    @property
    def corrupt(self):
        return self._reader.corrupt + self._corrupt_messages

    def feed(self, data):
        out = []
        for payload in self._reader.feed(data):
            if payload[0] not in self.accept:
                self._corrupt_messages += 1
                continue
            try:
                seq, message = messages.parse(payload, self.channels)
            except ProtocolError:
                self._corrupt_messages += 1
                continue
            if self._last_seq is not None:
                self.lost += (seq - self._last_seq - 1) & 0xFF
            self._last_seq = seq
            self.frames += 1
            if isinstance(message, messages.Info):
                self.channels = message.channels
            out.append(message)
        return out


def host_receiver(channels=None):
    """What a host receives: device -> host messages."""
    return Receiver(messages.DEVICE_TYPES, channels)


def device_receiver():
    """What a device receives: host -> device messages."""
    return Receiver(messages.HOST_TYPES)
