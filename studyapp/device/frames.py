"""Frames on the wire: ``COBS(payload || crc16_le(payload)) || 0x00`` (docs/device-protocol.md, Framing).

A payload is ``type:u8, seq:u8, body`` of at most ``MAX_PAYLOAD`` bytes.
Its CRC-16 (crc.py) follows it little-endian, the whole is COBS-stuffed
(cobs.py) so that it holds no 0x00, and one 0x00 ends the frame. The longest
stuffed frame is ``MAX_ENCODED`` bytes (payload, CRC, and one COBS code byte
per started 254 bytes).

``FrameReader`` takes the byte stream as it comes (any split) and returns the
payloads of the frames that check. A run between two delimiters that is not
a valid frame (bad COBS, a CRC that fails, shorter than type, seq and CRC,
longer than ``MAX_ENCODED``) is counted in ``corrupt`` and dropped (``last_error``
says why, for a handshake's refusal); the reader resynchronises on the next 0x00. An empty run (two delimiters in a
row, or one before the first frame) is no frame and not counted: a sender
may send 0x00 first to end any partial frame at the receiver.
"""

from studyapp.device import cobs
from studyapp.device.crc import crc16
from studyapp.device.errors import ProtocolError

MAX_PAYLOAD = 1024
MIN_PAYLOAD = 2  # type and seq
MAX_ENCODED = MAX_PAYLOAD + 2 + (MAX_PAYLOAD + 2 + 253) // 254
DELIMITER = 0


def encode(payload):
    """The wire bytes of one frame carrying ``payload``, its delimiter included."""
    if not MIN_PAYLOAD <= len(payload) <= MAX_PAYLOAD:
        raise ProtocolError(f"payload length {len(payload)}: allowed is {MIN_PAYLOAD}..{MAX_PAYLOAD} bytes")
    crc = crc16(payload)
    return cobs.encode(bytes(payload) + bytes((crc & 0xFF, crc >> 8))) + b"\x00"


def decode(run):
    """The payload of one frame given without its delimiter; ``ProtocolError`` if it does not check."""
    if len(run) > MAX_ENCODED:
        raise ProtocolError(f"frame of {len(run)} bytes: longer than the largest, {MAX_ENCODED}")
    raw = cobs.decode(run)
    if len(raw) < MIN_PAYLOAD + 2:
        raise ProtocolError(f"frame of {len(raw)} bytes after COBS: shorter than type, seq and CRC")
    payload, check = raw[:-2], raw[-2] | (raw[-1] << 8)
    if crc16(payload) != check:
        raise ProtocolError("CRC: the frame's check does not match its payload")
    return payload


class FrameReader:
    """Splits a byte stream into checked payloads; counts the runs that are not valid frames.

    ``feed(data)`` returns the payloads completed by ``data``, in order.
    ``frames``: valid frames so far; ``corrupt``: runs dropped.
    """

    def __init__(self):
        self._run = bytearray()
        self._overlong = False
        self._length = 0  # bytes of the current run, an overlong one's too
        self.frames = 0
        self.corrupt = 0
        self.last_error = None  # why the newest dropped run did not check

    def feed(self, data):
        data = bytes(data)
        payloads = []
        start = 0
        n = len(data)
        while start < n:
            end = data.find(b"\x00", start)
            if end < 0:
                self._append(data[start:])
                break
            self._append(data[start:end])
            payload = self._finish()
            if payload is not None:
                payloads.append(payload)
            start = end + 1
        return payloads

    def _append(self, chunk):
        self._length += len(chunk)
        if self._overlong:
            return
        self._run += chunk
        if len(self._run) > MAX_ENCODED:
            self._overlong = True
            self._run.clear()

    def _finish(self):
        run, overlong, length = bytes(self._run), self._overlong, self._length
        self._run.clear()
        self._overlong = False
        self._length = 0
        if overlong:
            self.corrupt += 1
            self.last_error = f"frame of {length} bytes: longer than the largest, {MAX_ENCODED}"
            return None
        if not run:
            return None
        try:
            payload = decode(run)
        except ProtocolError as exc:
            self.corrupt += 1
            self.last_error = str(exc)
            return None
        self.frames += 1
        return payload
